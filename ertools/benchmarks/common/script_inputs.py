"""The inputs of a benchmark that re-scores an ERL 2017-19 RSBB script's run alike, and the
options they make: the side files (the script's config, the team's transform, the run's result
file and the team, each found in the RSBB's folder layout when not given:
:func:`ertools.rsbb.sidefiles.find_side_files`), the script version reproduced whole
(``--rules``) and the refusal of a rule option that would undo it, how the ground truth is
looked up across a tracking gap (ertools refuses it; the script's tf interpolated) and the
intervals.

NumPy-free: the benchmarks' ``config`` modules list them for the command line's parser.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any, ClassVar

from ertools.benchmarks.base import Input
from ertools.benchmarks.common.inputs import (
    DEFAULT_CONFIDENCE,
    DEFAULT_DRAWS,
    DEFAULT_SEED,
    check_confidence,
)
from ertools.errors import UsageError
from ertools.frozen_dataclass import frozen_dataclass

#: The help section of the options that undo ertools' readings of a script one by one.
SCRIPT_GROUP = "the RSBB script's behaviour (each difference can be undone)"

#: The mocap runs at 100-120 Hz, so 0.1 s is several lost frames (ertools' rule).
DEFAULT_MAX_GAP_S = 0.1

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


@frozen_dataclass
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


TRANSFORM = Input(
    "transform",
    "path",
    "transform-<team>.yaml (markerset_to_robot_transform); default: found beside the "
    "bag or in rsbb_etc/transforms/",
    metavar="FILE",
    per_team=True,
)


def config_input(code: str, contents: str) -> Input:
    """``--config``: the script's ``<CODE>.yaml``, holding ``contents`` (its keys, in words)."""
    return Input(
        "config",
        "path",
        f"{code}.yaml ({contents}); default: found beside the bag or in the RSBB layout, else "
        "the result file's benchmark_info.params",
        metavar="FILE",
    )


def result_input(code: str) -> Input:
    """``--result``: the run's result file, which the recomputed score is compared with."""
    return Input(
        "result",
        "path",
        "the run's result_run_<n>_<date>.yaml, compared with the recomputed score; default: "
        f"found beside the bag or in results/{code}/<team>/",
        metavar="FILE",
    )


def team_input(code: str) -> Input:
    """``--team``: whose transform and result file to look for."""
    return Input(
        "team",
        "str",
        f"the team (default: rsbb_logs/{code}/<team>/ of the bag, else the result file's)",
        metavar="NAME",
        per_team=True,
    )


def refuse_undoing(rules: str, undone: Mapping[str, bool]) -> None:
    """Refuse the rule options (by their flag) that would undo what ``--rules RULES``
    reproduces.

    Raises:
        UsageError: one or more of them is True.
    """
    clash = [flag for flag, undoes in undone.items() if undoes]
    if clash:
        raise UsageError(
            f"--rules {rules} reproduces the script: {', '.join(clash)} would undo it; "
            "give one or the other"
        )
