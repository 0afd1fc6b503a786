"""Confidence intervals of HOPF's pose scores (docs/uncertainty.md, issue 28).

The ground truth is one tf lookup: the table and the positioner, one interpolated sample each.
Each body's mocap noise is measured from its own track (:func:`ertools.rsbb.jitter.mocap_noise`:
robust second differences). A draw moves both bodies by that noise and re-computes the item's
pose in the table frame to first order (the positioner's and the table's positions, and their
yaws turning the item's offset and the item's position about the table's origin), then every
pose score and the total, with :func:`ertools.benchmarks.hopf.formula.pose_terms` vectorised
over the draws. The class and instance accuracies and the execution time carry no
measurement noise.
"""

from __future__ import annotations

import math

import numpy as np

from ertools.arrays import F64
from ertools.benchmarks.common.interval_output import METHOD, NO_INTERVALS, ResultIntervals
from ertools.benchmarks.common.uncertainty import MOCAP_NOISE, Source, Uncertainty, monte_carlo
from ertools.benchmarks.hopf.config import CLIP_TRANSLATION_M, HopfOptions
from ertools.benchmarks.hopf.formula import pose_terms
from ertools.benchmarks.hopf.goals import Scored
from ertools.benchmarks.hopf.result import TOTAL_KEY, goal_key
from ertools.rsbb.jitter import DEFAULT_SIGMA_M, DEFAULT_SIGMA_RAD, MocapNoise, mocap_noise
from ertools.rsbb.tf import TfTrack, euler_yaw


def _noise(bodies: tuple[TfTrack | None, ...]) -> tuple[list[MocapNoise], Source]:
    """Each body's noise (a stated default for a body not in the log) and the source."""
    noises = [
        mocap_noise(b)
        if b is not None
        else MocapNoise(DEFAULT_SIGMA_M, DEFAULT_SIGMA_RAD, False, "no track: defaults")
        for b in bodies
    ]
    rms = math.sqrt(sum(n.sigma_m**2 for n in noises) / len(noises))
    note = (
        "; ".join(n.note for n in noises)
        + "; yaw sigma "
        + ", ".join(f"{n.sigma_rad:.3g}" for n in noises)
        + " rad"
    )
    return noises, Source(MOCAP_NOISE, rms, "m", all(n.measured for n in noises), note)


def hopf_intervals(
    bodies: tuple[TfTrack | None, ...], scored: Scored, options: HopfOptions
) -> ResultIntervals:
    """The intervals of each scored goal's pose score and of the total (none with
    ``--draws 0`` or no scored goal); ``bodies``: the table's and the positioner's tracks."""
    goals = [
        g
        for g in scored.goals
        if g.terms is not None
        and g.answer is not None
        and g.answer.pose is not None
        and g.truth is not None
        and g.truth.pose is not None
    ]
    if options.draws <= 0 or not goals:
        return NO_INTERVALS
    (table, positioner), source = _noise(bodies)
    answer = np.array(
        [g.answer.pose for g in goals if g.answer is not None and g.answer.pose is not None]
    )
    truth = np.array(
        [g.truth.pose for g in goals if g.truth is not None and g.truth.pose is not None]
    )
    # the item's offset from the positioner in the table frame, and its distance from the table
    offset = []
    for g in goals:
        assert g.item is not None and g.truth is not None and g.truth.pose is not None
        item_yaw = float(euler_yaw(np.asarray(g.item.rot, np.float64)))
        heading = g.truth.pose[2] - item_yaw
        c, s = math.cos(heading), math.sin(heading)
        tx, ty = g.item.trans[0], g.item.trans[1]
        offset.append((c * tx - s * ty, s * tx + c * ty))
    u = np.asarray(offset, np.float64)
    p = truth[:, :2]
    clip = CLIP_TRANSLATION_M if options.clip_translation else None
    in_total = np.array([g.counted for g in goals], bool)
    total = scored.score.get("pose_score")
    has_total = isinstance(total, int | float) and scored.divisor > 0
    n = len(goals)

    def perturbed(rng: np.random.Generator, sources: frozenset[str], draws: int) -> F64:
        out = np.empty((draws, n + 1))
        if MOCAP_NOISE not in sources:
            est = np.array([g.terms[5] for g in goals if g.terms is not None])
            out[:, :n] = est
        else:
            d_pos = rng.normal(0.0, positioner.sigma_m, (draws, n, 2)) - rng.normal(
                0.0, table.sigma_m, (draws, n, 2)
            )
            d_pos_yaw = rng.normal(0.0, positioner.sigma_rad, (draws, n))
            d_tab_yaw = rng.normal(0.0, table.sigma_rad, (draws, n))
            turn_u = np.stack([-u[:, 1], u[:, 0]], axis=-1)
            turn_p = np.stack([-p[:, 1], p[:, 0]], axis=-1)
            xy = p + d_pos + d_pos_yaw[..., None] * turn_u - d_tab_yaw[..., None] * turn_p
            theta = truth[:, 2] + d_pos_yaw - d_tab_yaw
            moved = np.concatenate([xy, theta[..., None]], axis=-1)
            terms = pose_terms(
                np.broadcast_to(answer, moved.shape).reshape(-1, 3),
                moved.reshape(-1, 3),
                single_wrap=options.single_wrap,
                clip=clip,
            )
            out[:, :n] = terms.pose_score.reshape(draws, n)
        sums = np.cumsum(np.where(in_total, out[:, :n], 0.0), axis=1)[:, -1]
        out[:, n] = sums / scored.divisor if has_total else np.nan
        return out

    est = [g.terms[5] for g in goals if g.terms is not None] + [
        float(total) if has_total and isinstance(total, int | float) else math.nan
    ]
    ivs = monte_carlo(
        est,
        perturbed,
        (MOCAP_NOISE,),
        draws=options.draws,
        seed=options.seed,
        confidence=options.confidence,
        nonnegative=False,
    )
    shares = {f"goal_{g.index}.partial_score.pose_score": {MOCAP_NOISE: 1.0} for g in goals}
    shares["pose_score"] = {MOCAP_NOISE: 1.0}
    uncertainty = Uncertainty(
        options.confidence, METHOD, options.draws, options.seed, (source,), shares
    )
    by_goal = {goal_key(g.index): ivs[k] for k, g in enumerate(goals)}
    return ResultIntervals({TOTAL_KEY: ivs[n], **by_goal}, uncertainty)
