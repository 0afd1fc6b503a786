"""The inputs of a benchmark that re-scores an ERL 2017-19 RSBB script's run alike, and the
options they make: the run's result file to compare with, the script version reproduced whole
(``--rules``), how the ground truth is looked up across a tracking gap (ertools refuses it;
the script's tf interpolated) and the intervals.

NumPy-free: the benchmarks' ``config`` modules list them for the command line's parser.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any, ClassVar

from ertools.benchmarks.base import Input
from ertools.benchmarks.common.inputs import (
    DEFAULT_CONFIDENCE,
    DEFAULT_DRAWS,
    DEFAULT_SEED,
    check_confidence,
)

#: The help section of the options that undo ertools' readings of a script one by one.
SCRIPT_GROUP = "the RSBB script's behaviour (each difference can be undone)"

#: The mocap runs at 100-120 Hz, so 0.1 s is several lost frames (ertools' rule).
DEFAULT_MAX_GAP_S = 0.1

RESULT = Input(
    "result",
    "path",
    "the run's result file result_run_<n>_<date>.yaml, compared with the recomputed score "
    "(default: beside the bag or in the RSBB layout)",
    metavar="FILE",
)

MAX_GAP = Input(
    "max_gap",
    "float",
    f"no ground truth across a tracking gap wider than this (default {DEFAULT_MAX_GAP_S} s)",
    unit="s",
    positive=True,
)

GT_GAPS = Input(
    "gt_gaps",
    "choice",
    "refuse (default): no ground truth across a gap wider than --max-gap; interpolate: as tf did",
    choices=("refuse", "interpolate"),
    group=SCRIPT_GROUP,
)


@dataclass(frozen=True)
class ScriptOptions:
    """The options every such benchmark has (its own options dataclass adds its rules).

    Attributes:
        result: the run's result file (None: found beside the bag; the live comparison).
        rules: ``ertools`` (the options of :data:`SCRIPT_GROUP` decide) or a key of
            ``SCRIPTS``, the script versions the benchmark reproduces (commit by version).
        gt_gaps: ``refuse`` (no ground truth across a gap wider than ``max_gap_s``) or
            ``interpolate`` (tf's interpolation, as the script).
        max_gap_s: see ``gt_gaps``.
        confidence, draws, seed: the score intervals.
    """

    SCRIPTS: ClassVar[Mapping[str, str]] = {}

    result: Path | None = None
    rules: str = "ertools"
    gt_gaps: str = "refuse"
    max_gap_s: float = DEFAULT_MAX_GAP_S
    confidence: float = DEFAULT_CONFIDENCE
    draws: int = DEFAULT_DRAWS
    seed: int = DEFAULT_SEED

    @property
    def script(self) -> str | None:
        """The script commit reproduced whole (``--rules``), None for ertools' reading."""
        return self.SCRIPTS.get(self.rules)


def script_values(values: Mapping[str, Any]) -> dict[str, Any]:
    """The fields of :class:`ScriptOptions` from resolved input values: under ``--rules``
    (a script reproduced whole) the ground truth is interpolated across any gap, as tf did."""
    rules = values.get("rules") or "ertools"
    max_gap = values.get("max_gap")
    return {
        "result": values.get("result"),
        "rules": rules,
        "gt_gaps": "interpolate" if rules != "ertools" else values.get("gt_gaps") or "refuse",
        "max_gap_s": DEFAULT_MAX_GAP_S if max_gap is None else float(max_gap),
        "confidence": check_confidence(values.get("confidence", DEFAULT_CONFIDENCE)),
        "draws": int(values.get("draws", DEFAULT_DRAWS)),
        "seed": int(values.get("seed", DEFAULT_SEED)),
    }
