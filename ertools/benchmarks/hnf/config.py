"""HNF's inputs and options: which reading of the script (``--rules``) and each rule's own
option, and :func:`make_options`, every check of their values.

NumPy-free: the declaration and the CLI's parser import it.
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from ertools.benchmarks.base import Input, resolve_values
from ertools.benchmarks.common.inputs import INTERVAL_INPUTS, check_confidence
from ertools.benchmarks.common.script_inputs import (
    SCRIPT_GROUP,
    TRANSFORM,
    config_input,
    refuse_undoing,
    result_input,
    team_input,
)
from ertools.frozen_dataclass import frozen_dataclass
from ertools.rsbb_states import ScriptFrame

#: ``--rules``: ertools' reading, or a version of the script (docs/hnf.md, "2017-18").
#: 2019 = rockin-robot-challenge/rsbb 2bb8a41; 2017 = Enri2077/rsbb 00e3106 (December 2017 to
#: May 2018); f594ff1 (4 November to 15 December 2017); 069fd1d (2-4 November 2017).
RULE_SETS = ("ertools", "2019", "2017", "f594ff1", "069fd1d")
#: The script's commit each ``--rules`` value reproduces.
SCRIPT_COMMITS = {
    "2019": "2bb8a41",
    "2017": "00e3106",
    "f594ff1": "f594ff1",
    "069fd1d": "069fd1d",
}
#: The season a script version served (the ``differs from`` lines of the default name 2019).
SEASONS = {"2bb8a41": "2019", "00e3106": "2017", "f594ff1": "2017", "069fd1d": "2017"}

#: The frames its script broadcasts (2bb8a41: ``benchmarks_description.yaml``'s tf helper).
SCRIPT_FRAMES: tuple[ScriptFrame, ...] = (
    ScriptFrame("/robot", "/robot_markerset", "/testbed_origin", 5, 1.0),
)
#: The mocap bodies whose pose topics its runs record.
MOCAP_BODIES = ("robot_markerset", "actor_markerset")
#: The seasons in which a script for it existed.
SCRIPT_SEASONS = ("2017", "2019")

_NUMBER = r"(-?\d+(?:\.\d+)?(?:[eE][-+]?\d+)?)"
#: The live robot_pose as the RefBox logged it: a Pose2D as PyYAML dumped it.
_POSE_DUMP = re.compile(rf"Pose2D\s+state: \[{_NUMBER}, {_NUMBER}, {_NUMBER}\]")


def pose_dump(value: str) -> tuple[tuple[str, float], ...] | None:
    """The x, y and theta of a live ``robot_pose`` dump, keyed by quantity; None: not one."""
    pose = _POSE_DUMP.search(value)
    if pose is None:
        return None
    return tuple(
        (key, float(pose.group(i))) for i, key in enumerate(("x", "y", "robot_pose.theta"), 1)
    )


#: Default largest interval between the mocap samples a pose is interpolated across (ertools'
#: reading): 12 frames of the RSBB's 120 Hz OptiTrack; a body lost for longer is not measured.
DEFAULT_MAX_GAP_S = 0.1


@frozen_dataclass
class HnfOptions:
    """How to score an HNF run.

    Attributes:
        config, transform, result: the side files given (None: found beside the bag).
        team: the team (None: from the layout or the result file).
        rules: one of :data:`RULE_SETS`.
        script: the script's commit followed for the control flow (2bb8a41 by default: its
            flow is 2019's; ertools' reading changes the arithmetic only).
        orientation_2019: the totals from sin/cos of the unwrapped |dtheta| (the script's).
        divisor_2019: the sums over every acquired pose divided by the completed goals.
        stopped_2019: a run stopped before its last pose has no totals.
        gaps_interpolate: tf's interpolation across any mocap gap (else refused beyond
            ``max_gap_s``).
        max_gap_s: the largest mocap interval a pose is interpolated across.
        score_format_2019: target and robot poses as the script's YAML dumps (else mappings).
        confidence, draws, seed: the intervals.
    """

    config: Path | None = None
    transform: Path | None = None
    result: Path | None = None
    team: str | None = None
    rules: str = "ertools"
    script: str = "2bb8a41"
    orientation_2019: bool = False
    divisor_2019: bool = False
    stopped_2019: bool = False
    gaps_interpolate: bool = False
    max_gap_s: float = DEFAULT_MAX_GAP_S
    score_format_2019: bool = False
    confidence: float = 0.95
    draws: int = 0
    seed: int = 0

    @property
    def faithful(self) -> bool:
        """Every rule as a script had it (``--rules`` names a script version)."""
        return self.rules != "ertools"


INPUTS = (
    config_input("HNF", "waypoints, goal_timeout"),
    TRANSFORM,
    result_input("HNF"),
    team_input("HNF"),
    Input(
        "max_gap",
        "float",
        f"a pose needs mocap samples at most S seconds apart around the lookup (default "
        f"{DEFAULT_MAX_GAP_S:g})",
        default=DEFAULT_MAX_GAP_S,
        unit="s",
        positive=True,
    ),
    Input(
        "orientation_2019",
        "flag",
        "orientation accuracy from the unwrapped |dtheta| as the script summed it",
        group=SCRIPT_GROUP,
    ),
    Input(
        "divisor",
        "choice",
        "2019: every acquired pose's error (timed-out goals too) divided by the completed "
        "goals, a skipped waypoint counted (default ertools: the completed goals with a pose)",
        choices=("ertools", "2019"),
        group=SCRIPT_GROUP,
    ),
    Input(
        "gt_gaps",
        "choice",
        "interpolate: tf's pose across any mocap gap (default refuse: beyond --max-gap)",
        choices=("refuse", "interpolate"),
        group=SCRIPT_GROUP,
    ),
    Input(
        "score_format",
        "choice",
        "2019: target_pose and robot_pose as the script's YAML dumps (default ertools: "
        "{x, y, theta})",
        choices=("ertools", "2019"),
        group=SCRIPT_GROUP,
    ),
    Input(
        "rules",
        "choice",
        "a script's every behaviour: 2019 (rockin-robot-challenge/rsbb 2bb8a41), 2017 "
        "(Enri2077/rsbb 00e3106, December 2017 to May 2018), f594ff1 and 069fd1d (November "
        "2017); ertools (default): the options above decide",
        choices=RULE_SETS,
        group=SCRIPT_GROUP,
    ),
    *INTERVAL_INPUTS,
)


def make_options(given: Mapping[str, Any]) -> HnfOptions:
    """The values of :data:`INPUTS` (missing ones at their defaults) -> :class:`HnfOptions`.

    Raises:
        UsageError: a value out of range, or a rule option that contradicts ``--rules``.
    """
    v = resolve_values(INPUTS, given)
    check_confidence(v["confidence"])
    rules = str(v["rules"] or "ertools")
    script = SCRIPT_COMMITS.get(rules, "2bb8a41")
    faithful = rules != "ertools"
    if faithful:
        refuse_undoing(
            rules,
            {
                "--divisor": v["divisor"] not in (None, "2019"),
                "--gt-gaps": v["gt_gaps"] not in (None, "interpolate"),
                "--score-format": v["score_format"] not in (None, "2019"),
            },
        )
    return HnfOptions(
        config=v["config"],
        transform=v["transform"],
        result=v["result"],
        team=v["team"],
        rules=rules,
        script=script,
        orientation_2019=faithful or bool(v["orientation_2019"]),
        divisor_2019=faithful or v["divisor"] == "2019",
        stopped_2019=faithful,
        gaps_interpolate=faithful or v["gt_gaps"] == "interpolate",
        max_gap_s=float(v["max_gap"]),
        score_format_2019=faithful or v["score_format"] == "2019",
        confidence=float(v["confidence"]),
        draws=int(v["draws"]),
        seed=int(v["seed"]),
    )
