"""The offset's effect from the GT's motion (steady.py) against the comparison re-scored by
the association itself at every shift, on a noiseless GT where the two must agree; and the
check that sends a comparison near a loss to the re-scoring."""

from __future__ import annotations

import math
from types import SimpleNamespace
from typing import Any

import numpy as np
import pytest

from ertools.benchmarks.common.clocks import OffsetEstimate
from ertools.benchmarks.trajectory import spread
from ertools.benchmarks.trajectory.association import COMPARED, associate
from ertools.benchmarks.trajectory.intervals import (
    KEYS,
    MEAN_LIKE,
    ORDER_STATS,
    Rescoring,
    offset_effects,
)
from ertools.benchmarks.trajectory.spread import offset_spread
from ertools.benchmarks.trajectory.steady import clear_of_losses, effects
from ertools.benchmarks.trajectory.terms import PoseTerms
from ertools.geometry import quat_from_yaw, wrap_angle
from ertools.streams import PoseStream

T0 = 1_448_000_000 * 10**9
W = 2 * math.pi / 25  # one lap of the ellipse in 25 s


def _gt(seconds: float) -> PoseStream:
    k = np.arange(round(seconds * 120))
    t = T0 + np.round(k * 1e9 / 120).astype(np.int64)
    s = k / 120.0
    xyz = np.column_stack([1.6 * np.cos(W * s), np.sin(W * s), 0.4 + 0 * s])
    yaw = np.arctan2(np.cos(W * s), -1.6 * np.sin(W * s))
    return PoseStream(t, xyz, quat_from_yaw(yaw), "world", "b", "gt")


def _robot(n: int, rng: np.random.Generator) -> PoseStream:
    """10 Hz from 1 s, off the ellipse by 1-3 cm and 1-3 degrees."""
    s = 1.0 + np.arange(n) * 0.1 + rng.uniform(0, 0.002, n)
    t = T0 + np.round(s * 1e9).astype(np.int64)
    xyz = np.column_stack([1.6 * np.cos(W * s), np.sin(W * s), 0.4 + 0 * s])
    xyz += rng.normal(0.0, 0.015, xyz.shape)
    yaw = np.arctan2(np.cos(W * s), -1.6 * np.sin(W * s)) + rng.normal(0.0, 0.03, n)
    return PoseStream(t, xyz, quat_from_yaw(yaw), "world", "r", "r")


