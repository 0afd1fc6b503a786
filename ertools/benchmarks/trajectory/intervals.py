"""Confidence intervals of the trajectory statistics (issue 28).

Every statistic of :mod:`ertools.benchmarks.trajectory.metrics` (the mean 3D distance, RMSE,
median, max and percentiles, the orientation errors) is re-computed ``draws`` times with the GT
side of each compared pair perturbed by two sources, vectorised over (draws, poses):

- ``mocap_noise``: each GT pose used carries the mocap's measurement noise, sigma per axis
  measured from the GT stream itself: from its stationary phases as ``ertools noise
  --stationary auto`` finds them (epsilon -> sigma), else from the second differences of the
  moving stream (at 120 Hz the motion's own second difference is hundredths of a millimetre;
  the noise's is sqrt(6) sigma: a robust MAD of them gives sigma), else a stated default. The
  yaw's sigma likewise from the yaw's second differences. An interpolated GT pose mixes two
  samples: its noise is sigma sqrt((1-a)^2 + a^2).
- ``time_association``: the robot-to-GT clock offset is known to the standard error of the
  least-squares offset, the robot's correlated error slid along the path by every lag
  (:func:`offset_spread`): one offset error per draw, common to every pose, moves
  each GT pose by the GT velocity times it. The offset is not a measurement of the truth
  plus an error that a draw adds a second time: the true offset lies around the applied one
  as the draws do, so the score at a drawn offset is itself a draw of the true score (with
  ``--offset auto`` the applied offset minimises the error: every other offset, the true one
  included, scores higher). Its draws are mirrored about the score before the engine's
  reflection, and added to the measurement-like draws (their interaction neglected). At
  each shift the comparison is re-scored by the score's own association and metrics
  (:class:`Rescoring`, :func:`offset_effects`): a pose the shift moves into a tracking loss
  or a GT gap leaves the comparison, one it moves out of them enters it, and one moved next
  to a loss's stale sample is compared with it, all as the score at that offset would (no
  linearisation: a GT velocity measured across a loss's repeated samples is not the
  body's). With ``hold`` (2015) the
  GT pose compared was measured up to one GT frame period before the robot's moment, with
  ``nearest`` up to half a period either side: an extra lag drawn uniformly over the pose's
  own frame period (the basic interval then removes the lag's bias). ``linear``
  interpolates: no frame-period term.

The interval is the engine's basic bootstrap: noise makes a distance longer on average (the
RMSE of a perfect robot is sqrt(3) sigma, not 0) and the reflection removes the bias the draws
show. The draws work in float64 (float32's sin, cos and arctan2 differ between CPUs: see
:data:`CHUNK_ELEMENTS`) and in chunks of draws. A comparison of more than
:data:`MAX_POSES` poses (an hour at 10 Hz is 36,000) draws on that many poses spread evenly
over it: the offset's effect is the same on them as on all, the per-pose noise's spread in
the mean-like statistics (mean, RMSE, orientation errors) is scaled by sqrt(thinned / all)
(it averages over all the poses), and in the median, percentiles and max it is left as the
thinned poses give it (wider: a conservative interval); the offset's grid re-scores at most
as many robot poses, evenly spread. An hour's log costs a fraction of a second.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from ertools.arrays import F64, IntArr
from ertools.benchmarks.common.clocks import MIN_POSES, OffsetEstimate
from ertools.benchmarks.common.interval_output import (
    METHOD,
    NO_INTERVALS,
    IntervalSettings,
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
from ertools.benchmarks.noise.benchmark import noise_from_stream
from ertools.benchmarks.trajectory.association import COMPARED, Matched
from ertools.benchmarks.trajectory.metrics import PERCENTILES, Metrics, metrics
from ertools.errors import ErtoolsError
from ertools.streams import PoseStream
from ertools.timeutil import NS_PER_S

METHOD_TRAJECTORY = f"{METHOD} (the clock offset's draws mirrored: a percentile interval)"

# A 2015 mocap marker set when nothing in the log measures it: 0.3 mm per axis, 0.05 deg.
DEFAULT_SIGMA_M = 3e-4
DEFAULT_SIGMA_RAD = math.radians(0.05)
MIN_PAIRS = 50  # stationary pairs (or second differences) needed to measure sigma
VELOCITY_HALF_SPAN = 5  # GT samples either side of a pose for its velocity (~40 ms at 120 Hz)
# Draws x poses per chunk: ~50 MB of float64 positions. float64, not float32: NumPy's float32
# sin, cos and arctan2 are its own SIMD code, one per instruction set (AVX-512, AVX2, SSE),
# which differ by a float32 ulp (6e-8), and a quantile of such draws moved the intervals by
# 6e-8 between CPUs (issue 36). The float64 ones differ by a float64 ulp at most: 1e-15.
CHUNK_ELEMENTS = 2_000_000
# Longer comparisons draw on this many evenly spread poses (module doc): an hour at 10 Hz
# stays well under a second.
MAX_POSES = 1500
OFFSET_GRID = 81  # shifts the statistics are re-scored at, over OFFSET_SPAN sd either side
OFFSET_SPAN = 4.0  # a draw beyond (1 in 16,000) takes the grid's end value
SIGMA_BLOCKS, SIGMA_BLOCK = 20, 2000  # GT samples the noise is measured on, at most

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
# Statistics that average over the poses (their noise part shrinks as 1 / sqrt(poses)).
MEAN_LIKE = [0, 1, 2, len(KEYS) - 1]


@dataclass(frozen=True)
class Rescoring:
    """How the score associated the robot poses, for the offset's draws to re-score with.

    Attributes:
        t_ns: the robot poses as logged, stamped on the GT clock at the applied offset.
        associate: (rows of those poses, extra shift in ns) -> the score's own association
            of those poses at the applied offset plus the shift.
    """

    t_ns: IntArr
    associate: Callable[[npt.NDArray[np.intp], int], Matched]


def _statistics(m: Metrics | None) -> F64 | None:
    """The statistics of :data:`KEYS` in order (None: no pose compared)."""
    if m is None:
        return None
    pct = [v for _, v in m.percentiles]
    return np.array(
        [
            m.position_error,
            m.orientation_error,
            m.rmse,
            m.median,
            m.max,
            *pct,
            m.orientation_error_2015,
        ]
    )


@dataclass(frozen=True)
class MocapSigma:
    """The GT's noise: per-axis position sigma (m), yaw sigma (rad), and how it was found."""

    position: float
    yaw: float
    measured: bool
    note: str


