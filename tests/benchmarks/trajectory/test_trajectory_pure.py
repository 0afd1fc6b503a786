"""Association, metrics and the clock-offset estimate on hand-made arrays."""

from __future__ import annotations

import math

import numpy as np
import pytest

from ertools.benchmarks.common import clocks as clock_offset
from ertools.benchmarks.common.clock_queries import around_window
from ertools.benchmarks.common.clocks import (
    GRID_NS,
    MIN_POSES,
    _coarse_scan,
    estimate_offset,
)
from ertools.benchmarks.common.hygiene import drop_duplicates, drop_invalid
from ertools.benchmarks.trajectory.association import (
    COMPARED,
    GAP,
    TRACKING_LOST,
    UNCOVERED,
    associate,
)
from ertools.benchmarks.trajectory.comparison import check_increasing, score_streams
from ertools.benchmarks.trajectory.config import TrajectoryConfig
from ertools.benchmarks.trajectory.formula import metrics
from ertools.errors import ClockError, ConfigError, ScoringError
from ertools.geometry import quat_from_yaw
from ertools.streams import PoseStream

MS = 1_000_000
T0 = 1_448_013_600 * 1_000_000_000


def stream(t_ms: list[float], x: list[float], yaw: list[float] | None = None) -> PoseStream:
    t = T0 + np.round(np.asarray(t_ms) * MS).astype(np.int64)
    xyz = np.column_stack([x, np.zeros(len(x)), np.zeros(len(x))])
    yaws = np.zeros(len(x)) if yaw is None else np.asarray(yaw)
    return PoseStream(t, xyz, quat_from_yaw(yaws))


GT = stream([0, 100, 200, 300], [0.0, 1.0, 2.0, 3.0])


@pytest.mark.parametrize(
    ("method", "at_50", "at_160"),
    [
        ("hold", 0.0, 1.0),  # the last GT pose at or before
        ("nearest", 0.0, 2.0),  # 50 ms is halfway: the earlier one wins the tie
        ("linear", 0.5, 1.6),
    ],
)
def test_association_modes_by_hand(method: str, at_50: float, at_160: float) -> None:
    robot = stream([50, 160], [0.0, 0.0])
    m = associate(robot, GT, method, 100 * MS)  # type: ignore[arg-type]
    assert m.status.tolist() == [COMPARED, COMPARED]
    assert m.gt_xyz[:, 0] == pytest.approx([at_50, at_160], abs=1e-12)
    assert m.position_error == pytest.approx([at_50, at_160], abs=1e-12)


def test_gap_tracking_lost_and_uncovered() -> None:
    # GT: a repeat (tracking lost) between 100 and 200 ms, then 300 ms of nothing.
    gt = stream([0, 100, 200, 500, 600], [0.0, 1.0, 1.0, 4.0, 5.0])
    robot = stream([-10, 50, 150, 200, 350, 550, 610], [0.0] * 7)
    m = associate(robot, gt, "linear", 100 * MS)
    assert m.status.tolist() == [
        UNCOVERED,  # before the first GT pose
        COMPARED,
        TRACKING_LOST,  # between two identical GT poses
        TRACKING_LOST,  # exactly on the repeat: its pair (100, 200) is identical
        GAP,  # GT poses around it are 300 ms apart > 100 ms
        COMPARED,
        UNCOVERED,  # after the last
    ]
    assert m.position_error[5] == pytest.approx(4.5, abs=1e-12)
    assert np.isnan(m.position_error[2])


def test_max_gap_is_inclusive() -> None:
    # Two GT poses exactly max_gap apart still bracket a comparable robot pose.
    m = associate(stream([50], [0.0]), GT, "linear", 100 * MS)
    assert m.status.tolist() == [COMPARED]
    m = associate(stream([50], [0.0]), GT, "linear", 100 * MS - 1)
    assert m.status.tolist() == [GAP]


def test_orientation_error_wraps_the_yaw_difference() -> None:
    # Robot yaw 3.1, GT yaw -3.1: 0.0832 rad apart across +-pi, not 6.2.
    gt = stream([0, 100], [0.0, 0.001], [-3.1, -3.1])
    robot = stream([50, 60], [0.0, 0.0], [3.1, 3.1])
    m = metrics(associate(robot, gt, "hold", 100 * MS))
    assert m is not None
    expected = 2 * math.pi - 6.2
    assert m.orientation_error == pytest.approx(expected, abs=1e-9)
    # 2015: sin|6.2| < 0, so atan2 lands at -expected (it did not wrap).
    assert m.orientation_error_2015 == pytest.approx(-expected, abs=1e-9)


