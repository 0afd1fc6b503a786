"""The trajectory intervals (closed forms and band draws, issue 39) against a brute-force
Monte Carlo of the same model: every compared GT pose redrawn with its noise (and, for
``hold``, its frame lag), the statistics recomputed as ``metrics`` computes them, and the
same basic interval taken from the draws (clipped at 0, widened to hold its score).

The model, written out here from its definition (docs/uncertainty.md): the GT pose compared
with robot pose i moves by sigma w_i per axis (w_i = sqrt((1 - a)^2 + a^2) of the linear
interpolation's weight a, 1 for hold) and its yaw by sigma_yaw w_i; with hold by l_i v_i
and l_i omega_i too, l_i uniform over [-1, 0] GT periods, v and omega the GT's velocity and
yaw rate over 5 samples either side. sigma and sigma_yaw are those the scorer measured from
the GT (``jitter``), so both sides draw the same noise. No clock offset source (the
audit has no estimate): its grid is tested in test_trajectory_intervals.py.

Both sides take 20,000 draws: an interval end is a 2.5 % or 97.5 % quantile, known to
sqrt(p (1 - p) / N) / density = 0.019 sd of the statistic's spread per side; the ends are
compared within 5 times the difference's standard error (sqrt 2 of one side's).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from ertools.benchmarks.common.clocks import OffsetEstimate
from ertools.benchmarks.common.interval_output import IntervalSettings
from ertools.benchmarks.trajectory.association import COMPARED, associate
from ertools.benchmarks.trajectory.formula import PERCENTILES, metrics
from ertools.benchmarks.trajectory.intervals import (
    KEYS,
    Rescoring,
    jitter,
    trajectory_intervals,
)
from ertools.geometry import quat_from_yaw, yaw_from_quat
from ertools.streams import PoseStream

pytestmark = pytest.mark.slow  # whole module: make test only

T0 = 1_448_000_000 * 10**9
DRAWS = 20_000
SE_PER_SD = math.sqrt(0.025 * 0.975 / DRAWS) / (math.exp(-0.5 * 1.96**2) / math.sqrt(2 * math.pi))


def _logs(rng: np.random.Generator) -> tuple[PoseStream, PoseStream]:
    """120 Hz GT on a circle (0.4 m/s) with 0.2 mm and 1 mrad of noise; a 10 Hz robot 1 cm
    off (per axis) and a few degrees, 30 s."""
    n = 3600
    t = T0 + np.round(np.arange(n) * 1e9 / 120).astype(np.int64)
    s = np.arange(n) / 120
    w = 0.4 / 1.5
    xyz = np.column_stack([1.5 * np.cos(w * s), 1.5 * np.sin(w * s), 0.3 + 0 * s])
    yaw = w * s + math.pi / 2
    gt = PoseStream(
        t,
        xyz + rng.normal(0.0, 2e-4, xyz.shape),
        quat_from_yaw(yaw + rng.normal(0.0, 1e-3, n)),
        "world",
        "b",
        "gt",
    )
    tr = T0 + np.arange(5, 295) * 100_000_000 + 3_000_000
    sr = (tr - T0) / 1e9
    rxyz = np.column_stack([1.5 * np.cos(w * sr), 1.5 * np.sin(w * sr), 0.3 + 0 * sr])
    rxyz += rng.normal(0.0, 0.01, rxyz.shape)
    ryaw = w * sr + math.pi / 2 + rng.normal(0.0, 0.05, len(sr))
    robot = PoseStream(tr, rxyz, quat_from_yaw(ryaw), "world", "r", "robot")
    return robot, gt


def _brute(robot: PoseStream, gt: PoseStream, method: str) -> dict[str, tuple[float, float]]:
    m = associate(robot, gt, method, 100_000_000)
    ok = m.status == COMPARED
    q = m.t_ns[ok]
    t = gt.t_ns
    k = np.clip(np.searchsorted(t, q, side="right") - 1, 0, len(t) - 2)
    k1 = k + 1
    a = (q - t[k]) / (t[k1] - t[k])
    period = (t[k1] - t[k]) / 1e9
    lo, hi = np.clip(k - 5, 0, len(t) - 1), np.clip(k1 + 5, 0, len(t) - 1)
    span = (t[hi] - t[lo]) / 1e9
    v = (gt.xyz[hi] - gt.xyz[lo]) / span[:, None]
    gy = yaw_from_quat(gt.quat_xyzw)
    omega = np.angle(np.exp(1j * (gy[hi] - gy[lo]))) / span
    sig = jitter(gt)
    w = np.sqrt((1 - a) ** 2 + a**2) if method == "linear" else np.ones(len(q))
    rng = np.random.default_rng(99)
    n = len(q)
    g = m.gt_xyz[ok][None] + (sig.position * w)[None, :, None] * rng.standard_normal((DRAWS, n, 3))
    dyaw = (sig.yaw * w)[None] * rng.standard_normal((DRAWS, n))
    if method == "hold":
        lag = rng.uniform(-1.0, 0.0, (DRAWS, n)) * period
        g = g + lag[..., None] * v
        dyaw = dyaw + lag * omega
    d = np.linalg.norm(robot.xyz[ok][None] - g, axis=-1)
    ryaw = yaw_from_quat(robot.quat_xyzw[ok])
    wrapped = np.abs(np.remainder(ryaw - (m.gt_yaw[ok] + dyaw) + math.pi, 2 * math.pi) - math.pi)
    raw = np.abs(m.yaw_diff_raw[ok] - dyaw)
    pct = np.percentile(d, PERCENTILES, axis=1)
    stats = {
        "position_error": d.mean(axis=1),
        "orientation_error": np.arctan2(np.sin(wrapped).sum(1), np.cos(wrapped).sum(1)),
        "rmse": np.sqrt(np.mean(d * d, axis=1)),
        "median": pct[0],
        "max": d.max(axis=1),
        **{f"percentiles.p{p:g}": pct[i] for i, p in enumerate(PERCENTILES)},
        "orientation_error_2015": np.arctan2(np.sin(raw).sum(1), np.cos(raw).sum(1)),
    }
    est = _estimates(m)
    out = {}
    for key, draws in stats.items():
        q_lo, q_hi = np.quantile(draws, [0.025, 0.975])
        low, high = max(0.0, 2 * est[key] - q_hi), 2 * est[key] - q_lo
        # an interval holds its score (docs/uncertainty.md, "Method"): with hold, the lag's
        # bias can pass the spread and the reflected interval lie wholly below the score
        out[key] = (min(low, est[key]), max(high, est[key]))
    return out


def _estimates(m) -> dict[str, float]:  # type: ignore[no-untyped-def]
    x = metrics(m)
    assert x is not None
    out = {
        "position_error": x.position_error,
        "orientation_error": x.orientation_error,
        "rmse": x.rmse,
        "median": x.median,
        "max": x.max,
        "orientation_error_2015": x.orientation_error_2015,
    }
    out.update({f"percentiles.p{p:g}": v for p, v in x.percentiles})
    return out


@pytest.mark.parametrize("method", ["linear", "hold"])
def test_intervals_equal_the_brute_force_of_their_model(method: str) -> None:
    robot, gt = _logs(np.random.default_rng(1))
    m = associate(robot, gt, method, 100_000_000)
    audit = OffsetEstimate(None, None, 5 * 10**9, 0, None, None, "no estimate here")

    def never(rows: np.ndarray, shift: int):  # type: ignore[no-untyped-def]
        raise AssertionError("no offset source: the grid is not re-scored")

    got = trajectory_intervals(
        robot,
        gt,
        m,
        audit,
        _estimates(m),
        association=method,
        offset_ns=0,
        settings=IntervalSettings(draws=DRAWS, seed=5),
        rescoring=Rescoring(robot.t_ns, never),
    )
    want = _brute(robot, gt, method)
    for key in KEYS:
        iv = got.intervals[key]
        assert iv is not None
        low, high = want[key]
        sd = (high - low) / (2 * 1.96)
        tol = 5 * math.sqrt(2) * SE_PER_SD * sd
        assert iv.low == pytest.approx(low, abs=tol), key
        assert iv.high == pytest.approx(high, abs=tol), key