def _mad_sigma(d2: F64) -> float:
    """sigma of the noise from second differences (each sqrt(6) sigma): 1.4826 MAD."""
    med = np.median(d2)
    return float(1.4826 * np.median(np.abs(d2 - med)) / math.sqrt(6.0))


def _second_differences(gt: PoseStream) -> tuple[F64, F64]:
    """Second differences of x, y, z (pooled) and of the yaw, over runs of three fresh
    samples (a repeated pose, tracking lost, is no measurement)."""
    xyz = gt.xyz
    if len(gt) < 3:
        return np.zeros(0), np.zeros(0)
    fresh = np.ones(len(gt), dtype=bool)
    fresh[1:] = np.any(xyz[1:] != xyz[:-1], axis=1)
    dt = np.diff(gt.t_ns)
    ok = fresh[2:] & fresh[1:-1] & fresh[:-2]
    # equal spacing (within 25%): a gap is not a second difference of the motion
    ok &= np.abs(dt[1:] - dt[:-1]) <= 0.25 * np.maximum(dt[1:], 1)
    d2 = (xyz[2:] - 2.0 * xyz[1:-1] + xyz[:-2])[ok]
    yaw = np.unwrap(gt.yaw)
    y2 = (yaw[2:] - 2.0 * yaw[1:-1] + yaw[:-2])[ok]
    return d2.reshape(-1), y2