def test_metrics_by_hand() -> None:
    # Position errors 0.5, 0.4 (linear): mean 0.45, rmse sqrt((0.25+0.16)/2), max 0.5.
    robot = stream([50, 160], [0.0, 1.2])
    m = metrics(associate(robot, GT, "linear", 100 * MS))
    assert m is not None
    assert m.position_error == pytest.approx(0.45, abs=1e-12)
    assert m.rmse == pytest.approx(math.sqrt((0.25 + 0.16) / 2), abs=1e-12)
    assert m.median == pytest.approx(0.45, abs=1e-12)
    assert m.max == pytest.approx(0.5, abs=1e-12)


def test_non_increasing_robot_stamps_raise() -> None:
    with pytest.raises(ScoringError, match="do not increase: message 2"):
        check_increasing(stream([0, 100, 100, 300], [0.0] * 4), "r.bag")


def test_duplicates_from_overlapping_files_are_dropped_once() -> None:
    doubled = GT.take(np.array([0, 1, 1, 2, 2, 3]))
    clean, dropped = drop_duplicates(doubled)
    assert dropped == 2
    assert clean.t_ns.tolist() == GT.t_ns.tolist()


def test_uncovered_robot_poses_need_allow_partial() -> None:
    robot = stream([50, 150, 250, 350, 450], [0.0] * 5)
    with pytest.raises(ClockError, match="2 of 5 robot poses lie outside the GT"):
        score_streams(robot, GT, TrajectoryConfig())
    result = score_streams(robot, GT, TrajectoryConfig(allow_partial=True))
    assert (result.compared, result.uncovered) == (3, 2)
    assert any("partial" in w for w in result.warnings)


def test_config_rejects_unknown_association() -> None:
    with pytest.raises(ConfigError):
        TrajectoryConfig(association="spline")  # type: ignore[arg-type]


def _moving(offset_ns: int, seed: int) -> tuple[PoseStream, PoseStream]:
    """GT at 120 Hz on a Lissajous path; robot at 10 Hz, 3 mm noise, stamps shifted."""
    rng = np.random.default_rng(seed)
    tg = T0 + np.arange(0, 120 * 120) * 8_333_333

    def path(t: np.ndarray) -> np.ndarray:
        s = (t - T0) / 1e9
        return np.column_stack([2 * np.cos(0.2 * s), 1.5 * np.sin(0.3 * s), 0 * s + 0.4])

    gt = PoseStream(tg, path(tg), quat_from_yaw(np.zeros(len(tg))))
    tr = T0 + 5 * 10**9 + np.arange(1000) * 10**8 + rng.integers(0, 2 * MS, 1000)
    xyz = path(tr) + rng.normal(0, 0.003, (1000, 3))
    robot = PoseStream(tr - offset_ns, xyz, quat_from_yaw(np.zeros(1000)))
    return robot, gt


@pytest.mark.parametrize("offset_ms", [-1234.5, 0.0, 350.0, 4000.0])
def test_offset_estimate_recovers_a_known_offset(offset_ms: float) -> None:
    robot, gt = _moving(round(offset_ms * MS), seed=3)
    est = estimate_offset(robot, gt)
    assert est.offset_ns is not None and est.uncertainty_ns is not None
    # 3 mm white noise over 1000 poses at ~0.4 m/s: sd ~ 3e-3 / (0.4 * sqrt(3000)) ~ 0.14 ms.
    # 2 ms leaves room for the speed varying along the path.
    assert est.offset_ns / MS == pytest.approx(offset_ms, abs=2.0)
    assert 0 < est.uncertainty_ns < 5 * MS


