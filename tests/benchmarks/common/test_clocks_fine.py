"""The clock audit's fine scan: each offset's mean distance to the GT interpolated exactly,
against a plain loop over offsets and poses (hostile streams: gaps, tracking losses, a body
standing still, logs sticking out of the GT)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from ertools.benchmarks.common import clock_queries, clocks
from ertools.benchmarks.common.clocks import FINE_STEP_NS, MIN_POSES
from ertools.benchmarks.common.hygiene import drop_repeats
from ertools.streams import PoseStream
from tests.benchmarks.common.test_clocks_coarse import MS, streams


def plain_fine(robot: PoseStream, gt: PoseStream, offsets: np.ndarray, max_gap: int) -> np.ndarray:
    """Per offset, per pose: the two GT samples around the shifted stamp (not further apart
    than ``max_gap``), the position between them, the mean distance over the poses that have
    one; inf where fewer than half the best coverage (and MIN_POSES) compare."""
    t = [int(v) for v in gt.t_ns]
    costs, counts = [], []
    for off in offsets.tolist():
        dists = []
        for q, p in zip((robot.t_ns + off).tolist(), robot.xyz.tolist(), strict=True):
            after = int(np.searchsorted(gt.t_ns, q, side="left"))
            before = int(np.searchsorted(gt.t_ns, q, side="right")) - 1
            if before < 0 or after >= len(t) or t[after] - t[before] > max_gap:
                continue
            span = t[after] - t[before]
            a = (q - t[before]) / span if span > 0 else 0.0
            g = [lo + a * (hi - lo) for lo, hi in zip(gt.xyz[before], gt.xyz[after], strict=True)]
            dists.append(math.dist(p, g))
        counts.append(len(dists))
        costs.append(math.fsum(dists) / len(dists) if dists else math.inf)
    enough = np.array(counts) >= max(MIN_POSES, int(0.5 * max(counts)))
    return np.where(enough, costs, np.inf)


@settings(max_examples=40, deadline=None)
@given(streams())
def test_fine_costs_are_the_plain_means(case: tuple[PoseStream, PoseStream]) -> None:
    gt, robot = case
    gt = drop_repeats(gt)
    assume(len(gt) >= 2)
    robot = robot.take(np.arange(0, len(robot), max(1, len(robot) // 60)))  # a plain loop's size
    max_gap = 100 * MS
    offsets = -60 * MS + np.arange(-8, 9, dtype=np.int64) * 3 * FINE_STEP_NS
    got, _ = clocks._scan(robot.t_ns, robot.xyz, gt, offsets, max_gap)
    want = plain_fine(robot, gt, offsets, max_gap)
    assert np.array_equal(np.isinf(got), np.isinf(want))
    # float64 sums of at most a few hundred distances of metres, in another order: 1e-12 m
    # relative is 10x the worst rounding (n * 2**-52 ~ 7e-14 at n = 300)
    finite = np.isfinite(want)
    assert np.allclose(got[finite], want[finite], rtol=1e-12, atol=1e-15)


@settings(max_examples=80, deadline=None)
@given(
    streams(),
    st.sampled_from([1, 3, 7]),
    st.lists(st.integers(1, 10**6), max_size=4),
    st.sampled_from([30, 100]),
    st.sampled_from([1, 500, clock_queries.BLOCK_ROWS]),
)
def test_window_distances_are_the_plain_ones_to_the_bit(
    case: tuple[PoseStream, PoseStream],
    step_ms: int,
    repeat: list[int],
    max_gap_ms: int,
    block_rows: int,
) -> None:
    """The per-pose tables give every query the distance and validity of its own evaluation,
    bit for bit: on GT stamps (whole ms here, as the robot's), on repeated stamps (two GT
    poses at one time), in gaps, outside the GT; whichever offsets are computed together."""
    gt, robot = case
    gt = drop_repeats(gt)
    assume(len(gt) >= 3)
    if repeat:
        t = gt.t_ns.copy()
        for i in repeat:
            j = 1 + i % (len(t) - 1)
            t[j] = t[j - 1]  # still non-decreasing: the stamp before is at most t[j]
        gt = PoseStream(t, gt.xyz, gt.quat_xyzw, gt.frame_id, gt.child_frame_id)
    offsets = -60 * MS + np.arange(-20, 21, dtype=np.int64) * step_ms * MS
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(clock_queries, "BLOCK_ROWS", block_rows)
        got = clock_queries.window_distances(robot.t_ns, robot.xyz, gt, offsets, max_gap_ms * MS)
    want = clock_queries.plain_distances(robot.t_ns, robot.xyz, gt, offsets, max_gap_ms * MS)
    assert got is not None
    assert np.array_equal(got[1], want[1])
    assert np.array_equal(got[0], want[0], equal_nan=True)
    assert got[0].flags.c_contiguous  # the means sum each row as one array


@settings(max_examples=100, deadline=None)
@given(
    st.lists(st.integers(0, 50), min_size=2, max_size=60),
    st.lists(st.integers(-300, 3000), min_size=1, max_size=40),
    st.integers(-40, 40),
    st.booleans(),
)
def test_places_moved_from_nearby_queries_are_the_binary_searchs(
    gaps: list[int], stamps: list[int], shift: int, fresh: bool
) -> None:
    """From the places of queries shifted by ``shift`` (one sample or many, repeated stamps,
    queries before and after the samples), the moved places are searchsorted's."""
    t = np.cumsum(np.array(gaps, dtype=np.int64))
    query = np.sort(np.array(stamps, dtype=np.int64))
    before = None if fresh else np.searchsorted(t, query - shift, side="right")
    got = clock_queries.right_near(t, query, before)
    assert np.array_equal(got, np.searchsorted(t, query, side="right"))
