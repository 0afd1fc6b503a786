"""The inputs of ``ertools score trajectory`` (:data:`INPUTS`) and the words its choices take:
all its parser needs. Apart from :mod:`ertools.benchmarks.trajectory.config` (the options'
frozen dataclasses and their checks), which the parser does not import.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Literal

from ertools.benchmarks.base import Input
from ertools.benchmarks.common.inputs import INTERVAL_INPUTS, unscoreable_input
from ertools.io.names import INPUT_FORMATS

if TYPE_CHECKING:  # a Literal: this module stays NumPy-free (the parser imports it)
    from ertools.geometry import Association

ASSOCIATIONS: tuple[Association, ...] = ("linear", "nearest", "hold")

Ties = Literal["at", "before"]
Gaps = Literal["skip", "compare"]
Unscoreable = Literal["null", "2015"]
BeforeGt = Literal["uncovered", "first"]
GtOrder = Literal["time", "chain"]
TIES: tuple[Ties, ...] = ("at", "before")
GAPS: tuple[Gaps, ...] = ("skip", "compare")
UNSCOREABLE: tuple[Unscoreable, ...] = ("null", "2015")
BEFORE_GT: tuple[BeforeGt, ...] = ("uncovered", "first")
GT_ORDERS: tuple[GtOrder, ...] = ("time", "chain")


LEGACY = "2015 behaviour (each difference can be undone)"

INPUTS = (
    Input(
        "robot_topic",
        "str",
        "the robot's pose of its marker set (default: the one /rockin/*/marker_pose)",
        metavar="TOPIC",
    ),
    Input(
        "gt_topic",
        "str",
        "the mocap pose of that marker set (default: the one PoseStamped topic)",
        metavar="TOPIC",
    ),
    Input(
        "association",
        "choice",
        "GT pose at a robot time: interpolated (linear, default), nearest, or the last "
        "before (hold, 2015)",
        choices=ASSOCIATIONS,
        group=LEGACY,
    ),
    Input(
        "ties",
        "choice",
        "with --association hold, a robot pose stamped exactly at a GT sample is compared "
        "with that sample (at, default) or the one before it (before, 2015)",
        choices=TIES,
        group=LEGACY,
    ),
    Input(
        "gaps",
        "choice",
        "robot poses in GT gaps longer than --max-gap: not compared (skip, default) or "
        "compared with the GT pose across the gap and counted (compare, 2015)",
        choices=GAPS,
        group=LEGACY,
    ),
    Input(
        "before_gt",
        "choice",
        "robot poses before the first GT pose: uncovered (default: an error, or not scored "
        "with --allow-partial) or compared with the first GT pose (first, 2015)",
        choices=BEFORE_GT,
        group=LEGACY,
    ),
    Input(
        "gt_order",
        "choice",
        "GT files overlapping in time: their poses merged in time order (time, default) or "
        "the files chained by start time and scanned forward (chain, 2015; needs "
        "--association hold --ties before)",
        choices=GT_ORDERS,
        group=LEGACY,
    ),
    # too few valid pairs make the comparison unscoreable (docs/uncertainty.md)
    unscoreable_input(LEGACY),
    Input(
        "as_2015",
        "flag",
        "compute what the 2015 script did: --association hold --ties before --gaps compare "
        "--before-gt first --gt-order chain --unscoreable 2015 (2015's orientation error is "
        "orientation_error_2015)",
        flag="--2015",
        group=LEGACY,
    ),
    Input(
        "max_gap",
        "float",
        "a robot pose whose surrounding GT poses are further apart is in a GT gap "
        "(default 0.1 s; see --gaps)",
        default=0.1,
        unit="s",
        positive=True,
    ),
    Input(
        "t_max_diff",
        "float",
        "pair as evo does (`evo_ape ... --t_max_diff S`, evo's default 0.01; implies "
        "--association nearest): each pose of the shorter trajectory with the nearest stamp "
        "of the other within S seconds; --max-gap and the tracking-lost rule do not apply",
        unit="s",
        minimum=0.0,
    ),
    Input(
        "offset",
        "str",
        "shift the robot stamps by S seconds, or estimate the shift (auto)",
        default="0",
        metavar="S|auto",
    ),
    Input(
        "apply_offset",
        "flag",
        "with --offset auto: score with the estimated offset (else it is only reported)",
    ),
    Input(
        "offset_range",
        "float",
        "the clock audit searches offsets within +-S seconds (default 5)",
        default=5.0,
        unit="s",
        positive=True,
    ),
    Input(
        "allow_partial",
        "flag",
        "score the covered part when robot poses lie outside the GT",
    ),
    Input(
        "robot_time_source",
        "choice",
        "robot pose time: message stamp (default) or the robot bag's record time (the GT "
        "keeps --time-source)",
        old_flags=("--robot-time",),
        choices=("header", "record"),
    ),
    Input(
        "time_source",
        "choice",
        "the time robot and GT poses are selected and paired by: header stamps (default; "
        "simulation time in a sim bag, as evo uses) or record times",
        choices=("header", "record"),
    ),
    Input(
        "input_format",
        "choice",
        "read every input as this (default: detected by content): a TUM, KITTI (paired row "
        "by row, as evo_ape kitti), EuRoC ground-truth or ertools CSV text trajectory, or a "
        "bag",
        choices=INPUT_FORMATS,
    ),
    *INTERVAL_INPUTS,
)