def _blocks(gt: PoseStream) -> PoseStream:
    """At most SIGMA_BLOCKS runs of SIGMA_BLOCK consecutive samples spread over ``gt``: an
    hour of 120 Hz GT measures its noise as well as from 40,000 samples, 10 times faster."""
    n = len(gt)
    if n <= SIGMA_BLOCKS * SIGMA_BLOCK:
        return gt
    starts = np.linspace(0, n - SIGMA_BLOCK, SIGMA_BLOCKS).astype(np.intp)
    index = (starts[:, None] + np.arange(SIGMA_BLOCK)[None, :]).reshape(-1)
    return gt.take(np.unique(index))


def mocap_sigma(gt: PoseStream) -> MocapSigma:
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


def offset_spread(
    r_xyz: F64, g_xyz: F64, vel: F64, audit: OffsetEstimate, offset_ns: int
) -> tuple[float, float]:
    """(sd, centre) in seconds of the true clock offset around the one applied.

    The least-squares offset is off by ``sum_i v_i . e_i / sum_i |v_i|^2`` (v the GT
    velocity at robot pose i, e the robot's error there). The poses' errors are not
    independent (a robot's estimate drifts over seconds), and how much a drift moves that sum
    depends on how it lines up with the path's velocity, which turns over a lap. The sd takes
    that from the log itself: the error series slid along the path by every lag h is as
    likely an alignment as the one logged (a stationary error, independent of where the path
    turns), so the variance of the sum is that of the cross-correlation over the lags,
    ``sum_h c(h)^2 / n`` with ``c(h) = sum_i v_i . e_(i+h)`` (e centred; all lags, no
    window: a window keeps the lags over which a lap's drift projection adds up and drops
    those over which it cancels, which is why a Newey-West sum overshoots 1.25 to 4 times).
    For independent errors it is the sandwich standard error. On the simulator
    (``bench/calibration/trajectory.py``: a bias, a 13 s drift and white noise, drawn anew per
    trial) the offset's actual error is 1.11 times it, as it is of the variance the
    simulator's own error model gives (the rest: the GT's stamping delay); the independent
    poses' sandwich error was 1.57 times too small. The clock audit's block bootstrap
    (``clock_audit``) stays the audit's warning threshold. The centre is the audit's estimate
    minus the offset applied (0 with ``--offset auto --apply-offset``): a given offset the
    data disagrees with moves the interval, not the score.
    """
    sv = float(np.sum(np.square(vel)))
    n = len(vel)
    if n < 3 or sv <= 0.0 or audit.offset_ns is None:
        return 0.0, 0.0
    e = (r_xyz - g_xyz).astype(np.float64)
    v = vel.astype(np.float64)
    centre = (audit.offset_ns - offset_ns) / NS_PER_S
    if audit.disagrees_with(offset_ns):
        # scored at an offset the data disagrees with (``--offset 0`` on a robot 0.35 s
        # ahead), the errors hold v times that disagreement: the spread is the errors' at
        # the offset the interval is centred on (left in, it made the sd 0.2 s there). Not
        # done otherwise: removing an offset estimated from these same errors would take
        # out the drift's projection whose variance this measures.
        e -= v * centre
    e -= e.mean(axis=0)
    # c(h) for every lag at once: zero-padded to a length >= 2n - 1, so the FFT's circular
    # correlation is the linear one; sum_h c(h)^2 = sum_f |C(f)|^2 / m (Parseval)
    m = 1 << (2 * n - 1).bit_length()
    cross = np.sum(np.conj(np.fft.rfft(v, m, axis=0)) * np.fft.rfft(e, m, axis=0), axis=1)
    power = np.abs(cross) ** 2
    # rfft keeps f = 0..m/2: every other frequency stands for its conjugate twin too
    total = float(power[0] + power[-1] + 2.0 * np.sum(power[1:-1])) / m
    return math.sqrt(total / n) / sv, centre


