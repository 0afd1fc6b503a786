"""The pure scoring of a robot stream against a GT stream (:func:`score_streams`): checks and
cleans both, runs the clock audit, applies the offset, associates, measures, and says where
ertools differs from the 2015 script.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import replace

import numpy as np
import numpy.typing as npt

from ertools.arrays import I64
from ertools.benchmarks import registry
from ertools.benchmarks.common.clocks import OffsetEstimate, search_offset, with_zero
from ertools.benchmarks.common.hygiene import (
    drop_duplicates,
    drop_invalid,
    frame_change_warning,
    impossible_samples,
    impossible_warning,
)
from ertools.benchmarks.common.inputs import IntervalSettings
from ertools.benchmarks.common.interval_output import NO_INTERVALS, ResultIntervals, shares_of
from ertools.benchmarks.common.teams import parse_robot_log_name
from ertools.benchmarks.common.uncertainty import few_warning
from ertools.benchmarks.common.validity import (
    from_codes,
)
from ertools.benchmarks.trajectory.association import (
    COMPARED,
    GAP,
    TRACKING_LOST,
    UNCOVERED,
    UNPAIRED,
    Matched,
    associate,
    associate_evo,
)
from ertools.benchmarks.trajectory.config import TrajectoryConfig
from ertools.benchmarks.trajectory.fitted import at_fitted_offset, audit_warnings, estimates
from ertools.benchmarks.trajectory.formula import Metrics, metrics
from ertools.benchmarks.trajectory.intervals import (
    FITTED_SUFFIX,
    Finish,
    MocapSigma,
    Rescoring,
    jitter,
    prepare_intervals,
    trajectory_intervals,
)
from ertools.benchmarks.trajectory.result import FittedScore, TrajectoryResult
from ertools.benchmarks.trajectory.rules import (
    RULE_ASSOCIATION,
    RULE_BEFORE_GT,
    RULE_GAPS,
    RULE_INVALID_POSES,
    RULE_TIES,
    RULE_UNSCOREABLE,
    RULE_YAW_WRAP,
)
from ertools.benchmarks.trajectory.validity import too_few, validity_codes
from ertools.cores import alongside
from ertools.errors import ClockError, ScoringError
from ertools.fidelity import Deviation
from ertools.streams import PoseStream, Provenance, float_seconds
from ertools.timeutil import iso_utc, ns_to_s

DEFAULT_INTERVALS = IntervalSettings()


def check_increasing(robot: PoseStream, where: str) -> None:
    """Raise when the robot stamps (in recording order) do not strictly increase."""
    if len(robot) < 2:
        return
    bad = np.flatnonzero(robot.t_ns[1:] <= robot.t_ns[:-1])
    if bad.size:
        i = int(bad[0]) + 1
        raise ScoringError(
            f"{where}: robot stamps do not increase: message {i} is stamped "
            f"{iso_utc(int(robot.t_ns[i]))}, not after message {i - 1} at "
            f"{iso_utc(int(robot.t_ns[i - 1]))} ({bad.size} such place(s)); "
            "fix the robot's clock or use --robot-time-source record"
        )


def _prepared(
    robot: PoseStream,
    gt: PoseStream,
    first: Matched | None,
    m: Metrics | None,
    config: TrajectoryConfig,
    intervals: IntervalSettings,
    sigma: MocapSigma | None,
) -> Finish | None:
    """The intervals' part the clock audit does not decide (:func:`prepare_intervals`) of the
    association ``first`` with the statistics ``m``, while the audit runs: None where the
    score will compare another robot stream (evo's pairs may repeat robot poses), has no
    statistics or intervals, or where an error came up, which the comparison then meets
    where it always did."""
    if first is None or first.robot_rows is not None or m is None or sigma is None:
        return None
    try:
        return prepare_intervals(
            robot,
            gt,
            first,
            estimates(m),
            association=config.association,
            settings=intervals,
            sigma=sigma,
        )
    except Exception:
        return None


def _decimate(stream: PoseStream, limit: int = 5000) -> PoseStream:
    step = max(1, len(stream) // limit)
    return stream.take(slice(None, None, step))


def score_streams(
    robot: PoseStream,
    gt: PoseStream,
    config: TrajectoryConfig,
    *,
    robot_file: str = "",
    robot_topic: str = "",
    gt_topic: str = "",
    gt_files: Sequence[str] = (),
    warnings: Sequence[str] = (),
    intervals: IntervalSettings = DEFAULT_INTERVALS,
) -> TrajectoryResult:
    """Compare a robot stream (stamps on the robot clock, recording order) with GT.

    ``intervals``: level, draws and seed of the statistics' confidence intervals
    (:mod:`ertools.benchmarks.trajectory.intervals`; draws 0: none).

    Raises:
        ScoringError: robot stamps not strictly increasing, or empty streams.
        ClockError: robot poses outside the GT without ``allow_partial``, or no overlap at all.
    """
    where = f"{robot_file}:{robot_topic}" if robot_file else "robot log"
    if len(robot) == 0:
        raise ScoringError(f"{where}: no robot poses")
    if len(gt) < 2:
        raise ScoringError(f"GT {gt_topic}: {len(gt)} pose(s) in the robot log's span")
    check_increasing(robot, where)
    notes = [*warnings, *_other_benchmark_gt(robot_file, gt_topic)]
    notes.extend(w for w in (frame_change_warning(gt), frame_change_warning(robot)) if w)
    # a robot's estimate may jump (relocalising): only the measured GT's jumps are impossible
    # (found once for the warnings and the drop below: an hour of GT's costs tens of ms)
    streams = gt, robot
    found = (
        impossible_samples(gt.t_ns, gt.xyz),
        impossible_samples(robot.t_ns, robot.xyz, jumps=False),
    )
    notes.extend(
        w
        for w in (
            impossible_warning(gt, found=found[0]),
            impossible_warning(robot, jumps=False, found=found[1]),
        )
        if w
    )
    evo = config.t_max_diff is not None
    invalid: list[Deviation] = []
    if config.gt_order == "time" and not evo:
        # evo keeps every pose it read: a sample recorded twice is two poses to it.
        gt, dropped = drop_duplicates(gt)
        if dropped:
            notes.append(
                f"{dropped} GT sample(s) recorded twice (overlapping GT files) were used once"
            )
    # (the GT without duplicates is another stream: its impossible samples found again)
    gt, bad_gt = drop_invalid(gt, found=found[0] if gt is streams[0] else None)
    robot, bad_robot = drop_invalid(robot, jumps=False, found=found[1])
    if bad_gt:
        notes.append(f"{bad_gt} GT sample(s) with NaN, zero-norm or impossible poses ignored")
    if bad_gt or bad_robot:
        invalid.append(
            RULE_INVALID_POSES.deviation(
                f"{bad_gt} GT and {bad_robot} robot pose(s) with NaN, zero-norm quaternions or "
                "physically impossible positions ignored (2015 used them: a NaN or absurd "
                "score, or a yaw of 0)"
            )
        )
    if bad_robot:
        notes.append(f"{bad_robot} robot pose(s) with NaN, zero-norm or impossible poses ignored")
    if len(robot) == 0:
        raise ScoringError(
            f"{where}: no valid robot poses left to compare (NaN or zero quaternions)"
        )
    if len(gt) < 2:
        raise ScoringError(
            f"GT {gt_topic} in {', '.join(gt_files) or 'the GT files'}: {len(gt)} valid pose(s) "
            "left in the robot log's span (the others are NaN or zero quaternions)"
        )
    # ``gt`` is in reading order with --gt-order chain (2015's scan); the clock audit, the
    # coverage messages and the figures want it in time order.
    timed = gt
    if config.gt_order == "chain":
        back = int(np.count_nonzero(gt.t_ns[1:] < gt.t_ns[:-1]))
        if back:
            timed = gt.take(np.argsort(gt.t_ns, kind="stable"))
            notes.append(
                f"the GT files chained by start time go back in time at {back} place(s) (files "
                "overlapping): scanned in that order as 2015 did, which warned 'poses out of "
                "order: result may be invalid' (--gt-order chain)"
            )
    logged = robot  # the robot poses as logged (evo's association may repeat some)

    def match(part: PoseStream, at: int) -> Matched:
        """The score's association of the robot poses ``part`` at the clock offset ``at``
        (the score's own, at the offset applied; the intervals' offset draws re-score with it
        at shifted offsets)."""
        if config.t_max_diff is not None:
            return associate_evo(
                part,
                gt,
                float_seconds(part),
                float_seconds(gt),
                config.t_max_diff,
                ns_to_s(at),
                at,
            )
        return match_rows(part, at)

    def match_rows(part: PoseStream, at: int | I64) -> Matched:
        """:func:`associate`, row by row: ``at`` one offset, or one per pose."""
        return associate(
            PoseStream(
                part.t_ns + at,
                part.xyz,
                part.quat_xyzw,
                part.frame_id,
                part.child_frame_id,
                part.source,
            ),
            gt,
            config.association,
            config.max_gap_ns,
            ties=config.ties,
            gaps=config.gaps,
            before_gt=config.before_gt,
            gt_order=config.gt_order,
        )

    def rescoring(at: int) -> Rescoring:
        """How the intervals' offset draws re-score the comparison around the offset ``at``:
        all shifts in one association, except evo's (not row by row)."""

        def rescore(rows: npt.NDArray[np.intp], shift_ns: int) -> Matched:
            return match(logged.take(rows), at + shift_ns)

        def rescore_shifted(rows: npt.NDArray[np.intp], shifts_ns: I64) -> Matched:
            return match_rows(logged.take(rows), at + shifts_ns)

        shifted = None if config.t_max_diff is not None else rescore_shifted
        gap = None if shifted is None else config.max_gap_ns
        return Rescoring(logged.t_ns + at, rescore, shifted, gap)

    # With the offset known beforehand the score associates while the clock audit searches on
    # a second core; at no offset the score's pairs are the audit's own (the same robot and GT
    # poses, interpolated by the same rule), and the audit takes their mean distance
    # afterwards instead of pairing the poses once more.
    applied = config.auto_offset and config.apply_offset

    def audited() -> tuple[OffsetEstimate, bool]:
        return search_offset(
            robot,
            timed,
            search_range_ns=config.offset_range_ns,
            max_gap_ns=config.max_gap_ns,
            zero_given=not applied and _same_rule(config),
        )

    with alongside(audited, parallel=not applied) as audit_of:
        first = None if applied else match(robot, config.offset_ns)
        # the GT's noise and what else the intervals need that the audit does not decide:
        # computed meanwhile too (wasted only when the comparison has no statistics)
        sigma = jitter(timed) if intervals.enabled and first is not None else None
        m = None if first is None else metrics(first)
        finish = _prepared(robot, timed, first, m, config, intervals, sigma)
        audit, pending = audit_of()
    pairs = None if first is None else _audit_pairs(first, config)
    if pending and pairs is not None:
        audit = with_zero(audit, pairs)
    offset_ns = config.offset_ns
    if applied:
        if audit.offset_ns is None:
            raise ClockError(f"{where}: cannot apply the estimated clock offset: {audit.note}")
        offset_ns = audit.offset_ns
    matched = match(robot, offset_ns) if first is None else first
    if matched.robot_rows is not None and len(matched.robot_rows) != len(robot):
        # A robot pose in two of evo's pairs is two rows; the result's robot stream too.
        robot = robot.take(matched.robot_rows)
        notes.append(
            f"{len(matched.robot_rows) - len(logged)} robot pose(s) are the nearest of two "
            "GT poses and are counted once per pair, as evo counts them"
        )
    outside = matched.status == UNCOVERED
    spans = _spans(matched.t_ns, outside)
    n_out = int(outside.sum())
    if n_out == len(matched.t_ns):
        raise ClockError(
            f"{where}: no robot pose lies within the GT ({iso_utc(timed.start_ns)} to "
            f"{iso_utc(timed.end_ns)}); robot poses span "
            f"{iso_utc(int(logged.t_ns[0]) + offset_ns)} to "
            f"{iso_utc(int(logged.t_ns[-1]) + offset_ns)} (offset {ns_to_s(offset_ns):+.3f} s)"
        )
    failures: list[str] = []
    if n_out:
        text = ", ".join(
            f"{iso_utc(a)} to {iso_utc(b)} ({ns_to_s(b - a):.1f} s)" for a, b in spans[:3]
        )
        more = f" and {len(spans) - 3} more" if len(spans) > 3 else ""
        msg = f"{n_out} of {len(matched.t_ns)} robot poses lie outside the GT: {text}{more}"
        if not (config.allow_partial or evo):
            early = int(np.count_nonzero(outside & (matched.t_ns < timed.t_ns[0])))
            hint = (
                f" ({early} lie before the first GT pose: 2015 compared them with it, "
                "--before-gt first)"
                if early
                else ""
            )
            if early < n_out:
                # Poses after the GT: 2015 stopped with no score (exit 6); so does this.
                raise ClockError(
                    f"{where}: {msg}; give the missing GT files or --allow-partial{hint}"
                )
            # Only before the GT, where 2015 still gave a score: the covered part is scored
            # and printed, the uncovered start a failure (exit 1).
            failures.append(
                f"{where}: {msg}; the covered part is scored; give the missing GT files or "
                f"--allow-partial{hint}"
            )
        else:
            notes.append(
                f"partial: {msg}; only the covered part is scored"
                + (" (--t-max-diff: as evo, no error)" if evo and not config.allow_partial else "")
            )

    if first is None:
        m = metrics(matched)
    validity = from_codes(
        validity_codes(matched, int(timed.t_ns[0])),
        matched.t_ns,
        gap_s=ns_to_s(config.max_gap_ns),
        nan=bad_robot,
    )
    problem = None if evo or m is None else too_few(validity)
    if problem is not None and config.unscoreable == "2015":
        notes.append(
            f"2015 scored this comparison from {validity.valid_samples} valid pair(s) "
            f"(--unscoreable 2015); by default it is unscoreable: {problem}"
        )
    elif problem is not None:
        m = None
        invalid.append(
            RULE_UNSCOREABLE.deviation(
                f"unscoreable, no statistics: {problem}; the 2015 script averaged the pairs it had"
            )
        )
    if m is None and evo:
        failures.append(
            f"no robot pose has a GT pose within --t-max-diff {config.t_max_diff:g} s "
            f"(evo: 'found no matching timestamps'); check the time source and --offset"
        )
    elif m is None and problem is None:
        failures.append(
            f"no robot pose could be compared ({matched.count(GAP)} in GT gaps, "
            f"{matched.count(TRACKING_LOST)} while tracking was lost)"
        )
    if matched.count(UNPAIRED):
        notes.append(
            f"{matched.count(UNPAIRED)} robot pose(s) have no GT pose paired within "
            f"--t-max-diff {config.t_max_diff:g} s (evo's association) and are not compared"
        )
    if matched.count(GAP):
        notes.append(
            f"{matched.count(GAP)} robot pose(s) fall in GT gaps longer than "
            f"{ns_to_s(config.max_gap_ns):g} s and are not compared"
        )
    if matched.gaps_compared:
        notes.append(
            f"{matched.gaps_compared} robot pose(s) fall in GT gaps longer than "
            f"{ns_to_s(config.max_gap_ns):g} s and are compared with the GT pose "
            f"{'held' if config.association == 'hold' else 'bridging'} across the gap "
            "(--gaps compare; 2015: 'result may be invalid')"
        )
    if config.before_gt == "first" and matched.before_gt:
        notes.append(
            f"{matched.before_gt} robot pose(s) before the first GT pose are compared with "
            "the first GT pose (--before-gt first; 2015 printed an error and went on)"
        )
    if matched.count(TRACKING_LOST):
        notes.append(
            f"{matched.count(TRACKING_LOST)} robot pose(s) fall where mocap tracking was lost "
            "(repeated GT poses) and are not compared"
        )
    iv = NO_INTERVALS
    fitted: FittedScore | None = None
    if m is not None:
        if sigma is None and intervals.enabled:
            sigma = jitter(timed)
        if finish is not None:
            iv = finish(audit, offset_ns, rescoring(offset_ns))
        else:
            iv = trajectory_intervals(
                robot,
                timed,
                matched,
                audit,
                estimates(m),
                association=config.association,
                offset_ns=offset_ns,
                settings=intervals,
                rescoring=rescoring(offset_ns),
                sigma=sigma,
            )
        disagree = audit.offset_ns is not None and audit.disagrees_with(offset_ns)
        if sigma is not None and audit.offset_ns is not None and disagree:
            fitted = at_fitted_offset(
                logged,
                timed,
                audit,
                audit.offset_ns,
                match,
                rescoring,
                config,
                intervals,
                sigma,
            )
        if fitted is not None and iv.uncertainty is not None:
            shares = dict(iv.uncertainty.shares)
            shares.update(
                {f"{k}{FITTED_SUFFIX}": v for k, v in shares_of(fitted.intervals).items()}
            )
            why = dict(iv.uncertainty.withheld)
            why.update({f"{k}{FITTED_SUFFIX}": v for k, v in fitted.withheld.items()})
            iv = ResultIntervals(iv.intervals, replace(iv.uncertainty, shares=shares, withheld=why))
    notes.extend(audit_warnings(audit, offset_ns, fitted))
    few = few_warning(matched.count(COMPARED), "compared pose(s)", "the comparison")
    if few is not None and m is not None:
        notes.append(few)
    result = TrajectoryResult(
        robot_file=robot_file,
        robot_topic=robot_topic,
        gt_topic=gt_topic,
        gt_files=tuple(gt_files),
        config=config,
        offset_ns=offset_ns,
        metrics=m,
        matched=matched,
        robot=robot,
        gt_path=_decimate(timed),
        audit=audit,
        uncovered_spans=tuple(spans),
        warnings=tuple(notes),
        deviations=(*_deviations(config, matched, m), *invalid),
        failures=tuple(failures),
        validity=validity,
        unscoreable_reason=problem,
        intervals=iv.intervals,
        uncertainty=iv.uncertainty,
        fitted=fitted,
        provenance=Provenance(
            inputs=(robot_file, *gt_files),
            parameters=(
                ("robot_topic", robot_topic),
                ("gt_topic", gt_topic),
                ("association", config.association),
                ("ties", config.ties),
                ("gaps", config.gaps),
                ("before_gt", config.before_gt),
                ("gt_order", config.gt_order),
                ("max_gap", f"{ns_to_s(config.max_gap_ns):g}"),
                ("t_max_diff", "" if config.t_max_diff is None else f"{config.t_max_diff!r}"),
                ("offset", f"{ns_to_s(offset_ns):g}"),
            ),
        ),
    )
    return result


def _audit_pairs(matched: Matched, config: TrajectoryConfig) -> tuple[float, int] | None:
    """The clock audit's mean distance with no offset and its pose count, from the score's
    association where it pairs exactly as the audit does: no offset, linear interpolation
    in time order, nothing compared across a gap, held or before the GT (the audit then
    checks that no GT sample repeats the one before it: none is tracking-lost)."""
    if not _same_rule(config):
        return None
    ok = matched.status == COMPARED
    used = int(np.count_nonzero(ok))
    return (float(matched.position_error[ok].mean()), used) if used else (float("inf"), 0)


def _same_rule(config: TrajectoryConfig) -> bool:
    """Whether the score pairs the poses as the clock audit does at no offset
    (:func:`_audit_pairs`)."""
    return (
        config.offset_ns == 0
        and config.association == "linear"
        and config.ties == "at"
        and config.gaps == "skip"
        and config.before_gt == "uncovered"
        and config.gt_order == "time"
        and config.t_max_diff is None
    )


def _other_benchmark_gt(robot_file: str, gt_topic: str) -> list[str]:
    """A warning when the robot log's rockin_logger name names one benchmark and the GT topic
    lies under another's namespace (a folder of the other arena's mocap files given as
    GT_PATH: their times overlap at a venue recording both arenas at once)."""
    named = parse_robot_log_name(robot_file) if robot_file else None
    ns = gt_topic.strip("/").split("/")[0]
    if named is None or ns == named.benchmark or ns not in registry.names():
        return []
    return [
        f"the robot log's name says {named.benchmark}, but the GT {gt_topic} is the "
        f"{registry.get(ns).title} arena's: check GT_PATH (or --gt-topic)"
    ]


def _deviations(config: TrajectoryConfig, m: Matched, metr: Metrics | None) -> list[Deviation]:
    out = []
    if config.association != "hold":
        out.append(
            RULE_ASSOCIATION.deviation(
                f"association {config.association} (2015: hold, the GT pose before the robot pose)"
            )
        )
    elif config.ties == "at" and m.exact_ties:
        out.append(
            RULE_TIES.deviation(
                f"{m.exact_ties} robot pose(s) stamped exactly at a GT sample use that sample "
                "(2015 used the one before it)"
            )
        )
    if m.count(GAP):
        out.append(
            RULE_GAPS.deviation(
                f"{m.count(GAP)} robot pose(s) in GT gaps > {ns_to_s(config.max_gap_ns):g} s "
                "not compared (2015 compared them with the held pose and only warned)"
            )
        )
    if config.before_gt == "uncovered" and m.before_gt:
        out.append(
            RULE_BEFORE_GT.deviation(
                f"{m.before_gt} robot pose(s) before the first GT pose not scored (2015 compared "
                "them with the first GT pose)"
            )
        )
    wrapped = int(np.count_nonzero(np.abs(m.yaw_diff_raw[m.status == COMPARED]) > np.pi))
    if wrapped and metr is not None:
        out.append(
            RULE_YAW_WRAP.deviation(
                f"yaw differences wrapped to [-pi, pi] ({wrapped} pose(s) crossed +-pi; 2015 did "
                f"not wrap: its orientation error, orientation_error_2015, is "
                f"{metr.orientation_error_2015:.4f} rad)"
            )
        )
    return out


def _spans(t_ns: I64, mask: npt.NDArray[np.bool_]) -> list[tuple[int, int]]:
    """(first, last) times of each run of consecutive True in ``mask``."""
    idx = np.flatnonzero(mask)
    if idx.size == 0:
        return []
    breaks = np.flatnonzero(np.diff(idx) > 1)
    starts = np.concatenate([[idx[0]], idx[breaks + 1]])
    ends = np.concatenate([idx[breaks], [idx[-1]]])
    return [(int(t_ns[a]), int(t_ns[b])) for a, b in zip(starts, ends, strict=True)]