def test_offset_of_a_robot_standing_still_is_not_observable() -> None:
    # Mocap noise 0.2 mm (reads as 3 cm/s between 120 Hz samples), robot noise 3 mm.
    rng = np.random.default_rng(5)
    n = 300
    g = n * 12 + 240
    gt = PoseStream(
        T0 + np.arange(g) * 8_333_333,
        1 + rng.normal(0, 2e-4, (g, 3)),
        quat_from_yaw(np.zeros(g)),
    )
    robot = PoseStream(
        T0 + 10**9 + np.arange(n) * 10**8,
        1 + rng.normal(0, 3e-3, (n, 3)),
        quat_from_yaw(np.zeros(n)),
    )
    est = estimate_offset(robot, gt)
    assert est.offset_ns is None
    assert "barely moved" in est.note


def test_nan_and_zero_quaternion_poses_are_ignored_and_counted() -> None:
    gt = stream([0, 100, 200, 300], [0.0, 1.0, 2.0, 3.0])
    gt.xyz[2, 1] = np.nan  # GT sample at 200 ms unusable: 100..300 is then a 200 ms gap
    robot = stream([50, 160, 250], [0.0, 0.0, 0.0])
    robot.quat_xyzw[1] = 0.0  # "no pose" from the robot
    r = score_streams(robot, gt, TrajectoryConfig(max_gap_ns=250 * MS))
    assert (r.compared, r.gaps) == (2, 0)
    assert r.metrics is not None
    # 50 ms -> x 0.5; 250 ms between 100 (x 1) and 300 (x 3) -> x 2.5
    assert r.metrics.position_error == pytest.approx((0.5 + 2.5) / 2, abs=1e-12)
    assert any("1 GT sample(s) with NaN" in w for w in r.warnings)
    assert any("1 robot pose(s) with NaN" in w for w in r.warnings)


