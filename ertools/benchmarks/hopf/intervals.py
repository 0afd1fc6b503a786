"""Confidence intervals of HOPF's pose scores (docs/uncertainty.md, issue 28).

The ground truth is one tf lookup: the table and the positioner, one interpolated sample each.
Their mocap noise is measured around the lookups (the bodies stand still while the robot
looks): per body, the scatter of successive samples' x, y and yaw within
:data:`WINDOW_NS` of each lookup (pairs less than :data:`PAIR_NS` apart), sigma = 1.4826
MAD(difference) / sqrt(2) (a difference cancels a slow drift; the median absolute deviation
ignores the jump when the positioner is moved). A draw moves both bodies by that noise and re-computes the item's pose in the table
frame to first order (the positioner's and the table's positions, and their yaws turning the
item's offset and the item's position about the table's origin), then every pose score and
the total, with :func:`ertools.benchmarks.hopf.formula.pose_terms` vectorised over the draws.
The class and instance accuracies and the execution time carry no measurement noise.
"""

from __future__ import annotations

import math

import numpy as np

from ertools.arrays import F64
from ertools.benchmarks.common.interval_output import METHOD
from ertools.benchmarks.common.uncertainty import (
    MIN_INTERVAL_SAMPLES,
    MOCAP_NOISE,
    Source,
    Uncertainty,
    monte_carlo,
)
from ertools.benchmarks.hopf.config import CLIP_TRANSLATION_M, HopfOptions
from ertools.benchmarks.hopf.formula import pose_terms
from ertools.benchmarks.hopf.goals import Scored
from ertools.benchmarks.hopf.result import HopfIntervals
from ertools.rsbb.tf import TfTrack, euler_yaw

#: The samples around each lookup the noise is measured on.
WINDOW_NS = 1_000_000_000
PAIR_NS = 50_000_000
#: Where too few samples are around the lookups: one sample of a still marker set (0.3 mm per
#: axis, 0.05 deg), as ertools states for the 2015 mocap (fbm1's default).
DEFAULT_SIGMA_M = 3e-4
DEFAULT_SIGMA_RAD = math.radians(0.05)


def _scatter(track: TfTrack | None, moments: list[int]) -> tuple[F64, F64]:
    """Successive differences of (x, y) and of yaw over the windows around ``moments``."""
    if track is None or not moments:
        return np.empty((0, 2)), np.empty(0)
    dxy, dyaw = [], []
    for t in moments:
        lo = np.searchsorted(track.t_ns, t - WINDOW_NS, side="left")
        hi = np.searchsorted(track.t_ns, t + WINDOW_NS, side="right")
        if hi - lo < 2:
            continue
        close = np.diff(track.t_ns[lo:hi]) < PAIR_NS
        yaw = np.unwrap(euler_yaw(track.quat_xyzw[lo:hi]))
        dxy.append(np.diff(track.xyz[lo:hi, :2], axis=0)[close])
        dyaw.append(np.diff(yaw)[close])
    if not dxy:
        return np.empty((0, 2)), np.empty(0)
    return np.concatenate(dxy), np.concatenate(dyaw)


def _sigma(bodies: tuple[TfTrack | None, ...], moments: list[int]) -> tuple[float, float, Source]:
    """Per-body sigma of a position axis and of yaw, and the source as reported."""
    pairs_xy, pairs_yaw = [], []
    for track in bodies:
        dxy, dyaw = _scatter(track, moments)
        pairs_xy.append(dxy)
        pairs_yaw.append(dyaw)
    dxy = np.concatenate(pairs_xy)
    dyaw = np.concatenate(pairs_yaw)
    if dyaw.size < MIN_INTERVAL_SAMPLES:
        note = (
            f"only {dyaw.size} successive samples around the lookups: a still marker set's "
            "stated noise"
        )
        return (
            DEFAULT_SIGMA_M,
            DEFAULT_SIGMA_RAD,
            Source(MOCAP_NOISE, DEFAULT_SIGMA_M, "m", False, note),
        )
    s_m = robust_sigma(dxy.ravel())
    s_rad = robust_sigma(dyaw)
    note = (
        f"table and positioner, {dyaw.size} successive samples within "
        f"{WINDOW_NS / 1e9:g} s of the lookups; yaw sigma {s_rad:.3g} rad"
    )
    return s_m, s_rad, Source(MOCAP_NOISE, s_m, "m", True, note)


def robust_sigma(differences: F64) -> float:
    """The noise of samples whose successive ``differences`` are given: 1.4826 times their
    median absolute deviation (a normal's sigma), over sqrt(2) (a difference of two)."""
    d = np.asarray(differences, np.float64)
    mad = float(np.median(np.abs(d - np.median(d))))
    return 1.4826 * mad / math.sqrt(2.0)


def hopf_intervals(
    bodies: tuple[TfTrack | None, ...], scored: Scored, options: HopfOptions
) -> HopfIntervals | None:
    """The intervals of each scored goal's pose score and of the total (None with
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
        return None
    moments = [
        g.truth.moment_ns for g in goals if g.truth is not None and g.truth.moment_ns is not None
    ]
    s_m, s_rad, source = _sigma(bodies, moments)
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
            d_pos = rng.normal(0.0, s_m, (draws, n, 2)) - rng.normal(0.0, s_m, (draws, n, 2))
            d_pos_yaw = rng.normal(0.0, s_rad, (draws, n))
            d_tab_yaw = rng.normal(0.0, s_rad, (draws, n))
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
    return HopfIntervals(ivs[n], {g.index: ivs[k] for k, g in enumerate(goals)}, uncertainty)
