"""The frozen result of a trajectory comparison (:class:`TrajectoryResult`) and its outputs:
JSON/YAML/text and the CSV tables.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import field
from typing import Any

import numpy as np

from ertools.benchmarks.base import Rows
from ertools.benchmarks.common.clocks import OffsetEstimate
from ertools.benchmarks.common.interval_output import (
    ScoreRow,
    interval_lines,
    interval_tables,
    low_high,
)
from ertools.benchmarks.common.uncertainty import Interval, Uncertainty, interval_keys
from ertools.benchmarks.common.validity import Validity, cell
from ertools.benchmarks.results import ResultBase
from ertools.benchmarks.trajectory.association import (
    COMPARED,
    GAP,
    STATUS_NAMES,
    TRACKING_LOST,
    UNCOVERED,
    UNPAIRED,
    Matched,
)
from ertools.benchmarks.trajectory.config import TrajectoryConfig
from ertools.benchmarks.trajectory.formula import Metrics
from ertools.benchmarks.trajectory.intervals import FITTED_KEYS, FITTED_SUFFIX, KEYS
from ertools.fidelity import Deviation
from ertools.frozen_dataclass import frozen_dataclass
from ertools.streams import PoseStream, Provenance
from ertools.timeutil import NS_PER_S, ns_to_s

# The summary table's statistics that get ``_low``/``_high`` columns (the percentiles have
# their own table).
INTERVAL_COLUMNS = tuple(k for k in KEYS if not k.startswith("percentiles."))


@frozen_dataclass
class FittedScore:
    """The statistics at the clock offset the audit fits, where the score used another one
    the data disagrees with: what ``--offset auto --apply-offset`` would score, beside the
    score (``<key>_at_fitted_offset`` and its interval).

    Attributes:
        offset_ns: the fitted offset.
        metrics: the statistics there.
        intervals: the intervals of :data:`~ertools.benchmarks.trajectory.intervals.
            FITTED_KEYS` there, centred on that offset.
        withheld: why a key of those has no interval (too few poses compared there).
    """

    offset_ns: int
    metrics: Metrics
    intervals: Mapping[str, Interval | None]
    withheld: Mapping[str, str] = field(default_factory=dict)

    def values(self) -> dict[str, float]:
        m = self.metrics
        every = {
            "position_error": m.position_error,
            "orientation_error": m.orientation_error,
            "rmse": m.rmse,
            "median": m.median,
            "max": m.max,
        }
        return {k: every[k] for k in FITTED_KEYS}


@frozen_dataclass(eq=False)
class TrajectoryResult(ResultBase):
    """A scored robot log (implements ``BenchmarkResult``).

    Attributes:
        robot_file, robot_topic, gt_topic: what was compared.
        gt_files: the GT files used, by start time.
        config: the comparison settings.
        offset_ns: the offset applied to the robot stamps.
        metrics: None when no pose could be compared.
        matched: the per-pose association (the error series of the figures).
        robot: the robot stream (stamps on the robot clock).
        gt_path: the GT positions, decimated to at most a few thousand points, for figures.
        audit: the clock-offset estimate.
        uncovered_spans: robot-time spans outside the GT, (start_ns, end_ns) on the GT clock.
        intervals: the confidence interval of each statistic by key (``rmse``,
            ``percentiles.p95``...; :mod:`ertools.benchmarks.trajectory.intervals`); empty
            with ``--draws 0``.
        uncertainty: how the intervals were obtained (None without intervals).
        fitted: the statistics at the offset the clock audit fits, where the score used one
            the data disagrees with (with intervals only; None otherwise).
    """

    robot_file: str
    robot_topic: str
    gt_topic: str
    gt_files: tuple[str, ...]
    config: TrajectoryConfig
    offset_ns: int
    metrics: Metrics | None
    matched: Matched
    robot: PoseStream
    gt_path: PoseStream
    audit: OffsetEstimate
    uncovered_spans: tuple[tuple[int, int], ...] = ()
    warnings: tuple[str, ...] = ()
    deviations: tuple[Deviation, ...] = ()
    failures: tuple[str, ...] = ()
    provenance: Provenance = field(default_factory=Provenance)
    name: str = "trajectory"
    validity: Validity | None = None
    unscoreable_reason: str | None = None
    intervals: Mapping[str, Interval | None] = field(default_factory=dict)
    uncertainty: Uncertainty | None = None
    fitted: FittedScore | None = None

    @property
    def nothing_scored(self) -> bool:
        """No robot pose compared, so no metric: the CLI prints only the failure. An
        unscoreable comparison is a verdict, printed with its null statistics."""
        return self.metrics is None and not self.unscoreable

    @property
    def unscoreable(self) -> bool:
        """Too few valid pairs for statistics (their values null)."""
        return self.metrics is None and self.unscoreable_reason is not None

    def validity_lines(self) -> list[str]:
        """The stderr line: the robot poses' valid fraction and reasons, and the verdict."""
        if self.validity is None:
            return []
        t0 = int(self.matched.t_ns[0]) if len(self.matched.t_ns) else 0
        line = "validity: " + self.validity.text("trajectory", t0)
        if self.unscoreable:
            line += f"; unscoreable: {self.unscoreable_reason}"
        return [line]

    @property
    def compared(self) -> int:
        return self.matched.count(COMPARED)

    @property
    def gaps(self) -> int:
        return self.matched.count(GAP)

    @property
    def tracking_lost(self) -> int:
        return self.matched.count(TRACKING_LOST)

    @property
    def uncovered(self) -> int:
        return self.matched.count(UNCOVERED)

    @property
    def unpaired(self) -> int:
        """Robot poses evo's association (``--t-max-diff``) left without a GT pose."""
        return self.matched.count(UNPAIRED)

    def listing(self) -> dict[Any, Any]:
        """Scores, counts and the clock audit (the keys scripts depend on come first); the YAML
        lists the same (the 2015 script printed two text lines)."""
        m = self.metrics
        a = self.audit
        data: dict[str, Any] = {
            "position_error": None if m is None else m.position_error,
            "orientation_error": None if m is None else m.orientation_error,
            "rmse": None if m is None else m.rmse,
            "median": None if m is None else m.median,
            "max": None if m is None else m.max,
            "compared": self.compared,
            "gaps": self.gaps,
            "tracking_lost": self.tracking_lost,
            "gt_files": list(self.gt_files),
            "association": self.config.association,
            "offset": ns_to_s(self.offset_ns),
            "percentiles": None if m is None else {f"p{p:g}": v for p, v in m.percentiles},
            "orientation_error_2015": None if m is None else m.orientation_error_2015,
            "uncovered": self.uncovered,
            "gaps_compared": self.matched.gaps_compared,
            "before_gt": self.matched.before_gt,
            "ties": self.config.ties,
            "gap_poses": self.config.gaps,
            "before_gt_poses": self.config.before_gt,
            "robot_poses": len(self.matched.t_ns),
            "partial": self.uncovered > 0,
            "uncovered_spans": [[ns_to_s(s), ns_to_s(e)] for s, e in self.uncovered_spans],
            "max_gap": ns_to_s(self.config.max_gap_ns),
            "t_max_diff": self.config.t_max_diff,
            "unpaired": self.unpaired,
            "robot_file": self.robot_file,
            "robot_topic": self.robot_topic,
            "gt_topic": self.gt_topic,
            "clock_audit": {
                "estimated_offset": a.offset_s,
                "uncertainty": a.uncertainty_s,
                "applied": self.config.auto_offset and self.config.apply_offset,
                "residual": None if a.offset_ns is None else ns_to_s(a.offset_ns - self.offset_ns),
                "search_range": ns_to_s(a.search_range_ns),
                "poses_used": a.poses_used,
                "mean_error_at_estimate": a.mean_error,
                "mean_error_at_zero": a.mean_error_at_zero,
                "method": a.method,
                "note": a.note,
            },
            "warnings": list(self.warnings),
            "deviations": list(self.deviations),
        }
        if self.validity is not None:
            data.update(self.validity.fields())
        if self.unscoreable:
            data["status"] = "unscoreable"
        if self.unscoreable_reason is not None:
            data["unscoreable_reason"] = self.unscoreable_reason
        if self.intervals:
            data = interval_keys(data, self.intervals)
            if self.fitted is not None:
                data = _with_fitted(data, self.fitted)
            if isinstance(data["percentiles"], dict):
                pct = {k.split(".", 1)[1]: v for k, v in self.intervals.items() if "." in k}
                data["percentiles"] = interval_keys(data["percentiles"], pct)
        if self.uncertainty is not None:
            data["uncertainty"] = self.uncertainty.to_dict()
        return data

    def tables(self) -> dict[str, Rows]:
        """``samples`` (one row per robot pose: the error series) and ``summary``."""
        mt = self.matched
        t0 = int(mt.t_ns[0]) if len(mt.t_ns) else 0
        ryaw = self.robot.yaw
        rows: Rows = [
            {
                "t": ns_to_s(int(t)),
                "t_rel_s": (int(t) - t0) / NS_PER_S,
                "status": STATUS_NAMES[int(s)],
                "in_gt_gap": bool(g_),
                "robot_x": float(r[0]),
                "robot_y": float(r[1]),
                "robot_z": float(r[2]),
                "robot_yaw": float(ry),
                "gt_x": _f(g[0]),
                "gt_y": _f(g[1]),
                "gt_z": _f(g[2]),
                "gt_yaw": _f(gy),
                "position_error": _f(e),
                "yaw_error": _f(ye),
            }
            for t, s, g_, r, ry, g, gy, e, ye in zip(
                mt.t_ns.tolist(),
                mt.status.tolist(),
                mt.across_gap.tolist(),
                self.robot.xyz,
                ryaw.tolist(),
                mt.gt_xyz,
                mt.gt_yaw.tolist(),
                mt.position_error.tolist(),
                mt.yaw_error.tolist(),
                strict=True,
            )
        ]
        d = self.to_dict()
        summary = {
            k: d[k]
            for k in (
                "position_error",
                "orientation_error",
                "rmse",
                "median",
                "max",
                "compared",
                "gaps",
                "tracking_lost",
                "uncovered",
                "association",
                "offset",
                "orientation_error_2015",
                "gaps_compared",
            )
        }
        summary["estimated_offset"] = d["clock_audit"]["estimated_offset"]
        summary["offset_uncertainty"] = d["clock_audit"]["uncertainty"]
        if "valid_fraction" in d:
            summary["valid_fraction"] = d["valid_fraction"]
            summary["invalid_samples"] = cell(d["invalid_samples"])
        if "unscoreable_reason" in d:
            summary["status"] = d.get("status", "scored")
            summary["unscoreable_reason"] = d["unscoreable_reason"]
        if self.intervals:
            for key in INTERVAL_COLUMNS:
                summary.update(low_high(key, self.intervals.get(key)))
        extra = interval_tables(self.intervals, self.uncertainty)
        return {"samples": rows, "summary": [summary], **extra}


