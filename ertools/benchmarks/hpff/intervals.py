"""Confidence intervals of HPFF's average deviation and distance covered: the samples
re-computed from perturbed mocap positions, all Monte Carlo draws at once. No IO.

The only source is the mocap's noise (``mocap_noise``), measured from each body's own track
(:mod:`ertools.rsbb.jitter`): the robot's and the cap's positions perturbed per axis (the
robot's sigma includes its marker set's yaw noise on the team transform's lever arm, folded in
as a position sigma). The distance covered sums small steps, so noise biases it upwards; the
basic interval removes the bias the draws show.
"""

from __future__ import annotations

import numpy as np

from ertools.arrays import F64
from ertools.benchmarks.common.uncertainty import (
    MOCAP_NOISE,
    Interval,
    Source,
    Uncertainty,
    monte_carlo,
)
from ertools.benchmarks.hpff.config import HpffOptions
from ertools.benchmarks.hpff.logs import HpffLogs
from ertools.benchmarks.hpff.result import COVERED_KEY, DEVIATION_KEY, HpffSamples
from ertools.rsbb.jitter import mocap_noise

METHOD = "Monte Carlo (parametric bootstrap, basic interval)"


def hpff_intervals(
    logs: HpffLogs, samples: HpffSamples, options: HpffOptions
) -> tuple[dict[str, Interval | None], Uncertainty | None]:
    """The intervals (empty without draws or without a measured sample)."""
    measured = samples.measured
    if options.draws <= 0 or not measured.any():
        return {}, None
    p = logs.params
    desired = float(p["desired_following_distance"])
    lo, hi = float(p["min_following_distance"]), float(p["max_following_distance"])
    robot_noise, person_noise = mocap_noise(logs.robot), mocap_noise(logs.person)
    lever = float(np.hypot(logs.transform[0][0], logs.transform[0][1]))
    sigma_robot = float(np.hypot(robot_noise.sigma_m, robot_noise.sigma_rad * lever))
    sigma = float(np.hypot(sigma_robot, person_noise.sigma_m))
    distance = np.nan_to_num(samples.distance)
    robot = np.nan_to_num(samples.robot_xy)
    ok = samples.robot_ok
    previous = np.concatenate([[False], ok[:-1]])
    k = len(distance)

    def scores(d: F64, xy: F64) -> F64:
        dev = np.sum(np.where(measured, np.abs(d - desired), 0.0), axis=-1) / measured.sum()
        step = np.zeros(d.shape)
        delta = xy[..., 1:, :] - xy[..., :-1, :]
        step[..., 1:] = np.sqrt(np.sum(delta**2, axis=-1))
        counted = measured & (d >= lo) & (d <= hi) & ok & previous
        return np.stack([dev, np.sum(np.where(counted, step, 0.0), axis=-1)], axis=-1)

    def perturbed(rng: np.random.Generator, sources: frozenset[str], n: int) -> F64:
        del sources  # one source
        d = distance + rng.normal(0.0, sigma, (n, k))
        xy = robot + rng.normal(0.0, sigma_robot, (n, k, 2))
        return scores(d, xy)

    estimate = scores(distance, robot)
    ivs = monte_carlo(
        estimate,
        perturbed,
        (MOCAP_NOISE,),
        draws=options.draws,
        seed=options.seed,
        confidence=options.confidence,
    )
    measured_both = robot_noise.measured and person_noise.measured
    note = f"robot {robot_noise.note}; person {person_noise.note}"
    source = Source(MOCAP_NOISE, sigma, "m", measured_both, note)
    keys = (DEVIATION_KEY, COVERED_KEY)
    shares = {key: {MOCAP_NOISE: 1.0} for key, iv in zip(keys, ivs, strict=True) if iv is not None}
    block = Uncertainty(options.confidence, METHOD, options.draws, options.seed, (source,), shares)
    return dict(zip(keys, ivs, strict=True)), block
