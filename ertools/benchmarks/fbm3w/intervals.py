"""Confidence intervals of FBM3@Work's distance errors (issue 28): the runs re-scored with
perturbed poses and ``d_min``, all Monte Carlo draws at once. No IO here.

Sources (:mod:`ertools.benchmarks.common.uncertainty`):

- ``mocap_noise``: every measured position (and the reference position) moved by normal
  noise of sigma per axis, sigma = epsilon / sqrt(pi) from the bag's own stationary phases
  (``noise_from_stream(..., stationary=True)``, as ``ertools noise --stationary auto``).
  sigma is itself an estimate: each draw takes its own sigma around it, with the relative
  standard error of a mean of M Rayleigh distances (0.523 / sqrt(M/2); consecutive pairs
  share a sample, hence M/2). A repeated (frozen) pose repeats its noise too: the mocap sent
  one measurement several times. Without a still phase: epsilon = d_min / 3 (the seed's
  D_MIN = c * epsilon with c = 3), stated as a default.
- ``d_min``: the seed sets d_min = c * epsilon (7.3.2); a d_min chosen from a noise estimate
  is as uncertain as that estimate, so each draw scales d_min by the same relative standard
  error as sigma's (10% when there is no estimate, stated as a default).

The draws perturb a smoothed path, not the measured one: a quadratic Savitzky-Golay fit over
9 samples (exact for any motion of constant acceleration over 75 ms at 120 Hz) keeps the
path and removes most of the noise (the residual's variance is 59/231 of sigma^2 and, what
Eq. (1) responds to, its consecutive differences almost vanish), and each draw adds noise of
the full sigma to it: a draw is then a log of the smoothed path measured again. Adding sigma
to the already noisy positions would double the noise variance, and Eq. (1) is far from
linear in it: d_min subsampling keeps a still
marker set's jitter only when a step passes d_min, a tail probability that grows ~200 times
from sigma to sigma sqrt(2) at the 2015 values; the basic interval then over-corrects the
bias (the calibration found every miss above the interval). Each draw's shift from the
smoothed path's own score, added to the score, gives the basic interval.

Each draw re-runs the whole Eq. (1) on the perturbed positions: the d_min subsampling (a
sequential rule: one pass over the samples, each step vectorised over the draws of all the
runs side by side), the run frame from the perturbed reference and start, l/L and the mean
distance. ``best_distance_error`` is the
minimum over the runs of each draw.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace

import numpy as np
import numpy.typing as npt

from ertools.arrays import F64, Bool, IntArr
from ertools.benchmarks.common.uncertainty import (
    D_MIN,
    MOCAP_NOISE,
    Interval,
    Source,
    Uncertainty,
    monte_carlo,
    sigma_from_epsilon,
    too_few,
)
from ertools.benchmarks.fbm3w.config import Fbm3wOptions
from ertools.benchmarks.fbm3w.result import RunResult
from ertools.benchmarks.noise.benchmark import NoiseResult
from ertools.configs.fbm3w import Fbm3wConfig
from ertools.configs.shapes import Shape
from ertools.streams import PoseStream

# The coefficient of variation of a Rayleigh distance, sqrt(4/pi - 1): the spread of one
# consecutive-pair distance around epsilon.
RAYLEIGH_CV = math.sqrt(4.0 / math.pi - 1.0)
DEFAULT_C = 3.0  # the seed's D_MIN = c * epsilon (7.3.2), for the default noise
DEFAULT_D_MIN_REL = 0.10
# Draws x samples of one batch: bounds the memory of a long run (~8 bytes x a few arrays).
BATCH_ELEMENTS = 2_000_000
# Draws x samples of the runs whose d_min rule runs in one pass (padded to the longest): a
# competition's four runs of ~600 samples x 400 draws in two passes, ~8 MB a pass, so that a
# score's peak memory stays within 4 MB of the run-by-run pass it replaced.
GROUP_ELEMENTS = 600_000
METHOD = "Monte Carlo (parametric bootstrap around the smoothed path, basic interval)"
# Quadratic Savitzky-Golay weights over 9 samples, and the variance of noise left after it.
SMOOTH = np.array([-21.0, 14.0, 39.0, 54.0, 59.0, 54.0, 39.0, 14.0, -21.0]) / 231.0
HALF = len(SMOOTH) // 2


def smooth(xy: F64) -> F64:
    """(N, 2) positions with most of the noise removed (a quadratic fit over 9 samples);
    the first and last 4 take the nearest full window's value; fewer than 9: the mean."""
    p = np.asarray(xy, dtype=np.float64)
    n = len(p)
    if n < len(SMOOTH):
        return np.repeat(p.mean(axis=0, keepdims=True), n, axis=0)
    out = np.column_stack([np.convolve(p[:, k], SMOOTH[::-1], mode="valid") for k in (0, 1)])
    head = np.repeat(out[:1], HALF, axis=0)
    tail = np.repeat(out[-1:], HALF, axis=0)
    return np.concatenate([head, out, tail])


