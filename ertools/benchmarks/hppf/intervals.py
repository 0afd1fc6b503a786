"""Confidence intervals of HPPF's position errors and Distance error (docs/uncertainty.md).

The ground truth is one tf lookup of the cap's marker set after each answer. Its mocap noise
is measured from its own track (:func:`ertools.rsbb.jitter.mocap_noise`: robust second
differences). A draw moves each ground truth by that noise and re-computes the position
errors (:func:`ertools.benchmarks.hppf.formula.position_errors`, vectorised over the draws)
and the Distance error. The names and the execution time carry no measurement noise.
"""

from __future__ import annotations

import math

import numpy as np

from ertools.arrays import F64
from ertools.benchmarks.common.interval_output import METHOD, NO_INTERVALS, ResultIntervals
from ertools.benchmarks.common.uncertainty import MOCAP_NOISE, Source, Uncertainty, monte_carlo
from ertools.benchmarks.hppf.config import HppfOptions
from ertools.benchmarks.hppf.formula import position_errors
from ertools.benchmarks.hppf.goals import Scored
from ertools.benchmarks.hppf.result import DISTANCE_KEY, goal_key
from ertools.rsbb.jitter import DEFAULT_SIGMA_M, mocap_noise
from ertools.rsbb.tf import TfTrack


def _sigma(actor: TfTrack | None) -> tuple[float, Source]:
    if actor is None:
        return DEFAULT_SIGMA_M, Source(MOCAP_NOISE, DEFAULT_SIGMA_M, "m", False, "no track")
    noise = mocap_noise(actor)
    return noise.sigma_m, Source(MOCAP_NOISE, noise.sigma_m, "m", noise.measured, noise.note)


def hppf_intervals(actor: TfTrack | None, scored: Scored, options: HppfOptions) -> ResultIntervals:
    """The intervals of each position error and of the Distance error (none with
    ``--draws 0`` or no position error)."""
    rows = [
        p
        for p in scored.passes
        if p.position_error is not None
        and p.truth is not None
        and p.truth.xy is not None
        and p.answer is not None
        and p.answer.xy is not None
    ]
    if options.draws <= 0 or not rows:
        return NO_INTERVALS
    sigma, source = _sigma(actor)
    truth = np.array([p.truth.xy for p in rows if p.truth is not None], np.float64)
    answer = np.array([p.answer.xy for p in rows if p.answer is not None], np.float64)
    total = scored.score.get(DISTANCE_KEY)
    has_total = isinstance(total, int | float)
    n = len(rows)

    def perturbed(rng: np.random.Generator, sources: frozenset[str], draws: int) -> F64:
        out = np.empty((draws, n + 1))
        moved = truth + (rng.normal(0.0, sigma, (draws, n, 2)) if MOCAP_NOISE in sources else 0.0)
        errs = position_errors(
            np.broadcast_to(answer, (draws, n, 2)).reshape(-1, 2),
            np.broadcast_to(moved, (draws, n, 2)).reshape(-1, 2),
        ).reshape(draws, n)
        out[:, :n] = errs
        out[:, n] = np.cumsum(errs, axis=1)[:, -1] / n if has_total else np.nan
        return out

    est = [float(p.position_error) for p in rows if p.position_error is not None]
    est.append(float(total) if has_total and isinstance(total, int | float) else math.nan)
    ivs = monte_carlo(
        est,
        perturbed,
        (MOCAP_NOISE,),
        draws=options.draws,
        seed=options.seed,
        confidence=options.confidence,
    )
    shares = {f"goal_{p.index}.position_error": {MOCAP_NOISE: 1.0} for p in rows}
    shares[DISTANCE_KEY] = {MOCAP_NOISE: 1.0}
    uncertainty = Uncertainty(
        options.confidence, METHOD, options.draws, options.seed, (source,), shares
    )
    by_goal = {goal_key(p.index): ivs[k] for k, p in enumerate(rows)}
    return ResultIntervals({DISTANCE_KEY: ivs[n], **by_goal}, uncertainty)
