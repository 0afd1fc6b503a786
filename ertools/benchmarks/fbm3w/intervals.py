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

Each draw re-runs the whole Eq. (1) on the perturbed positions
(:mod:`~ertools.benchmarks.fbm3w.perturbed`): the d_min subsampling (a
sequential rule: one pass over the samples, each step vectorised over the draws of all the
runs side by side), the run frame from the perturbed reference and start, l/L and the mean
distance. ``best_distance_error`` is the
minimum over the runs of each draw.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import replace
from statistics import NormalDist

import numpy as np
import numpy.typing as npt

from ertools.arrays import F64, IntArr
from ertools.benchmarks.common.epsilon import NoiseResult
from ertools.benchmarks.common.inputs import DEFAULT_C
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
from ertools.benchmarks.fbm3w.perturbed import RunSamples, perturbed_runs
from ertools.benchmarks.fbm3w.result import RunResult
from ertools.benchmarks.fbm3w.settings import Fbm3wConfig
from ertools.frozen_dataclass import frozen_dataclass
from ertools.streams import PoseStream

# The coefficient of variation of a Rayleigh distance, sqrt(4/pi - 1): the spread of one
# consecutive-pair distance around epsilon.
RAYLEIGH_CV = math.sqrt(4.0 / math.pi - 1.0)
DEFAULT_D_MIN_REL = 0.10
METHOD = (
    "Monte Carlo (parametric bootstrap around the smoothed path, basic interval; the shares: "
    "d_min's variance alone at 16 stratified d_mins, the mocap noise's the rest)"
)
# d_mins at which the smoothed paths are scored for d_min's share (run_intervals)
D_MIN_NODES = 16
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


@frozen_dataclass
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

    chosen: list[RunSamples] = [r for i in scored if (r := runs[i]) is not None]
    # Columns that ride along in the draws' d_min pass (sigma 0: the smoothed paths as
    # they are): the smoothed paths' own scores at d_min, from which each draw's shift is
    # added to the score, and at D_MIN_NODES equally likely d_mins (the normal's quantiles
    # at the midpoints of as many equal slices: a stratified draw of d_min's one
    # dimension) for d_min's share, instead of a pass of draws of its own.
    nodes = np.array([NormalDist().inv_cdf((k + 0.5) / D_MIN_NODES) for k in range(D_MIN_NODES)])
    extra_d_mins = np.concatenate(
        [[model.d_min], model.d_min * np.maximum(0.0, 1.0 + model.d_min_rel * nodes)]
    )
    along: dict[str, F64] = {}

    def perturbed(rng: np.random.Generator, sources: frozenset[str], n: int) -> F64:
        z_sigma = rng.standard_normal(n)
        z_dmin = rng.standard_normal(n)
        sigmas = np.full(n, model.sigma)
        if MOCAP_NOISE in sources:
            sigmas = sigmas * np.maximum(0.0, 1.0 + model.sigma_rel * z_sigma)
        d_mins = np.full(n, model.d_min)
        if D_MIN in sources:
            d_mins = model.d_min * np.maximum(0.0, 1.0 + model.d_min_rel * z_dmin)
        raw = perturbed_runs(
            chosen,
            np.concatenate([sigmas, np.zeros(extra_d_mins.size)]),
            np.concatenate([d_mins, extra_d_mins]),
            rng,
            MOCAP_NOISE in sources,
        )
        centers = raw[n]
        shift = np.asarray(est[:-1]) - centers
        shift_best = est[-1] - float(np.min(centers))
        out = np.empty((raw.shape[0], len(scored) + 1))
        # the best run of each draw; NaN when one of its runs could not be scored
        out[:, -1] = np.min(raw, axis=1) + shift_best
        out[:, :-1] = raw + shift
        along["d_min"] = _nanvar(out[n + 1 :])
        return out[:n]

    def d_min_alone() -> F64:
        """The scores' variance with d_min alone perturbed (the stratified d_mins of the
        together pass)."""
        return along["d_min"]

    names = tuple(s.name for s in model.sources)
    # the mocap noise's share: what the together pass's variance leaves over d_min's
    ivs = monte_carlo(
        est,
        perturbed,
        names,
        draws=draws,
        seed=seed,
        confidence=confidence,
        alone_variance={D_MIN: d_min_alone},
    )
    per_run: list[Interval | None] = [None] * len(runs)
    for col, i in enumerate(scored):
        per_run[i] = ivs[col]
    return per_run, ivs[-1]


def _nanvar(values: F64) -> F64:
    """(S,) variance of each column's finite values (0 with fewer than two)."""
    var = np.zeros(values.shape[1])
    finite = np.sum(np.isfinite(values), axis=0) >= 2
    var[finite] = np.nanvar(values[:, finite], axis=0)
    return var


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