@dataclass(frozen=True, eq=False)
class RunSamples:
    """What one scored run's Eq. (1) depends on.

    Attributes:
        xy: (N, 2) the measured positions of the path window (world).
        source: (N,) index of the measurement each sample carries (a repeated pose carries
            the one it repeats).
        reference_xy: (2,) the measured reference position.
        shape: the target.
        center_xy, center_reference_xy: the smoothed path and reference the draws perturb
            (None: the measured ones).
    """

    xy: F64
    source: IntArr
    reference_xy: F64
    shape: Shape
    center_xy: F64 | None = None
    center_reference_xy: F64 | None = None


@dataclass(frozen=True)
class NoiseModel:
    """The sources' sizes: sigma per axis (m), its relative standard error, d_min (m) and
    d_min's relative standard deviation."""

    sigma: float
    sigma_rel: float
    d_min: float
    d_min_rel: float
    sources: tuple[Source, ...]


def measurement_source(repeats: F64 | np.ndarray) -> IntArr:
    """(N,) index of the measurement each sample carries, from the (N-1,) repeat flags
    (True where a pose repeats the previous one)."""
    rep = np.asarray(repeats, dtype=bool)
    n = rep.size + 1
    idx = np.arange(n)
    new = np.ones(n, dtype=bool)
    new[1:] = ~rep
    return np.asarray(np.maximum.accumulate(np.where(new, idx, 0)), dtype=np.intp)


def noise_model(noise: NoiseResult | None, d_min: float) -> NoiseModel:
    """The sources' sizes from the bag's noise estimate, or the stated defaults."""
    pairs = 0 if noise is None else int(noise.distances.size)
    if noise is not None and pairs >= 2 and math.isfinite(noise.epsilon) and noise.epsilon > 0:
        sigma = sigma_from_epsilon(noise.epsilon)
        rel = RAYLEIGH_CV / math.sqrt(pairs / 2.0)
        note = (
            f"sigma = epsilon / sqrt(pi), epsilon {noise.epsilon * 1000:.4g} mm from "
            f"{pairs} pairs over {noise.duration_s:.1f} s of stationary phases (relative "
            f"standard error {rel:.1%}, drawn per draw)"
        )
        mocap = Source(MOCAP_NOISE, sigma, "m", True, note)
        dmin = Source(
            D_MIN,
            d_min * rel,
            "m",
            True,
            f"d_min = c * epsilon is as uncertain as epsilon: d_min x (1 + {rel:.2%} z)",
        )
        return NoiseModel(sigma, rel, d_min, rel, (mocap, dmin))
    epsilon = d_min / DEFAULT_C
    sigma = sigma_from_epsilon(epsilon)
    mocap = Source(
        MOCAP_NOISE,
        sigma,
        "m",
        False,
        "default: no stationary phase in the poses; epsilon = d_min / 3 (the seed's "
        "D_MIN = c * epsilon, c = 3), sigma = epsilon / sqrt(pi)",
    )
    dmin = Source(
        D_MIN,
        d_min * DEFAULT_D_MIN_REL,
        "m",
        False,
        f"default: d_min x (1 + {DEFAULT_D_MIN_REL:.0%} z), no noise estimate to size it",
    )
    return NoiseModel(sigma, 0.0, d_min, DEFAULT_D_MIN_REL, (mocap, dmin))


def perturbed_errors(
    run: RunSamples, sigmas: F64, d_mins: F64, rng: np.random.Generator, noisy: bool
) -> F64:
    """(D,) distance errors of one run with its positions perturbed by ``sigmas`` (D,) (when
    ``noisy``) and subsampled with ``d_mins`` (D,); NaN where a draw cannot be scored."""
    return perturbed_runs([run], sigmas, d_mins, rng, noisy)[:, 0]


