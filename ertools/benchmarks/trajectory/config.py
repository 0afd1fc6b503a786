"""The options of ``ertools score trajectory``: the settings of a comparison
(:class:`TrajectoryConfig`), what ``--2015`` selects (:data:`SETTINGS_2015`), and
:func:`make_options`, from the values of its inputs (:data:`INPUTS`, in
:mod:`ertools.benchmarks.trajectory.inputs`: the parser imports that module, not this one).
NumPy-free.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import field
from types import MappingProxyType
from typing import TYPE_CHECKING, Any

from ertools.benchmarks.base import resolve_values
from ertools.benchmarks.common.inputs import IntervalSettings
from ertools.benchmarks.trajectory.inputs import (
    ASSOCIATIONS,
    BEFORE_GT,
    GAPS,
    GT_ORDERS,
    INPUTS,
    TIES,
    UNSCOREABLE,
    BeforeGt,
    Gaps,
    GtOrder,
    Ties,
    Unscoreable,
)
from ertools.errors import ConfigError, UsageError
from ertools.frozen_dataclass import frozen_dataclass
from ertools.timeutil import MAX_SECONDS, NS_PER_S, s_to_ns

if TYPE_CHECKING:  # a Literal: this module stays NumPy-free (the parser imports it)
    from ertools.geometry import Association


@frozen_dataclass
class TrajectoryConfig:
    """How to compare.

    Attributes:
        association: ``linear`` (default), ``nearest`` or ``hold`` (2015).
        max_gap_ns: robot poses whose surrounding GT poses are further apart are in a GT gap.
        offset_ns: added to the robot stamps before comparing (``--offset S``).
        auto_offset: ``--offset auto``: estimate the offset (always done for the audit).
        apply_offset: with ``auto_offset``, score with the estimate.
        offset_range_ns: the audit searches offsets within +- this.
        allow_partial: score the covered part when robot poses lie outside the GT.
        ties: with ``hold``, a robot pose stamped exactly at a GT sample is compared with that
            sample (``at``) or with the one before it (``before``, 2015).
        gaps: robot poses in GT gaps are not compared (``skip``) or compared with the GT pose
            given by the association, counted and warned about (``compare``, 2015).
        before_gt: robot poses before the first GT pose are uncovered (``uncovered``) or
            compared with the first GT pose (``first``, 2015).
        gt_order: the GT poses of all files merged in time order (``time``), or the files
            chained by start time, each in record order, and scanned forward as 2015 did
            (``chain``; with ``hold`` and ``ties`` ``before`` only: 2015's scan).
        t_max_diff: with ``nearest``, pair as evo does (``--t-max-diff``): the nearest stamp
            within this many seconds, float seconds as evo compares them (its ``max_diff``);
            ``max_gap_ns`` and the tracking-lost rule then do not apply. None: ertools' rule.
        unscoreable: a comparison with too few valid pairs is ``unscoreable``, its statistics
            null (``null``), or scored from them with a warning (``2015``); see
            :mod:`ertools.benchmarks.trajectory.comparison`.
    """

    association: Association = "linear"
    max_gap_ns: int = NS_PER_S // 10
    offset_ns: int = 0
    auto_offset: bool = False
    apply_offset: bool = False
    offset_range_ns: int = 5 * NS_PER_S
    allow_partial: bool = False
    ties: Ties = "at"
    gaps: Gaps = "skip"
    before_gt: BeforeGt = "uncovered"
    gt_order: GtOrder = "time"
    t_max_diff: float | None = None
    unscoreable: Unscoreable = "null"

    def __post_init__(self) -> None:
        if self.association not in ASSOCIATIONS:
            raise ConfigError(
                f"association {self.association!r} unknown; choose from {', '.join(ASSOCIATIONS)}"
            )
        for name, value, allowed in (
            ("ties", self.ties, TIES),
            ("gaps", self.gaps, GAPS),
            ("before-gt", self.before_gt, BEFORE_GT),
            ("gt-order", self.gt_order, GT_ORDERS),
            ("unscoreable", self.unscoreable, UNSCOREABLE),
        ):
            if value not in allowed:
                raise ConfigError(f"--{name} {value!r} unknown; choose from {', '.join(allowed)}")
        if self.ties == "before" and self.association != "hold":
            # Only the held pose depends on the tie rule: linear and nearest give the sample at
            # the robot time whichever pair brackets it.
            raise ConfigError(f"--ties before needs --association hold (not {self.association})")
        if self.gt_order == "chain" and (self.association, self.ties) != ("hold", "before"):
            # The chained poses are out of time order where files overlap: only 2015's forward
            # scan (hold, the pose before a tie) says which pose a robot time is paired with.
            raise ConfigError(
                "--gt-order chain needs --association hold --ties before (2015's scan)"
            )
        if self.t_max_diff is not None:
            if self.association != "nearest":
                raise ConfigError(
                    f"--t-max-diff needs --association nearest (not {self.association}): "
                    "it is evo's nearest-stamp pairing"
                )
            if not (math.isfinite(self.t_max_diff) and self.t_max_diff >= 0):
                raise ConfigError(
                    f"--t-max-diff must be a finite number of seconds >= 0, not {self.t_max_diff}"
                )
            if self.gaps != "skip" or self.before_gt != "uncovered":
                raise ConfigError(
                    "--t-max-diff pairs as evo does: --gaps and --before-gt do not apply"
                )
        if self.max_gap_ns <= 0:
            raise ConfigError(f"--max-gap must be positive, not {self.max_gap_ns / NS_PER_S} s")
        if self.offset_range_ns <= 0:
            raise ConfigError("--offset-range must be positive")

    @classmethod
    def of_2015(cls, **overrides: Any) -> TrajectoryConfig:
        """Every 2015 behaviour of ``rockin_trajectory_benchmark.py`` at once (``--2015``).

        Hold association with 2015's tie rule, GT gaps compared against the held pose, robot
        poses before the first GT pose compared with it. ``overrides`` set the other fields
        (offset, max-gap, allow-partial).
        """
        return cls(**{**SETTINGS_2015, **overrides})


# What ``--2015`` selects: each is one option on its own (docs/trajectory.md, the RULE_*
# constants below). Read-only: the CLI and of_2015 copy it.
SETTINGS_2015: Mapping[str, str] = MappingProxyType(
    {
        "association": "hold",
        "ties": "before",
        "gaps": "compare",
        "before_gt": "first",
        "gt_order": "chain",
        "unscoreable": "2015",
    }
)


@frozen_dataclass
class TrajectoryOptions:
    """Everything ``ertools score trajectory`` can be told: how to compare (``config``) and
    where the poses are.

    Attributes:
        config: association, gaps, offset, coverage (:class:`TrajectoryConfig`).
        robot_topic: the robot's pose of its marker set (None: the one
            ``/rockin/*/marker_pose``).
        gt_topic: the mocap pose of that marker set (None: the one PoseStamped topic).
        robot_time: ``header`` (message stamps) or ``record`` (the robot bag's record time).
        gt_time: the same for the GT (``--time-source`` sets both).
        input_format: ``tum``, ``kitti``, ``euroc``, ``csv`` or ``bag`` for every input
            (``--input-format``); None: detected by content (:func:`ertools.io.text.sniff`).
        intervals: level, draws and seed of the statistics' confidence intervals.
    """

    config: TrajectoryConfig = field(default_factory=TrajectoryConfig)
    robot_topic: str | None = None
    gt_topic: str | None = None
    robot_time: str = "header"
    gt_time: str = "header"
    input_format: str | None = None
    intervals: IntervalSettings = field(default_factory=IntervalSettings)


def _2015_options() -> str:
    return " ".join(f"--{k.replace('_', '-')} {v}" for k, v in SETTINGS_2015.items())


def _offset(text: str) -> float | None:
    """Seconds, or None for ``auto``."""

    if text == "auto":
        return None
    try:
        value = float(text)
    except ValueError:
        raise UsageError(f"--offset takes seconds or 'auto', not {text!r}") from None
    if not (math.isfinite(value) and abs(value) < MAX_SECONDS):
        raise UsageError(
            f"--offset {text}: give a finite number smaller than {MAX_SECONDS:g} s in size "
            "or 'auto'"
        )
    return value


def make_options(given: Mapping[str, Any]) -> TrajectoryOptions:
    """The values of :data:`INPUTS` -> :class:`TrajectoryOptions`.

    Raises:
        UsageError: a value out of range, or options that contradict each other (exit 2).
    """
    v = resolve_values(INPUTS, given)
    offset = _offset(v["offset"])
    auto = offset is None
    if v["apply_offset"] and not auto:
        raise UsageError("--apply-offset needs --offset auto")
    chosen = {
        k: v[k] for k in ("association", "ties", "gaps", "before_gt", "gt_order", "unscoreable")
    }
    settings = {k: value for k, value in chosen.items() if value is not None}
    if v["as_2015"]:
        clash = [
            f"--{k.replace('_', '-')} {value}"
            for k, value in settings.items()
            if SETTINGS_2015[k] != value
        ]
        if clash:
            raise UsageError(f"--2015 sets {_2015_options()}; it cannot take {', '.join(clash)}")
        settings = dict(SETTINGS_2015)
    if v["t_max_diff"] is not None and "association" not in settings:
        settings["association"] = "nearest"  # evo's pairing is a nearest-stamp one
    if settings.get("ties") == "before" and settings.get("association") != "hold":
        raise UsageError("--ties before needs --association hold")
    try:
        config = TrajectoryConfig(
            **settings,
            max_gap_ns=s_to_ns(v["max_gap"]),
            offset_ns=0 if offset is None else s_to_ns(offset),
            auto_offset=auto,
            apply_offset=v["apply_offset"],
            offset_range_ns=s_to_ns(v["offset_range"]),
            allow_partial=v["allow_partial"],
            t_max_diff=v["t_max_diff"],
        )
    except ConfigError as err:
        raise UsageError(err.message) from None
    both = v["time_source"]
    robot_time = v["robot_time_source"]
    if both is not None and robot_time is not None and both != robot_time:
        raise UsageError(
            f"--time-source {both} sets the robot's time too: it cannot take "
            f"--robot-time-source {robot_time}"
        )
    return TrajectoryOptions(
        config,
        v["robot_topic"],
        v["gt_topic"],
        robot_time or both or "header",
        both or "header",
        v["input_format"],
        IntervalSettings.from_values(v),
    )