def test_drop_invalid_keeps_tiny_quaternions_and_drops_unusable_ones() -> None:
    s = stream([0, 10, 20, 30, 40, 50, 60], [0.0] * 7)
    s.quat_xyzw[1] = [0.0, 0.0, 0.0, 2e-9]  # norm 2e-9: small but a rotation, kept
    s.quat_xyzw[2] = [0.0, 0.0, 5e-10, 5e-10]  # norm 7.1e-10 <= 1e-9: "no pose"
    s.quat_xyzw[3] = [0.0, 0.0, 0.0, np.inf]
    s.quat_xyzw[4] = [0.0, 0.0, 1e200, 1e200]  # its norm overflows to inf
    s.xyz[5, 2] = -np.inf
    kept, dropped = drop_invalid(s)
    assert dropped == 4
    assert ((kept.t_ns - T0) // MS).tolist() == [0, 10, 60]
    clean, none = drop_invalid(stream([0, 10], [1.0, 2.0]))
    assert none == 0 and len(clean) == 2


def test_nothing_comparable_is_a_failure() -> None:
    # GT repeats one pose (tracking lost) for the whole robot log.
    gt = stream([0, 100, 200, 300], [1.0, 1.0, 1.0, 1.0])
    r = score_streams(stream([50, 150, 250], [0.0] * 3), gt, TrajectoryConfig())
    assert r.metrics is None and r.tracking_lost == 3
    assert r.failures and "no robot pose could be compared" in r.failures[0]
    d = r.to_dict()
    assert d["position_error"] is None and d["compared"] == 0


@pytest.mark.slow
def test_coarse_scan_equals_a_direct_nearest_grid_computation() -> None:
    """The coarse scan's vectorised gather (NaN-padded grid, gaps marked per gap) against the
    definition written out per offset: mean distance to the GT interpolated at the nearest
    10 ms grid point, over the grid points not strictly inside a GT gap > max_gap (the first
    grid point judged by the first GT interval), offsets reaching past the GT included."""

    robot, gt = _moving(250 * MS, seed=5)
    # Gaps: at the start (first interval), in the middle, and one just above max_gap.
    keep = np.ones(len(gt), dtype=bool)
    keep[1:40] = False
    keep[3000:3300] = False
    keep[6000:6012] = False
    gt = gt.take(keep)
    max_gap = 100 * MS
    offsets = np.arange(-300, 301, dtype=np.int64) * 20 * MS  # to +-6 s, past the GT's ends
    got = _coarse_scan(robot.t_ns, robot.xyz, gt, offsets, max_gap)

    t, t0 = gt.t_ns, int(gt.t_ns[0])
    n_grid = (int(t[-1]) - t0) // GRID_NS + 1
    want = np.full(len(offsets), np.inf)
    counts = np.zeros(len(offsets), dtype=np.int64)
    for k, off in enumerate(offsets):
        g = np.rint((robot.t_ns - t0) / GRID_NS).astype(np.int64) + round(off / GRID_NS)
        inside = (g >= 0) & (g < n_grid)
        gt_ns = t0 + g[inside] * GRID_NS
        j = np.searchsorted(t, gt_ns, side="left")
        after = np.clip(j, 1, len(t) - 1)
        ok = (t[after] - t[after - 1] <= max_gap) | (t[after] == gt_ns)
        rel = (gt_ns - t0).astype(np.float64)
        xyz = np.column_stack(
            [np.interp(rel, (t - t0).astype(np.float64), gt.xyz[:, a]) for a in range(3)]
        ).astype(np.float32)
        d = np.linalg.norm(xyz[ok] - robot.xyz[inside][ok].astype(np.float32), axis=1)
        counts[k] = ok.sum()
        if ok.any():
            want[k] = d.mean()
    want[counts < max(MIN_POSES, int(0.5 * counts.max()))] = np.inf
    assert np.array_equal(np.isfinite(got), np.isfinite(want))
    # Offsets reach past the GT's start (robot from 5 s, offsets to -6 s) and the gaps drop
    # poses: the counts vary, so the padding and the gap marks are exercised.
    assert counts.min() < counts.max() and np.isfinite(got).sum() > 100
    # float32 positions (0.1 um at 10 m) summed in another order: 1e-6 m is far below the
    # 5 mm error the nearest-grid lookup itself allows.
    fin = np.isfinite(want)
    assert np.max(np.abs(got[fin] - want[fin])) < 1e-6


def test_fine_scan_window_search_equals_binary_searches() -> None:
    """The fine scan counts GT samples inside each pose's window instead of searching: the
    same indices as two binary searches, with exact hits, doubled stamps and windows running
    past both ends of the GT; a window too dense to pay falls back (None)."""

    t = np.array([0, 8, 17, 25, 25, 33, 42, 50, 58], dtype=np.int64) * MS
    robot_t = np.array([-30, 0, 12, 25, 41, 57, 70], dtype=np.int64) * MS
    offsets = np.arange(-20, 21, dtype=np.int64) * MS
    around = around_window(t, robot_t, offsets)
    assert around is not None
    q = (offsets[:, None] + robot_t[None, :]).ravel()
    assert np.array_equal(around[0], np.searchsorted(t, q, side="right") - 1)
    assert np.array_equal(around[1], np.searchsorted(t, q, side="left"))
    dense = np.arange(0, 100, dtype=np.int64) * MS  # 1 kHz: 41 samples per 40 ms window
    assert around_window(dense, robot_t, offsets) is None


def test_coarse_grid_in_chunks_equals_one_interpolation(monkeypatch: pytest.MonkeyPatch) -> None:
    """Grid chunks of 97 points (boundaries everywhere, exact hits included) against one
    np.interp over the whole GT: the same float32 values; NaN in the padding and strictly
    inside the gap."""

    _, gt = _moving(0, seed=6)
    keep = np.ones(len(gt), dtype=bool)
    keep[2000:2030] = False  # 258 ms without GT after sample 1999
    gt = gt.take(keep)
    monkeypatch.setattr(clock_offset, "GRID_CHUNK", 97)
    t, t0, step = gt.t_ns, int(gt.t_ns[0]), 10 * MS
    n_grid = (int(t[-1]) - t0) // step + 1
    grid = clock_offset._grid(gt, step, n_grid, 100 * MS, pad=3)
    rel_g = np.arange(n_grid) * float(step)
    want = np.vstack(
        [np.interp(rel_g, (t - t0).astype(np.float64), gt.xyz[:, k]) for k in range(3)]
    ).astype(np.float32)
    inner = grid[:, 3:-3]
    gap = (t0 + np.arange(n_grid) * step > t[1999]) & (t0 + np.arange(n_grid) * step < t[2000])
    assert gap.sum() == 26  # 16.6583 s to 16.9167 s: grid points 16.66 to 16.91 s
    assert np.isnan(grid[:, :3]).all() and np.isnan(grid[:, -3:]).all()
    assert np.isnan(inner[:, gap]).all()
    assert np.array_equal(inner[:, ~gap], want[:, ~gap])