def perturbed_runs(
    runs: Sequence[RunSamples],
    sigmas: F64,
    d_mins: F64,
    rng: np.random.Generator,
    noisy: bool,
    *,
    budget: int = BATCH_ELEMENTS,
) -> F64:
    """(D, R) distance errors of every run in every draw: column ``r`` is
    :func:`perturbed_errors` of ``runs[r]``, with the noise drawn from ``rng`` in the same
    order (run by run, each run's draws in batches of at most ``budget`` samples).

    The d_min rule is one pass over the samples for as many runs (all their draws side by
    side) as fit in :data:`GROUP_ELEMENTS` (or ``budget``, if smaller) padded samples.
    """
    d = sigmas.size
    out = np.empty((d, len(runs)))
    pieces = [
        (col, lo, min(d, lo + batch))
        for col, run in enumerate(runs)
        for batch in [max(1, budget // max(len(run.xy), 1))]
        for lo in range(0, d, batch)
    ]
    for group in _groups(pieces, [len(r.xy) for r in runs], min(budget, GROUP_ELEMENTS)):
        # every piece's draws side by side, samples down the rows (shorter runs padded with
        # NaN, never kept): the positions are drawn straight into these two arrays
        lengths = [len(runs[col].xy) for col, _, _ in group]
        edges = np.cumsum([0, *(hi - lo for _, lo, hi in group)])
        xt = np.full((max(lengths), int(edges[-1])), np.nan)
        yt = np.full_like(xt, np.nan)
        views = [
            (xt[:m, a:b].T, yt[:m, a:b].T, slice(a, b), m)
            for a, b, m in zip(edges[:-1], edges[1:], lengths, strict=True)
        ]
        refs = [
            _positions(runs[col], sigmas[lo:hi], rng, noisy, x, y)
            for (col, lo, hi), (x, y, _, _) in zip(group, views, strict=True)
        ]
        kept = _subsample(xt, yt, np.concatenate([d_mins[lo:hi] for _, lo, hi in group]))
        for (col, lo, hi), (x, y, cols, m), (rx, ry) in zip(group, views, refs, strict=True):
            out[lo:hi, col] = _eq1(x, y, kept[:m, cols].T, rx, ry, runs[col].shape)
    return out


def _groups(
    pieces: list[tuple[int, int, int]], lengths: list[int], budget: int
) -> list[list[tuple[int, int, int]]]:
    """Consecutive (run, lo, hi) pieces grouped while the group's draws x its longest run
    stay within ``budget`` (a piece alone may exceed it only with a single draw)."""
    groups: list[list[tuple[int, int, int]]] = []
    width = longest = 0
    for piece in pieces:
        col, lo, hi = piece
        w, n = width + hi - lo, max(longest, lengths[col])
        if groups and w * n <= budget:
            groups[-1].append(piece)
            width, longest = w, n
        else:
            groups.append([piece])
            width, longest = hi - lo, lengths[col]
    return groups


def _positions(
    run: RunSamples, sigmas: F64, rng: np.random.Generator, noisy: bool, x: F64, y: F64
) -> tuple[F64, F64]:
    """One run's perturbed sample positions written into ``x`` and ``y`` (D, N), and the
    (D,) x and y of its reference; the noise of the samples drawn first (D, measurements,
    2), then the reference's (D, 2)."""
    d = sigmas.size
    n = len(run.xy)
    xy = run.xy if run.center_xy is None else run.center_xy
    ref = run.reference_xy if run.center_reference_xy is None else run.center_reference_xy
    if not noisy:
        np.add(xy[None, :, 0], 0.0, out=x)
        np.add(xy[None, :, 1], 0.0, out=y)
        return np.full(d, ref[0] + 0.0), np.full(d, ref[1] + 0.0)
    measured = int(run.source.max()) + 1 if n else 0
    eps = rng.standard_normal((d, measured, 2))
    if np.any(run.source != np.arange(n)):  # a repeated pose repeats its noise
        eps = eps[:, run.source, :]
    eps *= sigmas[:, None, None]
    ref_eps = rng.standard_normal((d, 2)) * sigmas[:, None]
    np.add(xy[None, :, 0], eps[:, :, 0], out=x)
    np.add(xy[None, :, 1], eps[:, :, 1], out=y)
    return ref[0] + ref_eps[:, 0], ref[1] + ref_eps[:, 1]


def _subsample(xt: F64, yt: F64, d_mins: F64) -> Bool:
    """(N, W) kept flags of the 2015 d_min rule for the W draws side by side in the columns
    of ``xt``, ``yt`` (N, W), each with its d_min: one pass over the samples, each step
    vectorised over every draw (the rule is sequential within a draw). NaN is never kept."""
    n, w = xt.shape
    d2 = d_mins * d_mins
    kept = np.zeros((n, w), dtype=bool)
    kept[0] = True
    lx = xt[0].copy()
    ly = yt[0].copy()
    dx = np.empty(w)
    dy = np.empty(w)
    for j in range(1, n):
        # dx*dx + dy*dy >= d_min^2 against the last kept point, in place (no temporaries)
        np.subtract(xt[j], lx, out=dx)
        np.subtract(yt[j], ly, out=dy)
        np.multiply(dx, dx, out=dx)
        np.multiply(dy, dy, out=dy)
        np.add(dx, dy, out=dx)
        k = np.greater_equal(dx, d2, out=kept[j])
        np.copyto(lx, xt[j], where=k)
        np.copyto(ly, yt[j], where=k)
    return kept


def _eq1(x: F64, y: F64, kept: Bool, rx: F64, ry: F64, shape: Shape) -> F64:
    """Eq. (1) of every draw from its kept flags (as :func:`~.path.score_path`), on the kept
    points only: in row-major order each draw's kept points follow one another, its first
    one (the start, always kept) first. Temporaries are reused (``out=``): on this scale
    (10^5 kept points per run) fresh arrays cost more in page faults than in arithmetic."""
    d = x.shape[0]
    rows, cols = np.nonzero(kept)  # draw by draw (row-major), whatever the layout in memory
    count = np.bincount(rows, minlength=d)
    xk, yk = x[rows, cols], y[rows, cols]
    m = rows.size
    starts = np.cumsum(count) - count  # each draw's first kept point (column 0)
    a, b = np.empty(m), np.empty(m)
    run = np.empty(m)
    run[0] = 0.0
    np.subtract(xk[1:], xk[:-1], out=a[1:])
    np.subtract(yk[1:], yk[:-1], out=b[1:])
    np.hypot(a[1:], b[1:], out=run[1:])
    run[starts] = 0.0
    np.cumsum(run, out=run)  # sequential within each draw, as the 2015 loop
    cum = np.subtract(run, np.repeat(run[starts], count), out=run)
    last = starts + count - 1
    total = np.zeros(d)
    total[count > 0] = cum[last[count > 0]]
    x0, y0 = x[:, 0], y[:, 0]
    yaw = np.arctan2(y0 - ry, x0 - rx)
    dx = np.subtract(xk, np.repeat(x0, count), out=xk)
    dy = np.subtract(yk, np.repeat(y0, count), out=yk)
    with np.errstate(invalid="ignore", divide="ignore"):
        l_norm = np.divide(cum, np.repeat(total, count), out=cum)
    np.clip(np.nan_to_num(l_norm, copy=False), 0.0, 1.0, out=l_norm)
    target = shape(l_norm)
    c, s = np.repeat(np.cos(yaw), count), np.repeat(np.sin(yaw), count)
    # the run frame: (c dx + s dy, -s dx + c dy), each minus the target
    np.multiply(c, dx, out=a)
    a += np.multiply(s, dy, out=b)
    a -= target[:, 0]
    np.multiply(c, dy, out=b)
    b -= np.multiply(s, dx, out=c)
    b -= target[:, 1]
    err = np.hypot(a, b, out=a)
    err[starts] = 0.0  # 2015 started its sum at the second kept point
    out = np.bincount(rows, weights=err, minlength=d) / np.maximum(count, 1)
    bad = (count < 2) | ~(total > 0) | ((x0 == rx) & (y0 == ry))
    return np.where(bad, np.nan, out)


def run_intervals(
    runs: Sequence[RunSamples | None],
    estimates: Sequence[float | None],
    model: NoiseModel,
    *,
    draws: int,
    seed: int,
    confidence: float,
) -> tuple[list[Interval | None], Interval | None]:
    """The interval of each run's distance error (None for runs not scored) and of the best
    (smallest) one.

    ``runs[i]`` is None for a run without a score; ``estimates`` are the scores themselves.
    """
    scored = [i for i, r in enumerate(runs) if r is not None and estimates[i] is not None]
    if draws <= 0 or not scored:
        return [None] * len(runs), None
    est = [float(estimates[i]) for i in scored]  # type: ignore[arg-type]
    est.append(min(est))

    # the smoothed paths' own scores: each draw's shift from them is added to the score
    chosen: list[RunSamples] = [r for i in scored if (r := runs[i]) is not None]
    centers = perturbed_runs(
        chosen, np.zeros(1), np.full(1, model.d_min), np.random.default_rng(0), False
    )[0]
    shift = np.asarray(est[:-1]) - centers
    shift_best = est[-1] - float(np.min(centers))

    def perturbed(rng: np.random.Generator, sources: frozenset[str], n: int) -> F64:
        z_sigma = rng.standard_normal(n)
        z_dmin = rng.standard_normal(n)
        sigmas = np.full(n, model.sigma)
        if MOCAP_NOISE in sources:
            sigmas = sigmas * np.maximum(0.0, 1.0 + model.sigma_rel * z_sigma)
        d_mins = np.full(n, model.d_min)
        if D_MIN in sources:
            d_mins = model.d_min * np.maximum(0.0, 1.0 + model.d_min_rel * z_dmin)
        out = np.empty((n, len(scored) + 1))
        out[:, :-1] = perturbed_runs(chosen, sigmas, d_mins, rng, MOCAP_NOISE in sources)
        # the best run of each draw; NaN when one of its runs could not be scored
        best = np.min(out[:, :-1], axis=1) + shift_best
        out[:, :-1] += shift
        out[:, -1] = best
        return out

    names = tuple(s.name for s in model.sources)
    ivs = monte_carlo(est, perturbed, names, draws=draws, seed=seed, confidence=confidence)
    per_run: list[Interval | None] = [None] * len(runs)
    for col, i in enumerate(scored):
        per_run[i] = ivs[col]
    return per_run, ivs[-1]


def uncertainty_block(
    model: NoiseModel,
    per_run: Sequence[tuple[int, Interval | None]],
    best: Interval | None,
    *,
    draws: int,
    seed: int,
    confidence: float,
    withheld: Mapping[str, str] | None = None,
) -> Uncertainty:
    """The result's ``uncertainty`` block (sources, method, shares by dotted key, and why a
    score has no interval)."""
    shares: dict[str, dict[str, float]] = {}
    if best is not None:
        shares["best_distance_error"] = best.share_dict()
    for index, iv in per_run:
        if iv is not None:
            shares[f"runs_details.{index}.distance_error"] = iv.share_dict()
    return Uncertainty(confidence, METHOD, draws, seed, model.sources, shares, withheld or {})


def with_intervals(
    poses: PoseStream,
    same: npt.NDArray[np.bool_],
    results: list[RunResult],
    cfg: Fbm3wConfig,
    options: Fbm3wOptions,
    noise: NoiseResult | None,
) -> tuple[list[RunResult], Interval | None, Uncertainty | None]:
    """Each scored run's distance_error interval and the best run's, from the poses of its
    window; the runs unchanged when ``draws`` is 0."""
    if options.draws <= 0:
        return results, None, None
    samples: list[RunSamples | None] = []
    for run in results:
        w = run.window
        if run.score is None or w.start_ns is None or w.end_ns is None or w.ref_ns is None:
            samples.append(None)
            continue
        lo = int(np.searchsorted(poses.t_ns, w.start_ns, side="left"))
        hi = int(np.searchsorted(poses.t_ns, w.end_ns, side="right"))
        ref_i = int(np.searchsorted(poses.t_ns, w.ref_ns, side="right")) - 1
        shape = cfg.shape(run.spec)
        if options.arc_length:
            shape = shape.by_arc_length()
        around = poses.xyz[max(0, ref_i - 4) : ref_i + 5, :2]
        centre = smooth(around)[min(ref_i, 4)]
        samples.append(
            RunSamples(
                xy=poses.xyz[lo:hi, :2],
                source=measurement_source(same[lo : hi - 1]),
                reference_xy=poses.xyz[ref_i, :2],
                shape=shape,
                center_xy=smooth(poses.xyz[lo:hi, :2]),
                center_reference_xy=centre,
            )
        )
    model = noise_model(noise, cfg.d_min)
    per_run, best = run_intervals(
        samples,
        [r.distance_error for r in results],
        model,
        draws=options.draws,
        seed=options.seed,
        confidence=options.confidence,
    )
    # a run of too few kept points has no interval (null, with the reason), nor has the best
    # score when it is that run's (common/uncertainty.py, MIN_INTERVAL_SAMPLES)
    withheld: dict[str, str] = {}
    scored = [r for r in results if r.score is not None and r.distance_error is not None]
    first_best = min(scored, key=lambda r: r.distance_error or 0.0, default=None)
    for k, r in enumerate(results):
        few = None if r.score is None else too_few(len(r.score.kept), "kept path point(s)")
        if few is not None and per_run[k] is not None:
            per_run[k] = None
            withheld[f"runs_details.{r.index}.distance_error"] = few
            if r is first_best:
                best = None
                withheld["best_distance_error"] = few
    block = uncertainty_block(
        model,
        [(r.index, iv) for r, iv in zip(results, per_run, strict=True)],
        best,
        draws=options.draws,
        seed=options.seed,
        confidence=options.confidence,
        withheld=withheld,
    )
    out = [replace(r, interval=iv) for r, iv in zip(results, per_run, strict=True)]
    return out, best, block
