"""Confidence intervals of the trajectory statistics (issues 28 and 39; the model and its
derivations: docs/uncertainty.md, "Trajectory" and "Closed forms").

Every statistic of :mod:`ertools.benchmarks.trajectory.formula` gets the interval of its
value under two sources of uncertainty on the GT side of each compared pair:

- ``mocap_noise``: sigma per axis (and the yaw's) measured from the GT stream itself
  (:func:`jitter`: its stationary phases, else its second differences); an
  interpolated GT pose mixes two samples: sigma sqrt((1-a)^2 + a^2).
- ``time_association``: the clock offset, known to the standard error of the least-squares
  offset (:func:`offset_spread`), one error per draw centred on the offset applied (the
  interval is the score's; where the data fits another offset, the score there is reported
  beside with its own). The score at a drawn offset is itself a draw of the true score: its
  draws are mirrored about the score before the engine's reflection and added to the
  measurement-like draws. The comparison is re-scored by the score's own association at a
  grid of shifts (:class:`Rescoring`, :func:`offset_effects`), so that poses entering or
  leaving a tracking loss or a GT gap are counted as the score at that offset would. With
  ``hold`` or ``nearest``, also a lag uniform over the pose's own GT frame period.

The measurement-like part of the mean distance, the RMSE and the two circular means comes
from their closed-form distribution (:mod:`ertools.benchmarks.common.closed_forms`, one draw
of it per Monte Carlo draw); the max and the percentiles are drawn on the poses that can
move them only (:mod:`ertools.benchmarks.common.draws`), the percentiles of a comparison of
more than :data:`MAX_POSES` poses on that many spread evenly over it (conservative). The
closed forms work in float64; the order statistics' draws in float32 with additions, products
and square roots only, which give the same bits on every CPU (float32's sin, cos and arctan2
do not: issue 36). A comparison of too few poses to measure the offset's spread gets no
interval, with the reason (:func:`~ertools.benchmarks.common.uncertainty.too_few`).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from functools import partial
from typing import Any

import numpy as np
import numpy.typing as npt

from ertools.arrays import F64, I64, IntArr, distinct, median
from ertools.benchmarks.common.clocks import MIN_POSES, OffsetEstimate
from ertools.benchmarks.common.draws import (
    Distances,
    OrderStat,
    draw_order_stats,
    order_stats,
    percentile_rows,
)
from ertools.benchmarks.common.epsilon import noise_from_stream
from ertools.benchmarks.common.hygiene import rows_equal
from ertools.benchmarks.common.inputs import IntervalSettings
from ertools.benchmarks.common.interval_output import (
    METHOD,
    NO_INTERVALS,
    ResultIntervals,
    shares_of,
    withheld,
)
from ertools.benchmarks.common.uncertainty import (
    MIN_INTERVAL_SAMPLES,
    MOCAP_NOISE,
    TIME_ASSOCIATION,
    Source,
    Uncertainty,
    monte_carlo,
    sigma_from_epsilon,
    too_few,
)
from ertools.benchmarks.trajectory.association import COMPARED, Matched
from ertools.benchmarks.trajectory.formula import PERCENTILES
from ertools.benchmarks.trajectory.spread import offset_spread
from ertools.benchmarks.trajectory.steady import clear_of_losses
from ertools.benchmarks.trajectory.steady import effects as steady_effects
from ertools.benchmarks.trajectory.terms import PoseTerms
from ertools.cores import alongside
from ertools.errors import ErtoolsError
from ertools.frozen_dataclass import frozen_dataclass
from ertools.geometry import unwrap_angles, wrap_angle, yaw_from_quat
from ertools.streams import PoseStream
from ertools.timeutil import NS_PER_S

METHOD_TRAJECTORY = (
    f"{METHOD}; the noise and frame lag of the mean, RMSE and orientation errors from their "
    "closed-form distribution, the max and percentiles from draws of the poses that can move "
    "them; the clock offset's draws (centred on the offset applied) mirrored"
)

# A 2015 mocap marker set when nothing in the log measures it: 0.3 mm per axis, 0.05 deg.
DEFAULT_SIGMA_M = 3e-4
DEFAULT_SIGMA_RAD = math.radians(0.05)
MIN_PAIRS = 50  # stationary pairs (or second differences) needed to measure sigma
VELOCITY_HALF_SPAN = 5  # GT samples either side of a pose for its velocity (~40 ms at 120 Hz)
# Longer comparisons draw their percentiles on this many evenly spread poses (module doc),
# and re-score the offset's grid on MAX_GRID_POSES robot poses: the grid's statistics are
# averages of per-pose changes that 1,000 poses spread over the log measure to a few percent
# of the offset's effect (an hour at 10 Hz: 36,000 poses)
MAX_POSES = 1500
MAX_GRID_POSES = 1000
# Longer comparisons without a frame lag take the yaw's closed-form moments from the poses
# near a fold and this many of the others (:meth:`PoseTerms.thinned_mean_like`)
MAX_CLOSED = 4000
# Shifts the statistics are re-scored at, over OFFSET_SPAN sd either side: a step of 0.2 sd.
# Near the best offset a statistic grows as the square of the shift, and the chord between
# two shifts lies above it by at most a (0.2 sd)^2 / 4 = 1% of its value 1 sd away.
OFFSET_GRID = 41
OFFSET_SPAN = 4.0  # a draw beyond (1 in 16,000) takes the grid's end value
# GT samples the noise is measured on, at most: 5 runs of 2,000 (30,000 second differences
# measure sigma to 1 %, far below what 400 draws can tell: their quantiles move by ~7 %)
SIGMA_BLOCKS, SIGMA_BLOCK = 5, 2000

#: The scores with an interval, in the order of the result's keys (``percentiles.pNN`` nested).
KEYS = (
    "position_error",
    "orientation_error",
    "rmse",
    "median",
    "max",
    *(f"percentiles.p{p:g}" for p in PERCENTILES),
    "orientation_error_2015",
)
#: The statistics that average over the poses: closed forms (module doc).
MEAN_LIKE = (0, 1, 2, len(KEYS) - 1)
#: The order statistics, drawn: (index in KEYS, percent; 100 for the max).
ORDER_STATS = ((3, 50.0), (4, 100.0), *((5 + i, p) for i, p in enumerate(PERCENTILES)))
#: The statistics reported at the fitted clock offset too, when the data fits another one.
FITTED_KEYS = ("position_error", "orientation_error", "rmse", "median", "max")
FITTED_SUFFIX = "_at_fitted_offset"


@frozen_dataclass
class Rescoring:
    """How the score associated the robot poses, for the offset's draws to re-score with.

    Attributes:
        t_ns: the robot poses as logged, stamped on the GT clock at the applied offset.
        associate: (rows of those poses, extra shift in ns) -> the score's own association
            of those poses at the applied offset plus the shift.
        associate_shifted: (rows, one extra shift in ns per row) -> the same for rows each
            at its own shift (rows may repeat), in one call; None where the association is
            not row by row (evo's: its side that looks up depends on the counts), and
            :func:`offset_effects` then calls ``associate`` once per shift.
        max_gap_ns: the GT pair span the association calls a gap; None: never modelled
            (:mod:`~ertools.benchmarks.trajectory.steady`), always re-scored.
    """

    t_ns: IntArr
    associate: Callable[[npt.NDArray[np.intp], int], Matched]
    associate_shifted: Callable[[npt.NDArray[np.intp], I64], Matched] | None = None
    max_gap_ns: int | None = None


@frozen_dataclass
class MocapSigma:
    """The GT's noise: per-axis position sigma (m), yaw sigma (rad), and how it was found."""

    position: float
    yaw: float
    measured: bool
    note: str


def _mad_sigma(d2: F64) -> float:
    """sigma of the noise from second differences (each sqrt(6) sigma): 1.4826 MAD."""
    med = median(d2)
    return float(1.4826 * median(np.abs(d2 - med)) / math.sqrt(6.0))


def _second_differences(gt: PoseStream) -> tuple[F64, F64]:
    """Second differences of x, y, z (pooled) and of the yaw, over runs of three fresh
    samples (a repeated pose, tracking lost, is no measurement)."""
    xyz = gt.xyz
    if len(gt) < 3:
        return np.zeros(0), np.zeros(0)
    fresh = np.ones(len(gt), dtype=bool)
    fresh[1:] = ~rows_equal(xyz[1:], xyz[:-1])  # by column: no (N, 3) reduced over rows
    dt = np.diff(gt.t_ns)
    ok = fresh[2:] & fresh[1:-1] & fresh[:-2]
    # equal spacing (within 25%): a gap is not a second difference of the motion
    ok &= np.abs(dt[1:] - dt[:-1]) <= 0.25 * np.maximum(dt[1:], 1)
    d2 = (xyz[2:] - 2.0 * xyz[1:-1] + xyz[:-2])[ok]
    yaw = unwrap_angles(gt.yaw)
    y2 = (yaw[2:] - 2.0 * yaw[1:-1] + yaw[:-2])[ok]
    return d2.reshape(-1), y2


def _blocks(gt: PoseStream) -> PoseStream:
    """At most SIGMA_BLOCKS runs of SIGMA_BLOCK consecutive samples spread over ``gt``: an
    hour of 120 Hz GT measures its noise from 10,000 samples, 40 times faster."""
    n = len(gt)
    if n <= SIGMA_BLOCKS * SIGMA_BLOCK:
        return gt
    # the starts lie more than a block apart (n > the blocks' total): increasing indices
    starts = np.linspace(0, n - SIGMA_BLOCK, SIGMA_BLOCKS).astype(np.intp)
    index = (starts[:, None] + np.arange(SIGMA_BLOCK)[None, :]).reshape(-1)
    return gt.take(index)


def jitter(gt: PoseStream) -> MocapSigma:
    """The GT's measurement noise, measured from the GT stream (module doc)."""
    gt = _blocks(gt)
    d2, y2 = _second_differences(gt)
    yaw_sigma = _mad_sigma(y2) if y2.size >= MIN_PAIRS else DEFAULT_SIGMA_RAD
    yaw_note = "yaw from its second differences" if y2.size >= MIN_PAIRS else "yaw default"
    try:
        still = noise_from_stream(gt, stationary=True)
        pairs = int(still.pairs)
        epsilon = float(still.epsilon)
    except ErtoolsError:
        pairs, epsilon = 0, math.nan
    if pairs >= MIN_PAIRS and math.isfinite(epsilon) and epsilon > 0.0:
        return MocapSigma(
            sigma_from_epsilon(epsilon),
            yaw_sigma,
            True,
            f"stationary phases of the GT: epsilon {epsilon * 1000:.3f} mm over {pairs} pairs "
            f"(sigma = epsilon / sqrt(pi)); {yaw_note}",
        )
    if d2.size >= 3 * MIN_PAIRS:
        return MocapSigma(
            _mad_sigma(d2),
            yaw_sigma,
            True,
            f"no stationary phase: second differences of the moving GT ({d2.size // 3} "
            f"triples, 1.4826 MAD / sqrt(6)); {yaw_note}",
        )
    return MocapSigma(
        DEFAULT_SIGMA_M,
        yaw_sigma,
        False,
        f"too few GT samples to measure: default {DEFAULT_SIGMA_M * 1000:g} mm per axis; "
        + yaw_note,
    )


def _bracket(t: IntArr, q: IntArr) -> tuple[IntArr, IntArr]:
    """The GT samples k <= q < k+1 (clipped to the stream)."""
    n = len(t)
    k = np.clip(np.searchsorted(t, q, side="right") - 1, 0, max(n - 2, 0))
    return k, np.minimum(k + 1, n - 1)


def _rescored_rows(t_robot: IntArr, t_gt: IntArr, reach_s: float) -> npt.NDArray[np.intp]:
    """The robot poses the offset's grid re-scores: those the GT covers at some shift of the
    grid, at most :data:`MAX_GRID_POSES` of them evenly spread (an hour's log)."""
    reach = round(reach_s * NS_PER_S) + 1
    rows = np.flatnonzero((t_robot >= t_gt[0] - reach) & (t_robot <= t_gt[-1] + reach))
    if len(rows) > MAX_GRID_POSES:
        pick = np.linspace(0, len(rows) - 1, MAX_GRID_POSES).round().astype(np.intp)
        rows = rows[distinct(pick)]
    return rows


def grid_statistics(m: Matched, shifts: int) -> F64:
    """(shifts, KEYS) statistics of an association of ``shifts`` blocks of rows (each block
    the same poses at one shift), as :func:`~ertools.benchmarks.trajectory.formula.metrics`
    computes them; NaN for a block with no pose compared."""
    ok = (m.status == COMPARED).reshape(shifts, -1)
    d = m.position_error.reshape(shifts, -1)
    dyaw = m.yaw_error.reshape(shifts, -1)
    raw = np.abs(m.yaw_diff_raw.reshape(shifts, -1))
    count = ok.sum(axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        mean = np.where(ok, d, 0.0).sum(axis=1) / count
        rmse = np.sqrt(np.where(ok, d * d, 0.0).sum(axis=1) / count)
    orient = np.arctan2(
        np.where(ok, np.sin(dyaw), 0.0).sum(1), np.where(ok, np.cos(dyaw), 0.0).sum(1)
    )
    o2015 = np.arctan2(np.where(ok, np.sin(raw), 0.0).sum(1), np.where(ok, np.cos(raw), 0.0).sum(1))
    ranked = np.sort(np.where(ok, d, np.inf), axis=1)
    pct = [percentile_rows(ranked, count, p) for p in PERCENTILES]
    top = percentile_rows(ranked, count, 100.0)
    out = np.column_stack([mean, orient, rmse, pct[0], top, *pct, o2015])
    out[count == 0] = np.nan
    return np.asarray(out, dtype=np.float64)


def offset_effects(rescoring: Rescoring, t_gt: IntArr, shifts_s: F64) -> F64:
    """(shifts, KEYS) change of each statistic when the offset applied moves by each shift
    (seconds), the comparison re-scored by the score's own association and metrics: a pose
    a shift moves into a tracking loss or a GT gap leaves the comparison, one it moves out
    of them enters it, next to a stale sample as the score at that offset would compare it
    (0 where no pose would be compared: no score there). All shifts in one association of
    the rows repeated per shift where the association works row by row."""
    poses = _rescored_rows(rescoring.t_ns, t_gt, float(np.max(np.abs(shifts_s))))
    shifts_ns = np.concatenate([[0], np.round(np.asarray(shifts_s) * NS_PER_S)]).astype(np.int64)
    if rescoring.associate_shifted is not None:
        rows = np.tile(poses, len(shifts_ns))
        per_row = np.repeat(shifts_ns, len(poses))
        stats = grid_statistics(rescoring.associate_shifted(rows, per_row), len(shifts_ns))
    else:
        stats = np.vstack(
            [grid_statistics(rescoring.associate(poses, int(s)), 1) for s in shifts_ns]
        )
    ref, got = stats[0], stats[1:]
    if not np.isfinite(ref[0]):
        return np.zeros((len(shifts_s), len(KEYS)))
    out = got - ref
    out[~np.isfinite(got[:, 0])] = 0.0
    return np.asarray(out, dtype=np.float64)


def _part_variance(parts: Mapping[str, F64], name: str) -> F64:
    """(scores,) variance of each column of the source ``name``'s part of the draws (its
    finite values; 0 with fewer than two)."""
    part = parts[name]
    finite = np.isfinite(part)
    out = np.zeros(part.shape[1])
    ok = finite.sum(axis=0) >= 2
    if ok.any():
        out[ok] = np.nanvar(np.where(finite, part, np.nan)[:, ok], axis=0)
    return out


def trajectory_intervals(
    robot: PoseStream,
    gt: PoseStream,
    matched: Matched,
    audit: OffsetEstimate,
    estimates: Mapping[str, float],
    *,
    association: str,
    offset_ns: int,
    settings: IntervalSettings,
    rescoring: Rescoring,
    sigma: MocapSigma | None = None,
) -> ResultIntervals:
    """The intervals of the statistics ``estimates`` (by :data:`KEYS`) of a comparison.

    ``robot``: the robot stream whose row i is matched row i; ``gt``: the GT in time order;
    ``offset_ns``: the offset the score applied, on which the offset's draws are centred;
    ``rescoring``: the score's association, which the offset's draws re-score with;
    ``sigma``: the GT's noise when already measured (:func:`jitter`).
    """
    finish = prepare_intervals(
        robot, gt, matched, estimates, association=association, settings=settings, sigma=sigma
    )
    return finish(audit, offset_ns, rescoring)


# (the clock audit, the offset applied, the score's association) -> the intervals
Finish = Callable[[OffsetEstimate, int, Rescoring], ResultIntervals]


def prepare_intervals(
    robot: PoseStream,
    gt: PoseStream,
    matched: Matched,
    estimates: Mapping[str, float],
    *,
    association: str,
    settings: IntervalSettings,
    sigma: MocapSigma | None = None,
) -> Finish:
    """:func:`trajectory_intervals` in two steps: now, what the clock audit does not decide
    (the GT's motion at each pose, the noise's closed forms and bands), which a caller may
    compute while the audit runs on another core; the function returned does the rest."""
    ok = matched.status == COMPARED
    if not settings.enabled or not ok.any() or len(gt) < 2:
        return lambda *_: NO_INTERVALS
    few = too_few(
        int(ok.sum()),
        "compared pose(s)",
        max(MIN_INTERVAL_SAMPLES, MIN_POSES),
        f"the clock offset's spread (the time association, most often the largest source) "
        f"being measured from {MIN_POSES} or more",
    )
    if few is not None:
        # a null interval with the reason, not one of the mocap noise alone
        nulls = withheld(KEYS, few, settings, METHOD_TRAJECTORY)
        return lambda *_: nulls
    every = bool(ok.all())

    def compared(a: npt.NDArray[Any]) -> npt.NDArray[Any]:
        # the usual comparison compares every pose: its arrays as they are, not gathered
        # copies (read only below)
        return a if every else a[ok]

    q = compared(matched.t_ns)
    r_xyz = compared(robot.xyz)
    g_xyz = compared(matched.gt_xyz)
    t = gt.t_ns
    if matched.gt_lo is not None and len(matched.gt_lo) == len(matched.t_ns):
        # the association's own search over this GT: its bracket, as _bracket finds it
        k = np.clip(compared(matched.gt_lo), 0, max(len(t) - 2, 0))
        k1 = np.minimum(k + 1, len(t) - 1)
    else:
        k, k1 = _bracket(t, q)
    tk = np.take(t, k)
    gap = np.take(t, k1) - tk
    period = gap / NS_PER_S
    # A pose compared across a GT gap (--gaps compare, 2015) is held up to the gap's length:
    # that is the log's gap (a validity matter, reported), not the frame period's lag
    period = np.minimum(period, 1.5 * median(period))
    a = np.clip((q - tk) / np.maximum(gap, 1), 0.0, 1.0)
    # GT velocity and yaw rate around each pose, over ~VELOCITY_HALF_SPAN samples either side
    lo = np.clip(k - VELOCITY_HALF_SPAN, 0, len(t) - 1)
    hi = np.clip(k1 + VELOCITY_HALF_SPAN, 0, len(t) - 1)
    span = np.maximum((t[hi] - t[lo]).astype(np.float64) / NS_PER_S, 1e-9)
    # rows gathered by take (a fancy index of rows costs twice as much)
    # (and the differences and quotients written into the first gathered array)
    vel = np.take(gt.xyz, hi, axis=0)
    vel -= np.take(gt.xyz, lo, axis=0)
    vel /= span[:, None]
    # the yaw of the samples used only (an hour's GT holds 430,000)
    quat = gt.quat_xyzw
    turned = yaw_from_quat(np.take(quat, hi, axis=0)) - yaw_from_quat(np.take(quat, lo, axis=0))
    yaw_rate = wrap_angle(turned) / span
    sig = jitter(gt) if sigma is None else sigma
    lag: tuple[float, float] | None = None
    if association == "linear":
        weight = np.sqrt((1.0 - a) ** 2 + a**2)
    else:
        weight = np.ones(len(q))
        lag = (-1.0, 0.0) if association == "hold" else (-0.5, 0.5)
    if matched.yaw_diff is not None:
        theta = compared(matched.yaw_diff)  # the association's: the same yaws, subtracted
    else:
        theta = wrap_angle(compared(robot.yaw) - compared(matched.gt_yaw))
    # the association's distances: the same sums of squares of the same errors, in order
    d = compared(matched.position_error)
    terms = PoseTerms(
        error=r_xyz - g_xyz,
        theta=theta,
        raw=compared(matched.yaw_diff_raw),
        sigma=sig.position * weight,
        sigma_yaw=sig.yaw * weight,
        velocity=vel,
        yaw_rate=yaw_rate,
        period=period,
        lag=lag,
        distance=d,
    )
    distances = Distances(terms.error, terms.sigma, terms.velocity, terms.period, d)
    n_all = len(q)
    thinned = np.arange(n_all)
    if n_all > MAX_POSES:
        # steps over 1: the rounded picks are distinct and increasing
        thinned = np.linspace(0, n_all - 1, MAX_POSES).round().astype(np.intp)
    est = np.array([estimates[key] for key in KEYS])
    mean_cols = list(MEAN_LIKE)
    closed: dict[tuple[bool, bool], list[Callable[[F64], F64]]] = {}
    bands: dict[tuple[bool, bool], tuple[list[OrderStat], F64]] = {}

    def closed_and_bands(key: tuple[bool, bool]) -> None:
        """The closed forms of the mean-like statistics and the bands of the order statistics
        with the sources ``key`` (noise, frame lag) perturbed (no draw in them), once."""
        if key not in closed:
            full = (float(est[1]), float(est[-1]))
            closed[key] = terms.thinned_mean_like(*key, full, MAX_CLOSED)
            bands[key] = order_stats(d, thinned, terms.bounds(*key), ORDER_STATS)

    # those of the pass with every source: the noise, and the frame lag where there is one
    closed_and_bands((True, lag is not None))

    def finish(audit: OffsetEstimate, offset_ns: int, rescoring: Rescoring) -> ResultIntervals:
        off_sigma, _ = offset_spread(r_xyz, g_xyz, vel, audit, offset_ns)
        # The offset's effect, centred on the offset applied: the comparison re-scored by the
        # score's own association and metrics at shifts of it (every robot pose inside the GT,
        # compared or not), on a grid the draws interpolate
        grid = np.linspace(-OFFSET_SPAN, OFFSET_SPAN, OFFSET_GRID) * off_sigma

        def grid_effects() -> F64:
            if off_sigma <= 0.0:
                return np.zeros((OFFSET_GRID, est.size))
            gap_ns = rescoring.max_gap_ns
            # where no pose crosses a loss within reach: the GT's motion on every pose
            reach_ns = round(grid[-1] * NS_PER_S) + 1
            linear = association == "linear" and gap_ns is not None
            if linear and clear_of_losses(
                q, matched.status, matched.t_ns, t, gt.xyz, k, reach_ns, gap_ns or 0
            ):
                modelled = steady_effects(terms, thinned, grid, ORDER_STATS, est.size, MEAN_LIKE)
                if modelled is not None:
                    return modelled
            return offset_effects(rescoring, t, grid)

        # the grid re-scored on a second core while each pass's noise draws are made here
        # (they come first in a pass; its offset draws wait for the grid)
        with alongside(grid_effects, parallel=off_sigma > 0.0) as on_grid_of:
            own: dict[str, F64] = {}  # each source's own part of the draws, where they add

            def perturbed(rng: np.random.Generator, sources: frozenset[str], draws: int) -> F64:
                """Draws whose basic (reflected) interval is the interval wanted (module doc):
                measurement-like perturbations as re-computed scores, the offset's mirrored."""
                noise = MOCAP_NOISE in sources
                timing = TIME_ASSOCIATION in sources
                frame = timing and lag is not None
                measured = np.zeros((draws, est.size))
                z = rng.standard_normal((draws, len(mean_cols)))
                if noise or frame:
                    key = (noise, frame)  # the same closed forms and bands in two passes
                    closed_and_bands(key)
                    for j, (col, value) in enumerate(zip(mean_cols, closed[key], strict=True)):
                        measured[:, col] = value(z[:, j]) - est[col]
                    stats, base = bands[key]
                    got = draw_order_stats(
                        stats, distances, rng, draws, noise=noise, lag=lag if frame else None
                    )
                    got -= base
                    for k, st in enumerate(stats):
                        for col in st.columns:
                            measured[:, col] = got[:, k]
                offset = np.zeros((draws, est.size))
                if timing and off_sigma > 0.0:
                    on_grid = on_grid_of()
                    shift = rng.standard_normal(draws) * off_sigma
                    # one shift for every pose: the statistics are a function of it alone,
                    # re-scored on the grid and interpolated (the grid's step, a tenth of the sd,
                    # is much finer than the draws' spread)
                    for j in range(est.size):
                        offset[:, j] = np.interp(shift, grid, on_grid[:, j])
                if noise and timing and not frame:
                    own[MOCAP_NOISE], own[TIME_ASSOCIATION] = measured, offset
                # mirrored: the offset is not a measurement of the truth plus an error that the
                # draws add again; the truth's offset is spread around the applied one as the draws
                # are, so the reflection of the basic interval must not apply to it
                return np.asarray(est + measured - offset, dtype=np.float64)

            sources = [MOCAP_NOISE]
            if off_sigma > 0.0 or lag is not None:
                sources.append(TIME_ASSOCIATION)
            # without a frame lag the noise and the offset are independent parts of each draw:
            # a source's draws alone are its part of the draws of both (no pass for the shares)
            alone = None
            if lag is None and len(sources) == 2:
                alone = {name: partial(_part_variance, own, name) for name in sources}
            got = monte_carlo(
                est,
                perturbed,
                sources,
                draws=settings.draws,
                seed=settings.seed,
                confidence=settings.confidence,
                nonnegative=True,
                alone_variance=alone,
            )
            intervals = dict(zip(KEYS, got, strict=True))
        src = [Source(MOCAP_NOISE, sig.position, "m", sig.measured, sig.note)]
        if TIME_ASSOCIATION in sources:
            parts = []
            if off_sigma > 0.0:
                parts.append(
                    f"clock offset sd {off_sigma * 1000:.3f} ms (standard error of the "
                    "least-squares offset, the robot's error slid along the path by every lag), "
                    "centred on the offset applied; mirrored: drawn as the truth's offset"
                )
            else:
                parts.append(f"no offset estimate (clock audit: {audit.note or 'none'})")
            if lag is not None:
                med = float(median(period)) * 1000
                parts.append(
                    f"{association}: GT frame period {med:.2f} ms (lag uniform over "
                    f"[{lag[0]:g}, {lag[1]:g}] periods)"
                )
            src.append(Source(TIME_ASSOCIATION, off_sigma, "s", off_sigma > 0.0, "; ".join(parts)))
        unc = Uncertainty(
            confidence=settings.confidence,
            method=METHOD_TRAJECTORY,
            draws=settings.draws,
            seed=settings.seed,
            sources=tuple(src),
            shares=shares_of(intervals),
        )
        return ResultIntervals(intervals, unc)

    return finish
