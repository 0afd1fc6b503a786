"""The confidence interval of HGMF's ``Avg distance error``: the distances re-computed from
perturbed positions, all Monte Carlo draws at once ((draws, goals) arrays). No IO.

The final lookups' moments are logged exactly (the script's broadcasts), so the only source
is the mocap's own noise: the object's and the table's marker sets, each measured from its
own track (:mod:`ertools.rsbb.jitter`), added per axis. An interpolated position averages two
samples' noise (a factor sqrt(w^2 + (1 - w)^2) <= 1): taking the full sigma keeps the
interval on the safe side.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from ertools.arrays import F64
from ertools.benchmarks.common.uncertainty import (
    MOCAP_NOISE,
    Interval,
    Source,
    Uncertainty,
    monte_carlo,
)
from ertools.benchmarks.hgmf.config import HgmfOptions
from ertools.benchmarks.hgmf.result import AVERAGE_KEY, HgmfGoal
from ertools.rsbb.jitter import mocap_noise
from ertools.rsbb.tf import TfTrack

METHOD = "Monte Carlo (parametric bootstrap, basic interval)"


def hgmf_intervals(
    bodies: tuple[TfTrack, TfTrack],
    goals: Sequence[HgmfGoal],
    average: float | None,
    counted: int,
    options: HgmfOptions,
) -> tuple[dict[str, Interval | None], Uncertainty | None]:
    """The average's interval (empty without draws or without an average); ``bodies``: the
    object's and the table's marker sets, ``counted``: the average's divisor."""
    measured = [g for g in goals if g.distance_error is not None and g.position is not None]
    if options.draws <= 0 or average is None or not measured or counted <= 0:
        return {}, None
    target = np.array([g.attempt.target for g in measured], dtype=np.float64)
    position = np.array([g.position for g in measured], dtype=np.float64)
    obj, table = mocap_noise(bodies[0]), mocap_noise(bodies[1])
    sigma = math.hypot(obj.sigma_m, table.sigma_m)
    divisor = float(counted)

    def mean_distance(xy: F64) -> F64:
        d = np.hypot(target[:, 0] - xy[..., 0], target[:, 1] - xy[..., 1])
        return np.asarray(np.sum(d, axis=-1) / divisor)[..., None]

    def perturbed(rng: np.random.Generator, sources: frozenset[str], n: int) -> F64:
        del sources  # one source
        return mean_distance(position + rng.normal(0.0, sigma, (n, *position.shape)))

    (iv,) = monte_carlo(
        mean_distance(position),
        perturbed,
        (MOCAP_NOISE,),
        draws=options.draws,
        seed=options.seed,
        confidence=options.confidence,
    )
    note = f"object: {obj.note}; table: {table.note}"
    source = Source(MOCAP_NOISE, sigma, "m", obj.measured and table.measured, note)
    shares = {AVERAGE_KEY: {MOCAP_NOISE: 1.0}} if iv is not None else {}
    block = Uncertainty(options.confidence, METHOD, options.draws, options.seed, (source,), shares)
    return {AVERAGE_KEY: iv}, block
