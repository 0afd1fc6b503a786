"""The versions of the node files the benchmarks were scored with: each benchmark's
``VERSIONS`` lists its :class:`NodeVersion` rows, the version table of ``docs/fidelity.md``
(:func:`ertools.fidelity.version_table`, gathered by :mod:`ertools.benchmarks.catalogue`).
"""

from __future__ import annotations

from ertools.frozen_dataclass import frozen_dataclass


@frozen_dataclass
class NodeVersion:
    """One version of a node file of rockin-robot-challenge/benchmark_and_scoring_fbm: a row of
    the version table (``docs/fidelity.md``), read at its commit.

    Attributes:
        file: the file in that repository (``scripts/fbm2h``, ``src/rockin_scoring/BmBox.py``).
        commit: the short commit hash.
        date: the commit date (YYYY-MM-DD).
        event: the competition it served (RoCKIn 2015 Lisbon, the Lisbon 2016 second local,
            the Lisbon 2017 major tournament), or ``development``.
        changes: every change since the file's previous row that moves a score.
        restores: the option reproducing it, or ``not restorable:`` and why.
    """

    file: str
    commit: str
    date: str
    event: str
    changes: str
    restores: str
