"""HPFF's inputs and options: the script's reading (``--rules 2019``) or ertools', rule by
rule, and :func:`make_options`, every check of their values.

NumPy-free: the declaration and the CLI's parser import it.
"""

from __future__ import annotations

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

RULE_SETS = ("ertools", "2019")

#: The frames its script broadcasts (2bb8a41: ``benchmarks_description.yaml``'s tf helper).
SCRIPT_FRAMES: tuple[ScriptFrame, ...] = (
    ScriptFrame("/robot", "/robot_markerset", "/actor_markerset", 1, 0.2),
    ScriptFrame("/robot", "/robot_markerset", "/testbed_origin", 1, 0.2),
)
#: The mocap bodies whose pose topics its runs record.
MOCAP_BODIES = ("robot_markerset", "actor_markerset")
#: The seasons in which a script for it existed.
SCRIPT_SEASONS = ("2019",)
SCRIPT_COMMIT = "2bb8a41"
#: The script's sampling period and settling sleep (fbm5_person_following.py l. 96, 140).
PERIOD_S = 0.5
SETTLE_S = 8.0
#: The duration rule's margin around goal_timeout (l. 151-153).
MARGIN_S = 15.0
#: ertools' reading: a body interpolated across at most this between its samples.
DEFAULT_MAX_GAP_S = 0.1


@frozen_dataclass
class HpffOptions:
    """How to score an HPFF run.

    Attributes:
        config, transform, result, team: the side files (None: found beside the bag).
        rules: ``ertools`` or ``2019``.
        sampling_script: the script's own samples (its logged lookups) rather than a 2 Hz grid.
        plane_actor: the distance in the cap's frame (the script's) rather than horizontal.
        clock_script: the duration from the script's start to its loop's end rather than the
            RefBox's goal start and end.
        stopped_2019: a stopped run scores ``{}``.
        max_gap_s: the widest mocap interval a body is interpolated across (grid sampling).
        confidence, draws, seed: the intervals.
    """

    config: Path | None = None
    transform: Path | None = None
    result: Path | None = None
    team: str | None = None
    rules: str = "ertools"
    sampling_script: bool = False
    plane_actor: bool = False
    clock_script: bool = False
    stopped_2019: bool = False
    max_gap_s: float = DEFAULT_MAX_GAP_S
    confidence: float = 0.95
    draws: int = 0
    seed: int = 0

    @property
    def faithful(self) -> bool:
        return self.rules == "2019"


INPUTS = (
    config_input("HPFF", "distances, goal_timeout"),
    TRANSFORM,
    result_input("HPFF"),
    team_input("HPFF"),
    Input(
        "max_gap",
        "float",
        f"grid samples: a body interpolated across at most S seconds between its mocap samples "
        f"(default {DEFAULT_MAX_GAP_S:g})",
        default=DEFAULT_MAX_GAP_S,
        unit="s",
        positive=True,
    ),
    Input(
        "sampling",
        "choice",
        "script: the script's own samples (its lookups; a lookup failed when the data came "
        "0.2 s late) (default grid: every 0.5 s, both bodies interpolated)",
        choices=("grid", "script"),
        group=SCRIPT_GROUP,
    ),
    Input(
        "distance_plane",
        "choice",
        "actor: the distance in the cap's frame, as the script (default testbed: horizontal)",
        choices=("testbed", "actor"),
        group=SCRIPT_GROUP,
    ),
    Input(
        "duration_clock",
        "choice",
        "script: from the script's start to its loop's end (default refbox: the goal's start "
        "to its end)",
        choices=("refbox", "script"),
        group=SCRIPT_GROUP,
    ),
    Input(
        "rules",
        "choice",
        "2019: the script's every behaviour (rockin-robot-challenge/rsbb 2bb8a41, a stopped "
        "run's score {}); ertools (default): the options above decide",
        choices=RULE_SETS,
        group=SCRIPT_GROUP,
    ),
    *INTERVAL_INPUTS,
)


def make_options(given: Mapping[str, Any]) -> HpffOptions:
    """The values of :data:`INPUTS` (missing ones at their defaults) -> :class:`HpffOptions`.

    Raises:
        UsageError: a value out of range, or a rule option that contradicts ``--rules 2019``.
    """
    v = resolve_values(INPUTS, given)
    check_confidence(v["confidence"])
    rules = str(v["rules"] or "ertools")
    faithful = rules == "2019"
    if faithful:
        refuse_undoing(
            rules,
            {
                "--sampling": v["sampling"] == "grid",
                "--distance-plane": v["distance_plane"] == "testbed",
                "--duration-clock": v["duration_clock"] == "refbox",
            },
        )
    return HpffOptions(
        config=v["config"],
        transform=v["transform"],
        result=v["result"],
        team=v["team"],
        rules=rules,
        sampling_script=faithful or v["sampling"] == "script",
        plane_actor=faithful or v["distance_plane"] == "actor",
        clock_script=faithful or v["duration_clock"] == "script",
        stopped_2019=faithful,
        max_gap_s=float(v["max_gap"]),
        confidence=float(v["confidence"]),
        draws=int(v["draws"]),
        seed=int(v["seed"]),
    )
