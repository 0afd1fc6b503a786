"""The score at the clock offset the audit fits, where the score used another one the data
disagrees with (issue 39): its statistics and their own intervals (``*_at_fitted_offset``),
and the clock audit's warnings, which name it.
"""

from __future__ import annotations

from collections.abc import Callable

from ertools.benchmarks.common.clocks import OffsetEstimate
from ertools.benchmarks.common.inputs import IntervalSettings
from ertools.benchmarks.common.validity import from_codes
from ertools.benchmarks.trajectory.association import Matched
from ertools.benchmarks.trajectory.config import TrajectoryConfig
from ertools.benchmarks.trajectory.formula import Metrics, metrics
from ertools.benchmarks.trajectory.intervals import (
    FITTED_KEYS,
    FITTED_SUFFIX,
    MocapSigma,
    Rescoring,
    trajectory_intervals,
)
from ertools.benchmarks.trajectory.result import FittedScore
from ertools.benchmarks.trajectory.validity import too_few, validity_codes
from ertools.streams import PoseStream
from ertools.timeutil import ns_to_s


def estimates(m: Metrics) -> dict[str, float]:
    """The statistics by interval key (:data:`~ertools.benchmarks.trajectory.intervals.KEYS`)."""
    out = {
        "position_error": m.position_error,
        "orientation_error": m.orientation_error,
        "rmse": m.rmse,
        "median": m.median,
        "max": m.max,
        "orientation_error_2015": m.orientation_error_2015,
    }
    out.update({f"percentiles.p{p:g}": v for p, v in m.percentiles})
    return out


def audit_warnings(
    audit: OffsetEstimate, applied_ns: int, fitted: FittedScore | None = None
) -> list[str]:
    """The clock audit's warnings: no estimate, or one the offset applied disagrees with
    (naming the score at the fitted offset, when it was scored there)."""
    if audit.offset_ns is None:
        return [f"clock audit: no offset estimate ({audit.note})"]
    out = []
    sigma = audit.uncertainty_ns or 0
    if audit.disagrees_with(applied_ns):
        there = ""
        if fitted is not None and fitted.metrics is not None:
            iv = fitted.intervals.get("position_error")
            span = "" if iv is None else f" [{iv.low * 1000:.4g}, {iv.high * 1000:.4g}]"
            there = (
                f"; scored there, position_error{FITTED_SUFFIX} is "
                f"{fitted.metrics.position_error * 1000:.4g}{span} mm (the *{FITTED_SUFFIX} "
                "keys)"
            )
        out.append(
            f"clock audit: the robot stamps fit the GT best shifted by "
            f"{ns_to_s(audit.offset_ns):+.3f} +- {ns_to_s(sigma):.3f} s, but the score uses "
            f"{ns_to_s(applied_ns):+.3f} s{there}; check the clocks, or re-run with "
            "--offset auto --apply-offset"
        )
    if audit.note:
        out.append(f"clock audit: {audit.note}")
    return out


def at_fitted_offset(
    logged: PoseStream,
    timed: PoseStream,
    audit: OffsetEstimate,
    fitted_ns: int,
    match: Callable[[PoseStream, int], Matched],
    rescoring: Callable[[int], Rescoring],
    config: TrajectoryConfig,
    settings: IntervalSettings,
    sigma: MocapSigma,
) -> FittedScore | None:
    """The statistics of :data:`FITTED_KEYS` at the clock offset the audit fits, with their
    intervals (centred there): what ``--offset auto --apply-offset`` would score. None where
    no pose would be compared there, or too few for a score."""
    matched = match(logged, fitted_ns)
    robot = logged if matched.robot_rows is None else logged.take(matched.robot_rows)
    m = metrics(matched)
    if m is None:
        return None
    validity = from_codes(
        validity_codes(matched, int(timed.t_ns[0])),
        matched.t_ns,
        gap_s=ns_to_s(config.max_gap_ns),
    )
    if config.t_max_diff is None and too_few(validity) is not None:
        return None
    iv = trajectory_intervals(
        robot,
        timed,
        matched,
        audit,
        estimates(m),
        association=config.association,
        offset_ns=fitted_ns,
        settings=settings,
        rescoring=rescoring(fitted_ns),
        sigma=sigma,
    )
    kept = {k: iv.intervals.get(k) for k in FITTED_KEYS}
    why = {} if iv.uncertainty is None else iv.uncertainty.withheld
    return FittedScore(fitted_ns, m, kept, {k: why[k] for k in FITTED_KEYS if k in why})