def _f(x: float) -> float | None:
    return None if np.isnan(x) else float(x)


def notes(result: TrajectoryResult) -> list[str]:
    """One stderr line per main statistic with its interval and the sources' shares."""
    m = result.metrics
    if m is None or result.uncertainty is None:
        return []
    iv = result.intervals
    rows = [
        ScoreRow("position_error", m.position_error, iv.get("position_error"), 1000.0, "mm"),
        ScoreRow("rmse", m.rmse, iv.get("rmse"), 1000.0, "mm"),
        ScoreRow("max", m.max, iv.get("max"), 1000.0, "mm"),
        ScoreRow("orientation_error", m.orientation_error, iv.get("orientation_error"), 1.0, "rad"),
    ]
    fit = result.fitted
    if fit is not None:
        # the score at the offset the data fits, beside the clock audit's warning
        fi = fit.intervals
        suffix = FITTED_SUFFIX
        rows += [
            ScoreRow(
                f"position_error{suffix}",
                fit.metrics.position_error,
                fi.get("position_error"),
                1000.0,
                "mm",
            ),
            ScoreRow(
                f"orientation_error{suffix}",
                fit.metrics.orientation_error,
                fi.get("orientation_error"),
                1.0,
                "rad",
            ),
        ]
    return interval_lines(rows, result.uncertainty)


def _with_fitted(data: dict[str, Any], fitted: FittedScore) -> dict[str, Any]:
    """``data`` with ``K_at_fitted_offset`` and its interval after ``K_interval`` for each
    statistic of the fitted score."""
    values = fitted.values()
    out: dict[str, Any] = {}
    for key, value in data.items():
        out[key] = value
        base = key.removesuffix("_interval")
        if key.endswith("_interval") and base in values:
            iv = fitted.intervals.get(base)
            out[f"{base}{FITTED_SUFFIX}"] = values[base]
            out[f"{base}{FITTED_SUFFIX}_interval"] = None if iv is None else iv.as_list()
    return out