def _velocity(gt: PoseStream, q: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The GT's exact velocity and yaw rate on the ellipse at the robot times, by hand."""
    s = (q - T0) / 1e9
    vel = np.column_stack([-1.6 * W * np.sin(W * s), W * np.cos(W * s), 0 * s])
    # yaw = atan2(cos, -1.6 sin): d/ds = W * 1.6 / (1.6^2 sin^2 + cos^2)
    rate = W * 1.6 / (2.56 * np.sin(W * s) ** 2 + np.cos(W * s) ** 2)
    return vel, rate, s


def _reassociated(robot: PoseStream, gt: PoseStream, shifts: np.ndarray) -> np.ndarray:
    """The offset's effects as the association gives them: every pose paired again at each
    shift (the independent figure the motion's series is checked against)."""

    def rescore(rows: np.ndarray, shift_ns: int):  # type: ignore[no-untyped-def]
        part = robot.take(rows)
        moved = PoseStream(part.t_ns + shift_ns, part.xyz, part.quat_xyzw, "w", "r", "r")
        return associate(moved, gt, "linear", 100_000_000)

    return offset_effects(Rescoring(robot.t_ns, rescore), gt.t_ns, shifts)


def _associated_terms(robot: PoseStream, gt: PoseStream, m: Any) -> SimpleNamespace:
    """The per-pose terms `effects` reads, from the association ``m`` of ``robot`` with the
    noiseless ``gt`` and the GT's exact motion at the robot's stamps."""
    vel, rate, _ = _velocity(gt, m.t_ns)
    return SimpleNamespace(
        error=robot.xyz - m.gt_xyz,
        velocity=vel,
        yaw_rate=rate,
        theta=wrap_angle(robot.yaw - m.gt_yaw),
        raw=m.yaw_diff_raw,
        norms=lambda: np.linalg.norm(robot.xyz - m.gt_xyz, axis=1),
    )


def test_the_motion_gives_the_association_s_own_effects() -> None:
    rng = np.random.default_rng(4)
    gt = _gt(40.0)
    robot = _robot(380, rng)
    m = associate(robot, gt, "linear", 100_000_000)
    assert np.all(m.status == COMPARED)
    poses = _associated_terms(robot, gt, m)
    shifts = np.linspace(-4, 4, 41) * 0.003  # +-12 ms, under two GT frames either side
    got = effects(poses, np.arange(len(robot)), shifts, ORDER_STATS, len(KEYS), MEAN_LIKE)
    assert got is not None

    want = _reassociated(robot, gt, shifts)
    # The association interpolates the noiseless GT linearly between frames 8.3 ms apart:
    # its point lies off the ellipse by at most the sagitta (1.6 m (W / 120)^2 / 8 = 0.1 um)
    # and moves along a chord, whose direction differs from the tangent by W / 240 = 1 mrad,
    # so each distance's change (up to |v| 12 ms = 4.8 mm) agrees to ~5 um per pose, and
    # the means over 380 poses (changes of 20-200 um at the grid's ends) to ~1 um.
    for key in ("position_error", "rmse", "max", "median", "percentiles.p90"):
        j = KEYS.index(key)
        assert got[:, j] == pytest.approx(want[:, j], abs=5e-6), key
    # the yaw: the slerp between frames turns at the frame's mean rate, within 1e-5 of the
    # exact rate over 8 ms (the rate's relative change over a frame, W / 120 ~ 2e-3)
    for key in ("orientation_error", "orientation_error_2015"):
        j = KEYS.index(key)
        assert got[:, j] == pytest.approx(want[:, j], abs=2e-7), key
    # and the effects are not all nought: the test would pass on a constant otherwise
    assert np.max(np.abs(want[:, KEYS.index("position_error")])) > 2e-5


def test_a_loss_within_reach_sends_the_comparison_to_the_association() -> None:
    rng = np.random.default_rng(5)
    gt = _gt(40.0)
    robot = _robot(380, rng)
    m = associate(robot, gt, "linear", 100_000_000)
    k = np.searchsorted(gt.t_ns, m.t_ns, side="right") - 1
    args = (m.t_ns, m.status, m.t_ns, gt.t_ns)
    assert clear_of_losses(*args, gt.xyz, k, 3_000_000, 100_000_000)
    # tracking lost on the pair after pose 100's (its frames k+1 and k+2 alike): a shift
    # of 3 ms may not reach it, but the check keeps to whole frames either side
    frame = int(k[100]) + 1
    xyz = gt.xyz.copy()
    xyz[frame + 1] = xyz[frame]
    assert not clear_of_losses(*args, xyz, k, 3_000_000, 100_000_000)
    # a gap: the frames further apart than the largest span the association compares
    assert not clear_of_losses(*args, gt.xyz, k, 3_000_000, 8_000_000)
    # a reach of more than one frame either side: no longer one crossing
    assert not clear_of_losses(*args, gt.xyz, k, 20_000_000, 100_000_000)
    # a robot pose not compared, inside the GT
    status = m.status.copy()
    status[7] = 2
    assert not clear_of_losses(m.t_ns, status, m.t_ns, gt.t_ns, gt.xyz, k, 3_000_000, 10**8)


def test_closed_forms_of_a_long_comparison_from_spread_poses() -> None:
    """20,000 poses, yaw errors of 20 mrad (a third near the fold of sin|x|, for 0.5-1 mrad
    of yaw noise), the closed forms' draws with the yaw's terms from the poses near the
    fold and 4,000 of the others against those from every pose. Both are the same formulas
    (tests/benchmarks/common/test_closed_forms.py checks them against brute force); the
    spread poses add the sampling error of sums of slowly varying terms: their bias is
    |sin x| s^2 / 2 (1e-8 here, against an sd of 5e-6), their variances s^2 cos^2 x within
    a factor 4, so the sd to ~1 %: within 2 % of the sd. The distances use every pose."""
    rng = np.random.default_rng(8)
    n = 20_000
    err = rng.normal(0.0, 0.012, (n, 3)) + 0.002
    theta = rng.normal(0.0, 0.02, n)
    raw = theta + np.where(rng.uniform(size=n) < 0.01, 2 * math.pi, 0.0)
    terms = PoseTerms(
        error=err,
        theta=theta,
        raw=raw,
        sigma=rng.uniform(2e-4, 3e-4, n),
        sigma_yaw=rng.uniform(5e-4, 1e-3, n),
        velocity=np.zeros((n, 3)),
        yaw_rate=np.zeros(n),
        period=np.full(n, 1 / 120),
        lag=None,
    )
    full = (
        math.atan2(np.sum(np.abs(np.sin(theta))), np.sum(np.cos(theta))),
        math.atan2(np.sum(np.sin(np.abs(raw))), np.sum(np.cos(raw))),
    )
    z = np.array([-1.96, -1.0, 0.0, 1.0, 1.96])
    want = [f(z) for f in terms.mean_like(True, False)]
    got = [f(z) for f in terms.thinned_mean_like(True, False, full, 4000)]
    for w, g in zip(want, got, strict=True):
        sd = (w[3] - w[1]) / 2
        assert sd > 0
        assert g == pytest.approx(w, abs=0.02 * sd)
    # a comparison within the count: the closed forms of every pose, the same bits
    same = [f(z) for f in terms.thinned_mean_like(True, False, full, n)]
    assert all(np.array_equal(a, b) for a, b in zip(same, want, strict=True))


def test_the_offset_s_spread_of_a_long_log_in_blocks(monkeypatch: pytest.MonkeyPatch) -> None:
    """30,000 poses at 10 Hz on the ellipse, errors of a bias, a 13 s drift and white noise
    (the calibration's error model): the spread from blocks of 4 against every lag's. The
    blocks hold the velocity constant over 0.4 s (it turns by W 0.4 = 0.1 rad: ~0.2 % on
    c(h)) and count each lag between multiples of 4 as the multiple's; 3 % allows for the
    estimator's own scatter between the lags kept and dropped (1 % seen over seeds)."""
    rng = np.random.default_rng(9)
    n = 30_000
    s = np.arange(n) * 0.1
    vel = np.column_stack([-1.6 * W * np.sin(W * s), W * np.cos(W * s), 0 * s])
    step = math.exp(-0.1 / 13)
    shocks = rng.normal(0.0, 0.02 * math.sqrt(1 - step * step), (n, 3))
    drift = np.zeros((n, 3))
    for i in range(1, n):
        drift[i] = step * drift[i - 1] + shocks[i]
    err = 0.01 + drift + rng.normal(0.0, 0.01, (n, 3))
    audit = OffsetEstimate(0, 1_000_000, 5 * 10**9, n, 0.01, 0.02)
    blocks = offset_spread(err, 0 * err, vel, audit, 0)[0]
    monkeypatch.setattr(spread, "MAX_BLOCKS", n)
    every = offset_spread(err, 0 * err, vel, audit, 0)[0]
    assert blocks == pytest.approx(every, rel=0.03)
    assert blocks != every


def test_the_series_for_a_small_reach_against_the_association() -> None:
    """The hour's case: an offset sd of 0.3 ms, the grid's reach 1.2 ms, under which most
    poses' distances (1-5 cm, reach |v| <= 0.6 mm) take the series of sqrt(1 + x) and most
    yaw differences the series of sin and cos; against the association re-scoring every
    pose. The GT's point moves along the chord between two frames, whose direction differs
    from the tangent by up to half a frame's turn (1.6 W / 240 = 1.7 mrad): each pose's
    change (up to |v| 1.2 ms = 0.6 mm) agrees to ~1 um, their mean over 380 poses of
    either sign to ~50 nm, against changes of 10 um; the yaw's: the slerp turns at the
    frame's mean rate, off the exact rate at the pose by up to its change over half a frame
    (0.1 rad/s^2 x 4 ms), 5e-7 rad per pose over 1.2 ms, ~5e-8 rad in the mean, against
    changes of 30 urad."""
    rng = np.random.default_rng(6)
    gt = _gt(40.0)
    robot = _robot(380, rng)
    m = associate(robot, gt, "linear", 100_000_000)
    poses = _associated_terms(robot, gt, m)
    shifts = np.linspace(-4, 4, 41) * 0.0003
    d = np.sqrt(np.sum((robot.xyz - m.gt_xyz) ** 2, axis=1))
    reach = 0.0012 * np.sqrt(np.sum(poses.velocity**2, axis=1))
    assert np.mean(d > 10 * reach) > 0.5  # the series, not the exact path, for most poses
    got = effects(poses, np.arange(len(robot)), shifts, ORDER_STATS, len(KEYS), MEAN_LIKE)
    assert got is not None

    want = _reassociated(robot, gt, shifts)
    # the means to 50 nm; the max and the median follow one or two poses: to 1 um
    for key, tol in (("position_error", 5e-8), ("rmse", 5e-8), ("max", 1e-6), ("median", 1e-6)):
        j = KEYS.index(key)
        assert got[:, j] == pytest.approx(want[:, j], abs=tol), key
        assert np.max(np.abs(want[:, j])) > 1e-6, key  # changes of micrometres
    for key in ("orientation_error", "orientation_error_2015"):
        j = KEYS.index(key)
        assert got[:, j] == pytest.approx(want[:, j], abs=5e-8), key
        assert np.max(np.abs(want[:, j])) > 1e-5, key