def _bracket(t: IntArr, q: IntArr) -> tuple[IntArr, IntArr]:
    """The GT samples k <= q < k+1 (clipped to the stream)."""
    n = len(t)
    k = np.clip(np.searchsorted(t, q, side="right") - 1, 0, max(n - 2, 0))
    return k, np.minimum(k + 1, n - 1)


def _rescored_rows(t_robot: IntArr, t_gt: IntArr, reach_s: float) -> npt.NDArray[np.intp]:
    """The robot poses the offset's grid re-scores: those the GT covers at some shift of the
    grid, at most :data:`MAX_POSES` of them evenly spread (an hour's log: module doc)."""
    reach = round(reach_s * NS_PER_S) + 1
    rows = np.flatnonzero((t_robot >= t_gt[0] - reach) & (t_robot <= t_gt[-1] + reach))
    if len(rows) > MAX_POSES:
        rows = rows[np.unique(np.linspace(0, len(rows) - 1, MAX_POSES).round().astype(np.intp))]
    return rows


def offset_effects(rescoring: Rescoring, t_gt: IntArr, shifts_s: F64) -> F64:
    """(shifts, KEYS) change of each statistic when the offset applied moves by each shift
    (seconds), the comparison re-scored by the score's own association and metrics: a pose
    a shift moves into a tracking loss or a GT gap leaves the comparison, one it moves out
    of them enters it, next to a stale sample as the score at that offset would compare it
    (0 where no pose would be compared: no score there)."""
    poses = _rescored_rows(rescoring.t_ns, t_gt, float(np.max(np.abs(shifts_s))))
    ref = _statistics(metrics(rescoring.associate(poses, 0)))
    out = np.zeros((len(shifts_s), len(KEYS)))
    if ref is None:
        return out
    for i, shift in enumerate(shifts_s):
        got = _statistics(metrics(rescoring.associate(poses, round(float(shift) * NS_PER_S))))
        if got is not None:
            out[i] = got - ref
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
) -> ResultIntervals:
    """The intervals of the statistics ``estimates`` (by :data:`KEYS`) of a comparison.

    ``robot``: the robot stream whose row i is matched row i; ``gt``: the GT in time order;
    ``offset_ns``: the offset the score applied; ``rescoring``: the score's association, which
    the offset's draws re-score with.
    """
    ok = matched.status == COMPARED
    if not settings.enabled or not ok.any() or len(gt) < 2:
        return NO_INTERVALS
    few = too_few(
        int(ok.sum()),
        "compared pose(s)",
        max(MIN_INTERVAL_SAMPLES, MIN_POSES),
        f"the clock offset's spread (the time association, most often the largest source) "
        f"being measured from {MIN_POSES} or more",
    )
    if few is not None:
        # a null interval with the reason, not one of the mocap noise alone
        return withheld(KEYS, few, settings, METHOD_TRAJECTORY)
    q = matched.t_ns[ok]
    r_xyz = robot.xyz[ok]
    r_yaw = robot.yaw[ok]
    g_xyz = matched.gt_xyz[ok]
    g_yaw = matched.gt_yaw[ok]
    t = gt.t_ns
    k, k1 = _bracket(t, q)
    period = (t[k1] - t[k]) / NS_PER_S
    # A pose compared across a GT gap (--gaps compare, 2015) is held up to the gap's length:
    # that is the log's gap (a validity matter, reported), not the frame period's lag
    period = np.minimum(period, 1.5 * np.median(period))
    a = np.clip((q - t[k]) / np.maximum(t[k1] - t[k], 1), 0.0, 1.0)
    # GT velocity and yaw rate around each pose, over ~VELOCITY_HALF_SPAN samples either side
    lo = np.clip(k - VELOCITY_HALF_SPAN, 0, len(t) - 1)
    hi = np.clip(k1 + VELOCITY_HALF_SPAN, 0, len(t) - 1)
    span = np.maximum((t[hi] - t[lo]).astype(np.float64) / NS_PER_S, 1e-9)
    vel = (gt.xyz[hi] - gt.xyz[lo]) / span[:, None]
    yaw_rate = np.angle(np.exp(1j * (gt.yaw[hi] - gt.yaw[lo]))) / span
    sig = mocap_sigma(gt)
    if association == "linear":
        weight = np.sqrt((1.0 - a) ** 2 + a**2)
        lag_lo, lag_hi = 0.0, 0.0
    elif association == "hold":
        weight = np.ones(len(q))
        lag_lo, lag_hi = -1.0, 0.0
    else:
        weight = np.ones(len(q))
        lag_lo, lag_hi = -0.5, 0.5
    off_sigma, off_centre = offset_spread(r_xyz, g_xyz, vel, audit, offset_ns)
    frame_term = lag_hi > lag_lo
    raw0 = matched.yaw_diff_raw[ok]
    n_all = len(q)
    # An hour's log: the draws run on evenly thinned poses (module doc)
    if n_all > MAX_POSES:
        keep = np.unique(np.linspace(0, n_all - 1, MAX_POSES).round().astype(np.intp))
        r_xyz, r_yaw, g_xyz, g_yaw = r_xyz[keep], r_yaw[keep], g_xyz[keep], g_yaw[keep]
        vel, yaw_rate, weight, period, raw0 = (
            vel[keep],
            yaw_rate[keep],
            weight[keep],
            period[keep],
            raw0[keep],
        )
    else:
        keep = np.arange(n_all)
    n = len(r_yaw)
    thin = math.sqrt(n / n_all)
    est = np.array([estimates[key] for key in KEYS])

    def errors(gp: F64, gy: F64) -> F64:
        """(draws, S) statistics of perturbed GT poses, as metrics() computes them."""
        d = np.sqrt(np.sum(np.square(gp - r_xyz), axis=-1))
        pi = math.pi
        dyaw = np.abs(np.remainder(r_yaw - gy + pi, 2 * pi) - pi)
        raw = np.abs(raw0 + (np.remainder(g_yaw - gy + pi, 2 * pi) - pi))
        pct = np.percentile(d, PERCENTILES, axis=-1).T  # PERCENTILES[0] is the median
        return np.column_stack(
            [
                d.mean(axis=-1),
                np.arctan2(np.sin(dyaw).sum(axis=-1), np.cos(dyaw).sum(axis=-1)),
                np.sqrt(np.mean(np.square(d), axis=-1)),
                pct[:, 0],
                d.max(axis=-1),
                pct,
                np.arctan2(np.sin(raw).sum(axis=-1), np.cos(raw).sum(axis=-1)),
            ]
        )

    base = errors(g_xyz[None], g_yaw[None])[0]
    # The offset's effect: the comparison re-scored by the score's own association and
    # metrics at shifts of the offset (every robot pose inside the GT, compared or not: a
    # shift moves a pose into a tracking loss or out of one, across a GT sample or next
    # to a stale one, as the score at that offset would), on a grid the draws interpolate
    grid = np.linspace(-OFFSET_SPAN, OFFSET_SPAN, OFFSET_GRID) * off_sigma + off_centre
    on_grid = np.zeros((OFFSET_GRID, est.size))
    if off_sigma > 0.0:
        on_grid = offset_effects(rescoring, t, grid)

    def perturbed(rng: np.random.Generator, sources: frozenset[str], draws: int) -> F64:
        """Draws whose basic (reflected) interval is the interval wanted (module doc):
        measurement-like perturbations as re-computed scores, the offset's mirrored."""
        chunk = max(1, CHUNK_ELEMENTS // max(n, 1))
        noise = MOCAP_NOISE in sources
        timing = TIME_ASSOCIATION in sources
        measured = np.zeros((draws, est.size))
        offset = np.zeros((draws, est.size))
        for start in range(0, draws, chunk):
            m = min(chunk, draws - start)
            rows = slice(start, start + m)
            if noise or (timing and frame_term):
                gp = np.broadcast_to(g_xyz, (m, n, 3)).copy()
                gy = np.broadcast_to(g_yaw, (m, n)).copy()
                if noise:
                    # drawn in float32 (the stream the calibration was measured with;
                    # seven digits of a noise sample are plenty), added in float64
                    gp += rng.standard_normal((m, n, 3), dtype=np.float32) * (
                        sig.position * weight[None, :, None]
                    )
                    gy += rng.standard_normal((m, n), dtype=np.float32) * (sig.yaw * weight)
                if timing and frame_term:
                    lag = rng.uniform(lag_lo, lag_hi, (m, n)) * period
                    gp += lag[..., None] * vel
                    gy += lag * yaw_rate
                measured[rows] = errors(gp, gy) - base
            if timing and off_sigma > 0.0:
                shift = rng.standard_normal(m) * off_sigma + off_centre
                # one shift for every pose: the statistics are a function of it alone,
                # re-scored on the grid and interpolated (the grid's step, a tenth of the
                # sd, is much finer than the draws' spread)
                offset[rows] = np.column_stack(
                    [np.interp(shift, grid, on_grid[:, j]) for j in range(est.size)]
                )
        if thin < 1.0:
            # per-pose noise averages over all the poses of a mean-like statistic, not only
            # over the thinned ones: its spread (not its bias) scales with sqrt(n / N)
            bias = measured[:, MEAN_LIKE].mean(axis=0)
            measured[:, MEAN_LIKE] = bias + (measured[:, MEAN_LIKE] - bias) * thin
        # mirrored: the offset is not a measurement of the truth plus an error that the
        # draws add again; the truth's offset is spread around the applied one as the draws
        # are, so the reflection of the basic interval must not apply to it
        return np.asarray(est + measured - offset, dtype=np.float64)

    sources = [MOCAP_NOISE]
    if off_sigma > 0.0 or frame_term:
        sources.append(TIME_ASSOCIATION)
    got = monte_carlo(
        est,
        perturbed,
        sources,
        draws=settings.draws,
        seed=settings.seed,
        confidence=settings.confidence,
        nonnegative=True,
    )
    intervals = dict(zip(KEYS, got, strict=True))
    src = [Source(MOCAP_NOISE, sig.position, "m", sig.measured, sig.note)]
    if TIME_ASSOCIATION in sources:
        parts = []
        if off_sigma > 0.0:
            parts.append(
                f"clock offset sd {off_sigma * 1000:.3f} ms (standard error of the "
                "least-squares offset, the robot's error slid along the path by every lag), "
                f"centred {off_centre * 1000:+.3f} ms from the applied "
                "one (the clock audit's estimate); mirrored: drawn as the truth's offset"
            )
        else:
            parts.append(f"no offset estimate (clock audit: {audit.note or 'none'})")
        if frame_term:
            med = float(np.median(period)) * 1000
            parts.append(
                f"{association}: GT frame period {med:.2f} ms (lag uniform over "
                f"[{lag_lo:g}, {lag_hi:g}] periods)"
            )
        src.append(Source(TIME_ASSOCIATION, off_sigma, "s", off_sigma > 0.0, "; ".join(parts)))
    elif audit.uncertainty_s is None:
        pass
    unc = Uncertainty(
        confidence=settings.confidence,
        method=METHOD_TRAJECTORY,
        draws=settings.draws,
        seed=settings.seed,
        sources=tuple(src),
        shares=shares_of(intervals),
    )
    return ResultIntervals(intervals, unc)
