"""The scenarios of the simulated sample logs: each benchmark's own (the ``sample`` module
beside its declaration, reached through the registry:
:func:`ertools.benchmarks.registry.scenarios`) and the two that are no one benchmark's (the
timeline folder, the 2019 season).

A scenario is a function ``generate(outdir: Path, *, seed: int) -> list[Path]``
(:class:`ertools.benchmarks.base.Generate`). It writes one or more logs into ``outdir`` (which
exists and is empty) with :class:`ertools.simulator.writer.BagWriter`, the answers a correct
scorer must find next to each log, and any config YAML the scorer needs; it returns every path
it wrote (files, or rosbag2 directories). ``python -m ertools.samples OUTDIR`` runs each
scenario into ``OUTDIR/<name>/``.

Rules for scenario authors:

- Deterministic: every random draw from ``np.random.default_rng(seed)`` (or a child of it);
  no wall clock, no ``hash()`` of strings, no dict/set order that depends on the run. Use a
  fixed epoch start (e.g. :data:`ertools.simulator.answers.EPOCH_2015` + an offset): the
  logs look like 2015's.
- Small: each log <= ~2.5 MB, all of ``sample_bags/`` <= ~15 MB. One body at 120 Hz
  (PoseStamped + Pose2D + /tf) costs ~45 kB/s in an uncompressed ROS1 bag, so keep the
  mocap part under ~50 s per body (compress time: short manual operations, fast runs), and
  publish 120 Hz only for the bodies the benchmark needs.
- Independent: compute ``expected`` from the noiseless truth with the seed manual's formulas,
  written out in the scenario module; never import the scorers (a benchmark's ``sample``
  never imports its pipeline: the ``samples`` import contract).
- Use :mod:`ertools.simulator.mocap` for what the mocap node published,
  :mod:`ertools.simulator.statemachine` for the state topics and
  :func:`ertools.simulator.answers.write_answers` for the answers file (its conventions are
  written there); a scenario in the RSBB's layout
  :func:`~ertools.simulator.answers.write_layout_answers`, beside its folder, not in it.
"""

from __future__ import annotations

import zlib

from ertools.benchmarks import registry
from ertools.benchmarks.base import Generate
from ertools.errors import UsageError
from ertools.samples import season, timeline_folder

# The scenarios that are no benchmark's: a folder of logs for `ertools timeline`, and a season
# of RSBB runs for `ertools rescore` (after the benchmarks' own, in this order).
OWN: dict[str, Generate] = {
    "timeline": timeline_folder.generate,
    "season2019": season.generate,
}

# The seeds the own scenarios' folders of sample_bags/ were written with (fixed, so that `python
# -m ertools.samples` reproduces them byte for byte); a benchmark's is its `sample_seed`.
SEEDS: dict[str, int] = {"timeline": 2020, "season2019": 2026}


class ScenarioMissingError(UsageError):
    """A scenario asked for that no benchmark's sample module and no own scenario writes."""


def scenarios() -> dict[str, Generate]:
    """Every scenario by folder name: the benchmarks' in the registry's order, then
    :data:`OWN`. Imports the benchmarks' declarations, not their simulators."""
    found: dict[str, Generate] = {s.folder: s.generate for s in registry.scenarios()}
    clash = sorted(set(found) & set(OWN))
    if clash:  # a programming error, caught by the tests
        raise ValueError(f"scenario folders written twice: {', '.join(clash)}")
    return found | OWN


def seed_of(name: str) -> int:
    """The default seed of scenario ``name``: its benchmark's ``sample_seed`` or :data:`SEEDS`,
    else one derived from the name (CRC-32: the same on every run and machine, unlike
    ``hash()``)."""
    declared = {s.folder: s.seed for s in registry.scenarios() if s.seed} | SEEDS
    return declared.get(name, 2015 + zlib.crc32(name.encode("utf-8")) % 10_000)


def load_scenario(name: str) -> Generate:
    """The ``generate`` function of scenario ``name``.

    Raises:
        ScenarioMissingError: no scenario has that name (the known ones listed).
    """
    known = scenarios()
    if name not in known:
        raise ScenarioMissingError(f"unknown scenario {name!r}; known: {', '.join(known)}")
    return known[name]
