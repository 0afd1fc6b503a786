"""The settings of a trajectory comparison (:class:`TrajectoryConfig`) and what ``--2015``
selects (:data:`SETTINGS_2015`).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from types import MappingProxyType
from typing import Any, Literal

from ertools.errors import ConfigError
from ertools.geometry import (
    Association,
)
from ertools.timeutil import NS_PER_S

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


@dataclass(frozen=True)
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
