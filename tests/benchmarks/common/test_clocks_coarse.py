"""The clock audit's coarse scan leaves out offsets that cannot fit: on hostile streams (gaps,
tracking losses, a body standing still, motion that repeats itself, logs sticking out of the
GT) every offset it costs has the cost of a plain scan, every one it leaves out fits worse
than the best by more than the rival margin, and the audit is the one of the full scan.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from ertools.benchmarks.common import clocks
from ertools.benchmarks.common.clocks import (
    COARSE_MAX_POSES,
    COARSE_STEP_NS,
    GRID_NS,
    MIN_POSES,
    estimate_offset,
)
from ertools.benchmarks.common.hygiene import drop_repeats
from ertools.geometry import quat_from_yaw
from ertools.streams import PoseStream

MS = 1_000_000
T0 = 1_700_000_000 * 1_000_000_000


def plain_costs(
    robot: PoseStream, gt: PoseStream, offsets: np.ndarray, max_gap_ns: int
) -> np.ndarray:
    """Per offset, the mean distance (float64) of the robot poses to the GT on a 10 ms grid
    (linear between GT samples, none strictly inside a gap), the nearest grid point to each
    shifted stamp; inf where fewer poses compare than half the most any offset compares."""
    t = gt.t_ns.tolist()
    step = max(GRID_NS, (t[-1] - t[0]) // clocks.GRID_MAX_POINTS + 1)
    n_grid = (t[-1] - t[0]) // step + 1
    grid = np.full((n_grid, 3), np.nan)
    j = 0
    for i in range(n_grid):
        at = t[0] + i * step
        while j + 1 < len(t) and t[j + 1] <= at:
            j += 1
        if t[j] == at:  # on a sample (the first grid point: only if the first gap is short)
            if i > 0 or t[1] - t[0] <= max_gap_ns:
                grid[i] = gt.xyz[j]
        elif t[j + 1] - t[j] <= max_gap_ns:
            w = (at - t[j]) / (t[j + 1] - t[j])
            grid[i] = gt.xyz[j] + w * (gt.xyz[j + 1] - gt.xyz[j])
    every = max(1, len(robot) // COARSE_MAX_POSES)
    sub_t, sub_xyz = robot.t_ns[::every].tolist(), robot.xyz[::every]
    base = np.array([round((q - t[0]) / step) for q in sub_t])
    means, counts = [], []
    for off in offsets.tolist():
        at = base + round(off / step)
        inside = (at >= 0) & (at < n_grid)
        g = np.full((len(base), 3), np.nan)
        g[inside] = grid[at[inside]]
        d = np.linalg.norm(sub_xyz - g, axis=1)
        d = d[~np.isnan(d)]
        means.append(d.mean() if d.size else np.inf)
        counts.append(d.size)
    most = max(counts)
    enough = np.array(counts) >= max(MIN_POSES, int(0.5 * most))
    return np.where(enough, means, np.inf)


@st.composite
def streams(draw: st.DrawFn) -> tuple[PoseStream, PoseStream]:
    n = draw(st.integers(30, 1500))
    period = draw(st.sampled_from([8, 10, 33])) * MS
    dt = np.full(n - 1, period, dtype=np.int64)
    for _ in range(draw(st.sampled_from([0, 0, 0, 1, 3]))):  # gaps
        dt[draw(st.integers(0, n - 2))] = draw(st.sampled_from([150, 400, 2000])) * MS
    t = T0 + np.concatenate([[0], np.cumsum(dt)])
    s = (t - T0) / 1e9
    kind = draw(st.sampled_from(["walk", "repeat", "still", "turn"]))
    if kind == "walk":
        xyz = np.column_stack([0.5 * s, np.sin(0.8 * s), 0 * s])
    elif kind == "repeat":  # back and forth every 2 s: other offsets fit almost as well
        xyz = np.column_stack([np.sin(np.pi * s), 0 * s, 0 * s])
    elif kind == "still":
        xyz = np.column_stack([0 * s + 1.0, 0 * s, 0 * s])
    else:
        xyz = np.column_stack([np.cos(s), np.sin(s), 0.01 * s])
    for _ in range(draw(st.sampled_from([0, 0, 0, 1, 2]))):  # tracking lost: the pose re-sent
        i = draw(st.integers(1, n - 5))
        xyz[i : i + draw(st.integers(1, 4))] = xyz[i - 1]
    gt = PoseStream(t, xyz, quat_from_yaw(s), "world", "body")
    m = draw(st.integers(MIN_POSES, 300))
    first = T0 + draw(st.integers(-1500, int(s[-1] * 500))) * MS
    stamps = first + np.arange(m, dtype=np.int64) * draw(st.sampled_from([50, 100])) * MS
    lag = draw(st.sampled_from([0, 60, -300])) * MS
    r = (stamps + lag - T0) / 1e9
    noise = draw(st.sampled_from([0.0, 0.01]))
    rng = np.random.default_rng(draw(st.integers(0, 9)))
    robot_xyz = np.interp(r, s, xyz[:, 0])[:, None] * [1, 0, 0] + np.column_stack(
        [0 * r, np.interp(r, s, xyz[:, 1]), np.interp(r, s, xyz[:, 2])]
    )
    robot_xyz = robot_xyz + noise * rng.normal(size=robot_xyz.shape)
    robot = PoseStream(stamps, robot_xyz, quat_from_yaw(r), "world", "robot")
    return gt, robot


@pytest.mark.slow
@settings(max_examples=100, deadline=None)
@given(streams(), st.sampled_from([1, 3]))
def test_coarse_costs_are_plain_or_worse_than_any_rival(
    case: tuple[PoseStream, PoseStream], seconds: int
) -> None:
    gt, robot = case
    gt = drop_repeats(gt)
    assume(len(gt) >= 2)  # a body standing still: one pose left, no scan
    max_gap_ns = 100 * MS
    n = seconds * 1000 // (COARSE_STEP_NS // MS)
    offsets = np.arange(-n, n + 1, dtype=np.int64) * COARSE_STEP_NS
    every = max(1, len(robot) // COARSE_MAX_POSES)
    got = clocks._coarse_scan(robot.t_ns[::every], robot.xyz[::every], gt, offsets, max_gap_ns)
    want = plain_costs(robot, gt, offsets, max_gap_ns)
    best = float(want.min())
    if not np.isfinite(best):
        assert np.isinf(got).all()
        return
    # float32 grid and sums against float64: 1e-4 m relative and 1e-6 m absolute
    costed = np.isfinite(got)
    assert np.allclose(got[costed], want[costed], rtol=1e-4, atol=1e-6)
    left = ~costed & np.isfinite(want)
    assert (want[left] > (best * 1.1 + 1e-3) * (1 - 1e-4)).all()
    # the best and every offset within the rival margin are costed
    assert costed[want <= (best * 1.1 + 1e-3) * (1 - 1e-4)].all()


@pytest.mark.slow
@settings(max_examples=60, deadline=None)
@given(streams(), st.sampled_from([1, 3]))
def test_the_audit_is_the_full_scans(case: tuple[PoseStream, PoseStream], seconds: int) -> None:
    """Every shortcut off, the audit is the plain one: every coarse offset costed, every fine
    query located by a binary search and interpolated on its own, every Gauss-Newton
    evaluation searched afresh. Estimate, uncertainty, notes: the same to the bit."""
    gt, robot = case
    fast = estimate_offset(robot, gt, search_range_ns=seconds * 1000 * MS)
    full = pytest.MonkeyPatch()
    with full.context() as patch:
        patch.setattr(clocks, "_pruned_costs", lambda *args: None)
        patch.setattr(clocks, "window_distances", lambda *args: None)
        patch.setattr(clocks, "right_near", lambda t, q, right: np.searchsorted(t, q, side="right"))
        plain = estimate_offset(robot, gt, search_range_ns=seconds * 1000 * MS)
    assert dataclasses.astuple(fast) == dataclasses.astuple(plain)


def test_a_pose_leaving_the_gt_takes_its_distance_with_it(monkeypatch: pytest.MonkeyPatch) -> None:
    """The robot's first pose, 5 m off, lies 90 ms after the GT's first sample: from -100 ms
    it leaves the GT, and its 5 m with it. There the mean is 2.5 cm, the best; the offset
    costed first after it (-40 ms, one offset in 4 costed first) has 5 cm, and its bound must
    not forget the 5 m."""
    monkeypatch.setattr(clocks, "COARSE_FIRST_EVERY", 4)
    t = T0 + np.arange(2400, dtype=np.int64) * 25 * MS // 3  # 20 s at 120 Hz
    s = (t - T0) / 1e9
    gt = PoseStream(t, np.column_stack([s / 4, 0 * s, 0 * s]), quat_from_yaw(0 * s), "world", "b")
    stamps = T0 + np.arange(120, dtype=np.int64) * 100 * MS + 90 * MS
    r = (stamps - T0) / 1e9
    xyz = np.column_stack([r / 4, 0 * r, 0 * r])
    xyz[0, 1] = 5.0
    robot = PoseStream(stamps, xyz, quat_from_yaw(0 * r), "world", "r")
    offsets = np.arange(-50, 51, dtype=np.int64) * COARSE_STEP_NS
    got = clocks._coarse_scan(stamps, xyz, gt, offsets, 100 * MS)
    want = plain_costs(robot, gt, offsets, 100 * MS)
    assert int(np.argmin(got)) == int(np.argmin(want)) == 45  # -100 ms
    costed = np.isfinite(got)
    assert np.allclose(got[costed], want[costed], rtol=1e-4, atol=1e-6)
    assert costed[want <= float(want.min()) * 1.1 + 1e-3].all()
