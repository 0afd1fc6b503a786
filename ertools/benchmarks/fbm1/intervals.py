"""Confidence intervals of the FBM1 pose terms (issue 28).

What of an FBM1 score depends on the ground truth: per run the item's ground-truth pose (x, y,
theta), the errors of the answer against it (x, y, translation, theta) and the run's pose score;
over the runs the pose score total. The class and instance accuracies are counts of names
compared as strings and the execution time comes from the state messages: no measurement noise
enters them, and they get no interval.

Two sources, both measured from the data where the data has them:

- ``mocap_noise``: the ground truth is the mean of the item poses over the stationary window
  before the goal (``--gt window``), or one interpolated lookup (the 2015 and 2016 nodes). The
  per-sample scatter of x, y and yaw over that window is measured run by run; the mean of n
  samples has sigma / sqrt(n_eff). Mocap samples are not always independent (a tracker's
  filter smooths them, and one body is interpolated at the other's stamps, which mixes
  neighbouring samples): the lag-1 autocorrelation rho is measured, pooled over every run's
  window and axis, and n_eff = n (1 - rho) / (1 + rho), the AR(1) effective sample size.
  A sigma estimated from n samples is itself uncertain: the draws use it scaled by the
  Student t quantile over the normal one (n_eff - 1 degrees of freedom), so a short window
  gets the wider interval it deserves. A lookup uses one sample: sigma itself.
- ``transform``: T_board_item from the item list. A list written by ``ertools acquire items``
  carries each item's spread (RMS over its window) and sample count: per axis spread / sqrt(3)
  / sqrt(samples). A list without spread (the 2015 lists: one tf lookup each) is taken as one
  sample of this log's mocap noise (a stated default); a vanilla list (identity transforms) has
  no transform to be uncertain about. One item's transform error is shared by every run that
  presented it (drawn once per item, turned into each run's table frame).

The draws re-compute the scores exactly as :mod:`ertools.benchmarks.fbm1.formula` does, vectorised
over (draws, runs).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import replace

import numpy as np

from ertools.arrays import F64
from ertools.benchmarks.common.inputs import IntervalSettings
from ertools.benchmarks.common.interval_output import (
    METHOD,
    NO_INTERVALS,
    ResultIntervals,
    shares_of,
)
from ertools.benchmarks.common.uncertainty import (
    MOCAP_NOISE,
    TRANSFORM,
    Interval,
    Source,
    Uncertainty,
    monte_carlo,
    z_value,
)
from ertools.benchmarks.fbm1.config import GtOptions, ScoreRules
from ertools.benchmarks.fbm1.formula import MAX_POSE_ERROR_2015
from ertools.benchmarks.fbm1.gt import GroundTruthError, board_in_table, measure_ground_truth
from ertools.benchmarks.fbm1.result import Fbm1RunResult
from ertools.benchmarks.fbm1.runs import Fbm1Run
from ertools.configs.items import IDENTITY_ROT, IDENTITY_TRANS, Item
from ertools.frozen_dataclass import frozen_dataclass
from ertools.geometry import compose, yaw_from_quat
from ertools.streams import PoseStream
from ertools.timeutil import NS_PER_S

# Where a run's window has fewer than 3 samples: one sample of a 2015 mocap marker set
# (0.3 mm per axis, 0.05 deg: the scatter of a still body in the real 2015 logs).
DEFAULT_SIGMA_M = 3e-4
DEFAULT_SIGMA_RAD = math.radians(0.05)

#: The per-run keys with an interval, in the order of the run's YAML entry.
GT_KEYS = ("x", "y", "theta")
ERROR_KEYS = ("x", "y", "translation", "theta")


@frozen_dataclass
class RunNoise:
    """The measured mocap noise of one run's ground truth.

    Attributes:
        sample_sigma: (3,) per-sample standard deviation of x, y (metres) and yaw (radians)
            of the item in the table frame over the run's still window.
        mean_sigma: (3,) the same for the ground truth used (the window's mean, or one lookup),
            scaled for the sigma's own uncertainty (t over z).
        samples: samples in the window the noise was measured on (0: default used).
        rho: lag-1 autocorrelation of those samples (mean over x, y, yaw).
        n_eff: effective number of independent samples in the ground truth's mean.
    """

    sample_sigma: F64
    mean_sigma: F64
    samples: int
    rho: float
    n_eff: float


def window_samples(
    origin: PoseStream, board: PoseStream, item: Item, start_ns: int, end_ns: int, max_gap_ns: int
) -> tuple[F64, F64]:
    """The item's (x, y) and yaw in the table frame at every board sample in the window."""
    rel = board_in_table(
        origin.window(start_ns - max_gap_ns, end_ns + max_gap_ns),
        board.window(start_ns, end_ns),
        max_gap_ns,
    )
    if len(rel) == 0 or item.trans is None or item.rot is None:
        return np.zeros((0, 2)), np.zeros(0)
    n = len(rel)
    t_item = np.tile(np.asarray(item.trans, dtype=np.float64), (n, 1))
    q_item = np.tile(np.asarray(item.rot, dtype=np.float64), (n, 1))
    xyz, quat = compose(rel.xyz, rel.quat_xyzw, t_item, q_item)
    return xyz[:, :2], np.asarray(yaw_from_quat(quat), dtype=np.float64)


def _lag1(x: F64) -> float:
    d = x - x.mean()
    den = float(np.dot(d, d))
    return float(np.dot(d[1:], d[:-1]) / den) if den > 0.0 else 0.0


def _columns(xy: F64, yaw: F64, gt_yaw: float) -> tuple[F64, F64, F64]:
    return xy[:, 0], xy[:, 1], np.angle(np.exp(1j * (yaw - gt_yaw)))


def pooled_rho(windows: Sequence[tuple[F64, F64, float]]) -> float:
    """The lag-1 autocorrelation of the mocap noise, pooled over every window and axis.

    Correlation is a property of the mocap system (its filter, and the interpolation of one
    body at the other's stamps), not of one run: pooled over all runs it is measured to about
    0.02 instead of 0.1 from one window, so it does not make the intervals of single runs
    randomly wide or narrow. Never below 0 (anti-correlated noise is not credited).
    """
    num = den = 0.0
    for xy, yaw, gt_yaw in windows:
        if len(yaw) < 3:
            continue
        for c in _columns(xy, yaw, gt_yaw):
            d = c - c.mean()
            num += float(np.dot(d[1:], d[:-1]))
            den += float(np.dot(d, d))
    return max(0.0, num / den) if den > 0.0 else 0.0


def run_noise(
    xy: F64, yaw: F64, *, lookup: bool, confidence: float, gt_yaw: float, rho: float
) -> RunNoise:
    """The noise of a ground truth measured on ``n`` still samples (module doc)."""
    # scipy.special comes with scipy.spatial, which the ground truth's rotations already need;
    # scipy.stats (its t distribution) would add ~0.3 s of imports for this
    from scipy.special import stdtrit  # lazy: scipy.special, ~0 ms beside scipy.spatial

    n = len(yaw)
    if n < 3:
        sample = np.array([DEFAULT_SIGMA_M, DEFAULT_SIGMA_M, DEFAULT_SIGMA_RAD])
        return RunNoise(sample, sample.copy(), 0, 0.0, 1.0)
    sample = np.array([float(np.std(c, ddof=1)) for c in _columns(xy, yaw, gt_yaw)])
    # the AR(1) effective sample size of the window's mean
    n_eff = max(1.0, n * (1.0 - rho) / (1.0 + rho))
    df = max(n_eff - 1.0, 1.0)
    a = (1.0 - confidence) / 2.0
    widen = float(stdtrit(df, 1.0 - a)) / z_value(confidence)
    used = 1.0 if lookup else n_eff
    return RunNoise(sample, sample / math.sqrt(used) * widen, n, rho, n_eff)


def _wrap_deg(angle: F64, legacy: bool) -> F64:
    if legacy:
        angle = np.where(angle > 180.0, angle - 360.0, angle)
        return np.where(angle < -180.0, angle + 360.0, angle)
    return np.mod(angle + 180.0, 360.0) - 180.0


def _terms(dist: F64, dtheta: F64, rules: ScoreRules) -> F64:
    """The pose score 1 - t/2 - r/2 of :func:`ertools.benchmarks.fbm1.formula.pose_errors`."""
    if rules.clip_above_diagonal:
        t = np.where(dist > MAX_POSE_ERROR_2015, 1.0, dist)
    else:
        t = np.minimum(dist, 1.0)
    r = np.minimum(np.abs(dtheta) / 180.0, 1.0)
    return np.asarray(1.0 - t / 2.0 - r / 2.0, dtype=np.float64)


def _is_identity(item: Item) -> bool:
    return (item.trans, item.rot) in ((IDENTITY_TRANS, IDENTITY_ROT), (None, None))


def fbm1_intervals(
    runs: Sequence[Fbm1RunResult],
    found: Sequence[Fbm1Run],
    origin: PoseStream,
    board: PoseStream,
    *,
    gt_options: GtOptions,
    rules: ScoreRules,
    pose_runs: int,
    pose_total: float | None,
    settings: IntervalSettings,
) -> ResultIntervals:
    """The intervals of every ground-truth-derived number of the result (module doc)."""
    scored = [r for r in runs if r.errors is not None and r.gt is not None and r.answer]
    if not settings.enabled or not scored:
        return NO_INTERVALS
    by_index = {run.index: run for run in found}
    max_gap = round(gt_options.max_gap_s * NS_PER_S)
    lookup = gt_options.method != "window"
    windows: list[tuple[F64, F64, float]] = []
    for r in scored:
        assert r.gt is not None and r.item is not None
        start, end = r.gt.start_ns, r.gt.end_ns
        if lookup:
            # One lookup: its noise is measured on the still window the window method uses.
            run = by_index.get(r.index)
            try:
                if run is None or run.goal_ns is None:
                    raise GroundTruthError("no goal")
                win, _ = measure_ground_truth(
                    origin,
                    board,
                    r.item,
                    search_start_ns=run.start_ns,
                    goal_ns=run.goal_ns,
                    result_ns=run.result_ns,
                    options=replace(gt_options, method="window"),
                    placed_ns=run.placed_ns,
                )
                start, end = win.start_ns, win.end_ns
            except GroundTruthError:
                start, end = 0, -1
        xy, yaw = window_samples(origin, board, r.item, start, end, max_gap)
        windows.append((xy, yaw, r.gt.yaw))
    rho = pooled_rho(windows)
    noises = [
        run_noise(xy, yaw, lookup=lookup, confidence=settings.confidence, gt_yaw=g, rho=rho)
        for xy, yaw, g in windows
    ]
    n_runs = len(scored)
    gx = np.array([r.gt.x for r in scored if r.gt])
    gy = np.array([r.gt.y for r in scored if r.gt])
    gyaw = np.array([r.gt.yaw_deg for r in scored if r.gt])
    ax = np.array([r.answer.x for r in scored if r.answer])
    ay = np.array([r.answer.y for r in scored if r.answer])
    ath = np.array([r.answer.theta_deg for r in scored if r.answer])
    mean_sigma = np.array([nz.mean_sigma for nz in noises])  # (R, 3)
    # Items: one transform error each, shared by the runs presenting it.
    item_ids = sorted({r.item.id for r in scored if r.item})
    slot = np.array([item_ids.index(r.item.id) for r in scored if r.item])
    item_sigma = np.zeros((len(item_ids), 3))
    spread_given = 0
    for k, iid in enumerate(item_ids):
        runs_k = [i for i, r in enumerate(scored) if r.item and r.item.id == iid]
        item = scored[runs_k[0]].item
        assert item is not None
        if _is_identity(item):
            continue
        if item.spread is not None and item.spread.samples > 0:
            spread_given += 1
            root = math.sqrt(3.0 * item.spread.samples)
            item_sigma[k] = (
                item.spread.position_m / root,
                item.spread.position_m / root,
                math.radians(item.spread.angle_deg) / root,
            )
        else:
            item_sigma[k] = np.median([noises[i].sample_sigma for i in runs_k], axis=0)
    has_transform = bool(item_sigma.any())
    used = item_sigma[item_sigma.any(axis=1)]
    transform_sigma = float(np.median(used[:, 0])) if has_transform else None
    # The board's yaw in the table frame turns an item's error (board frame) into the table's.
    board_yaw = np.array(
        [
            r.gt.yaw - float(yaw_from_quat(np.asarray([r.item.rot]))[0])
            if r.gt and r.item and r.item.rot
            else 0.0
            for r in scored
        ]
    )
    cos_b, sin_b = np.cos(board_yaw), np.sin(board_yaw)
    others = [r for r in runs if r.status in ("scored", "no_answer") and r not in scored]
    rest = math.fsum(r.pose_score or 0.0 for r in others)

    def perturbed(rng: np.random.Generator, sources: frozenset[str], n: int) -> F64:
        px = np.broadcast_to(gx, (n, n_runs)).copy()
        py = np.broadcast_to(gy, (n, n_runs)).copy()
        pyaw = np.broadcast_to(gyaw, (n, n_runs)).copy()
        if MOCAP_NOISE in sources:
            e = rng.standard_normal((n, n_runs, 3)) * mean_sigma
            px += e[..., 0]
            py += e[..., 1]
            pyaw += np.degrees(e[..., 2])
        if TRANSFORM in sources and has_transform:
            e = (rng.standard_normal((n, len(item_ids), 3)) * item_sigma)[:, slot, :]
            px += cos_b * e[..., 0] - sin_b * e[..., 1]
            py += sin_b * e[..., 0] + cos_b * e[..., 1]
            pyaw += np.degrees(e[..., 2])
        ex, ey = ax - px, ay - py
        dist = np.hypot(ex, ey)
        dth = _wrap_deg(ath - pyaw, rules.single_wrap)
        score = _terms(dist, dth, rules)
        total = (score.sum(axis=1) + rest) / pose_runs if pose_runs else np.full(n, np.nan)
        return np.column_stack(
            [px, py, _wrap_deg(pyaw, False), ex, ey, dist, dth, score, total[:, None]]
        )

    blocks = [
        [r.gt.x for r in scored if r.gt],
        [r.gt.y for r in scored if r.gt],
        [r.gt.yaw_deg for r in scored if r.gt],
        [r.errors.dx for r in scored if r.errors],
        [r.errors.dy for r in scored if r.errors],
        [r.errors.trans_error_m for r in scored if r.errors],
        [r.errors.theta_error_deg for r in scored if r.errors],
        [r.errors.pose_score for r in scored if r.errors],
    ]
    estimate = [v for block in blocks for v in block]
    estimate.append(math.nan if pose_total is None else pose_total)
    names = [MOCAP_NOISE] + ([TRANSFORM] if has_transform else [])
    got = monte_carlo(
        estimate,
        perturbed,
        names,
        draws=settings.draws,
        seed=settings.seed,
        confidence=settings.confidence,
        nonnegative=False,
    )
    paths = [
        *(("ground_truth", k) for k in GT_KEYS),
        *(("error", k) for k in ERROR_KEYS),
        ("pose_score", ""),
    ]
    out: dict[str, Interval | None] = {}
    for i, r in enumerate(scored):
        for b, (section, key) in enumerate(paths):
            name = f"runs.{r.index}.{section}" + (f".{key}" if key else "")
            iv = got[b * n_runs + i]
            if iv is not None and (section, key) == ("error", "translation"):
                iv = Interval(max(0.0, iv.low), max(0.0, iv.high), iv.shares)
            out[name] = iv
    out["pose_score"] = got[-1]
    unc = _uncertainty(out, noises, settings, transform_sigma, spread_given, lookup)
    return ResultIntervals(out, unc)


def _uncertainty(
    intervals: Mapping[str, Interval | None],
    noises: Sequence[RunNoise],
    settings: IntervalSettings,
    transform_sigma: float | None,
    spread_given: int,
    lookup: bool,
) -> Uncertainty:
    measured = [nz for nz in noises if nz.samples]
    sig = np.array([nz.sample_sigma for nz in measured]) if measured else None
    xy_sigma = float(np.median(sig[:, :2])) if sig is not None else DEFAULT_SIGMA_M
    rho = measured[0].rho if measured else 0.0
    ratio = float(np.median([nz.n_eff / nz.samples for nz in measured])) if measured else 1.0
    used = "one lookup per run (sigma of one sample)" if lookup else "the mean over the window"
    note = (
        f"per-sample scatter of the item pose over each run's still window ({len(measured)} of "
        f"{len(noises)} run(s) measured, median "
        f"{int(np.median([nz.samples for nz in measured])) if measured else 0} samples, "
        f"median yaw {math.degrees(float(np.median(sig[:, 2]))) if sig is not None else 0:.3g}"
        f" deg); ground truth = {used}; lag-1 autocorrelation {rho:.3f} (pooled over the "
        f"runs), n_eff = n (1-rho)/(1+rho) = {ratio:.2f} n; "
        "sigma widened by Student t / normal for its own uncertainty"
    )
    sources = [Source(MOCAP_NOISE, xy_sigma, "m", bool(measured), note)]
    if transform_sigma is not None:
        sources.append(
            Source(
                TRANSFORM,
                transform_sigma,
                "m",
                spread_given > 0,
                f"{spread_given} item(s) with the acquisition's spread (spread / sqrt(3 n)); "
                "the others one sample of this log's mocap noise (a list without spread: "
                "one 2015 tf lookup)",
            )
        )
    return Uncertainty(
        confidence=settings.confidence,
        method=METHOD,
        draws=settings.draws,
        seed=settings.seed,
        sources=tuple(sources),
        shares=shares_of(intervals),
    )
