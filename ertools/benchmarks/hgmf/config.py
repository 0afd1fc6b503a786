"""How an HGMF score is computed: its inputs, the options (as data), the script's constants
and :func:`make_options`, which turns the inputs' values into :class:`HgmfOptions`.

NumPy-free: the declaration and the CLI's parser import it.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

from ertools.benchmarks.base import Input, resolve_values
from ertools.benchmarks.common.inputs import (
    DEFAULT_CONFIDENCE,
    DEFAULT_DRAWS,
    DEFAULT_SEED,
    INTERVAL_INPUTS,
    check_confidence,
)
from ertools.benchmarks.common.script_inputs import SCRIPT_GROUP, config_input, result_input
from ertools.errors import UsageError
from ertools.frozen_dataclass import frozen_dataclass
from ertools.rsbb_states import ScriptFrame

NAME = "hgmf"
CODE = "HGMF"

#: The frames its script broadcasts (2bb8a41: ``benchmarks_description.yaml``'s tf helper).
SCRIPT_FRAMES: tuple[ScriptFrame, ...] = (
    ScriptFrame("/object", "/actor_markerset", "/table_origin", 3, 1.0),
)
#: The mocap bodies whose pose topics its runs record.
MOCAP_BODIES = ("table_origin", "actor_markerset")
#: The seasons in which a script for it existed.
SCRIPT_SEASONS = ("2019",)
TITLE = "HGMF (FBM6@Home 2019)"

# fbm6_grasping_manipulation.py at 2bb8a41 (docs/hgmf.md): a grasp is a rise of more than
# 3 cm (l. 270), checked by a 0.1 s timer (l. 176) whose tf wait lasts 0.1 s (l. 264); the
# target area is the table less 0.15 m on each side (l. 66-69).
GRASP_RISE_M = 0.03
CHECK_PERIOD_NS = 100_000_000
CHECK_WAIT_NS = 100_000_000
TABLE_MARGIN_M = 0.15
# The frames the script reads: the object's marker set in the table's frame, and its own
# broadcast at each lookup.
TABLE = "table_origin"
OBJECT_BODY = "actor_markerset"
OBJECT_FRAME = "object"
DEFAULT_MAX_GAP_S = 0.1

SCRIPT_2019 = "fbm6_grasping_manipulation.py at rockin-robot-challenge/rsbb 2bb8a41 (ERL 2019)"
RULE_SETS = ("ertools", "2019")


@frozen_dataclass
class HgmfOptions:
    """Everything ``ertools score hgmf`` can be told.

    Attributes:
        config: ``HGMF.yaml`` (the objects, the table); None: found beside the run in the
            RSBB layout, else the result file's ``benchmark_info.params``.
        result: the run's result file (its params, and the score to compare); None: found
            beside the run.
        rules: ``2019`` (every behaviour of the script at 2bb8a41) or ``ertools``.
        restarted_goals_2019: a restarted goal counts in the divisor and the grasps.
        grasp_timer: grasps checked at the script's inferred 10 Hz ticks (else every sample).
        gaps_interpolate: lookups interpolate across any tracking gap (else ``max_gap_s``).
        max_gap_s: the samples around a lookup may be at most this far apart.
        confidence, draws, seed: the score intervals.
    """

    config: Path | None = None
    result: Path | None = None
    rules: str = "ertools"
    restarted_goals_2019: bool = False
    grasp_timer: bool = False
    gaps_interpolate: bool = False
    max_gap_s: float = DEFAULT_MAX_GAP_S
    confidence: float = DEFAULT_CONFIDENCE
    draws: int = DEFAULT_DRAWS
    seed: int = DEFAULT_SEED

    @property
    def exact(self) -> bool:
        """Every 2019 behaviour at once (the replay's numbers)."""
        return self.restarted_goals_2019 and self.grasp_timer and self.gaps_interpolate


INPUTS = (
    config_input(CODE, "objects, table_size, goal_timeout"),
    result_input(CODE),
    Input(
        "max_gap",
        "float",
        f"a position needs mocap samples at most S seconds apart around the lookup (default "
        f"{DEFAULT_MAX_GAP_S:g})",
        default=DEFAULT_MAX_GAP_S,
        unit="s",
        positive=True,
    ),
    Input(
        "restarted_goals",
        "choice",
        "2019: a goal restarted after its final lookup failed still counts in the divisor and "
        "the grasps (default ertools: the measured goals only)",
        choices=("ertools", "2019"),
        group=SCRIPT_GROUP,
    ),
    Input(
        "grasp_sampling",
        "choice",
        "timer: a grasp checked at the script's 10 Hz ticks, at tf's latest common time "
        "(inferred); default samples: at every mocap sample of the object during the goal",
        choices=("samples", "timer"),
        group=SCRIPT_GROUP,
    ),
    Input(
        "gt_gaps",
        "choice",
        "interpolate: tf's position across any mocap gap (default limit: --max-gap)",
        choices=("limit", "interpolate"),
        group=SCRIPT_GROUP,
    ),
    Input(
        "rules",
        "choice",
        "2019: every behaviour of fbm6_grasping_manipulation.py at rockin-robot-challenge/rsbb "
        "2bb8a41, field for field; ertools (default): the options above decide",
        choices=RULE_SETS,
        group=SCRIPT_GROUP,
    ),
    *INTERVAL_INPUTS,
)


def make_options(given: Mapping[str, Any]) -> HgmfOptions:
    """The values of :data:`INPUTS` (missing ones at their defaults) -> :class:`HgmfOptions`;
    ``--rules 2019`` sets every 2019 behaviour.

    Raises:
        UsageError: a value out of range, or options that contradict each other.
    """
    v = resolve_values(INPUTS, given)
    rules = v.get("rules") or "ertools"
    script = rules == "2019"
    chosen = {
        "restarted_goals": v.get("restarted_goals"),
        "grasp_sampling": v.get("grasp_sampling"),
        "gt_gaps": v.get("gt_gaps"),
    }
    if script:
        for key, value in chosen.items():
            if value is not None and value not in ("2019", "timer", "interpolate"):
                option = "--" + key.replace("_", "-")
                raise UsageError(f"--rules 2019 sets {option} as the script did; not {value}")
    return HgmfOptions(
        config=v.get("config"),
        result=v.get("result"),
        rules=rules,
        restarted_goals_2019=script or chosen["restarted_goals"] == "2019",
        grasp_timer=script or chosen["grasp_sampling"] == "timer",
        gaps_interpolate=script or chosen["gt_gaps"] == "interpolate",
        max_gap_s=float(v.get("max_gap") or DEFAULT_MAX_GAP_S),
        confidence=check_confidence(float(v.get("confidence") or DEFAULT_CONFIDENCE)),
        draws=int(v.get("draws", DEFAULT_DRAWS)),
        seed=int(v.get("seed", DEFAULT_SEED)),
    )
