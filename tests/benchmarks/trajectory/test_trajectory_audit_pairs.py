"""The clock audit inside a score reuses the score's pairs at no offset: on hostile streams its
result is the audit's own to the bit, and the mean distance it takes equals a plain reading of
the rule (every robot pose paired with the GT interpolated at its stamp, not across a gap).
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from ertools.benchmarks.common.clocks import estimate_offset
from ertools.benchmarks.common.inputs import IntervalSettings
from ertools.benchmarks.trajectory.association import associate
from ertools.benchmarks.trajectory.comparison import _audit_pairs, score_streams
from ertools.benchmarks.trajectory.config import TrajectoryConfig
from ertools.errors import ClockError, ScoringError
from ertools.geometry import quat_from_yaw
from ertools.streams import PoseStream

MS = 1_000_000
T0 = 1_700_000_000 * 1_000_000_000
NO_DRAWS = IntervalSettings(draws=0)


@st.composite
def gt_and_robot(draw: st.DrawFn) -> tuple[PoseStream, PoseStream]:
    """A GT at ~120 Hz with gaps, repeated stamps and positions (tracking lost), and a robot
    log at ~10 Hz moving with it, some of it before or after the GT."""
    n = draw(st.integers(2, 400))
    gaps = st.sampled_from([8 * MS] * 20 + [0, 1 * MS, 150 * MS, 700 * MS])
    t = T0 + np.cumsum([0, *draw(st.lists(gaps, min_size=n - 1, max_size=n - 1))])
    seconds = (t - T0) / 1e9
    xyz = np.column_stack([np.sin(seconds), np.cos(0.7 * seconds), 0.1 * seconds])
    xyz = np.round(xyz * 2**20) / 2**20
    frozen = draw(st.lists(st.integers(1, n - 1), max_size=5)) if draw(st.booleans()) else []
    for i in frozen:  # Motive re-sending the last pose
        xyz[i] = xyz[i - 1]
    gt = PoseStream(t.astype(np.int64), xyz, quat_from_yaw(seconds), "world", "body")
    m = draw(st.integers(1, 80))
    start = T0 + draw(st.integers(-300, 1500)) * MS
    stamps = start + np.cumsum(
        draw(
            st.lists(
                st.sampled_from([100, 100, 97, 8, 400]).map(lambda x: x * MS),
                min_size=m,
                max_size=m,
            )
        )
    )
    lag = draw(st.sampled_from([0, 3, 40])) * MS  # the robot clock behind the GT's
    at = (stamps + lag - T0) / 1e9
    noise = np.array(draw(st.lists(st.integers(-20, 20), min_size=3 * m, max_size=3 * m)))
    robot_xyz = np.column_stack([np.sin(at), np.cos(0.7 * at), 0.1 * at])
    robot_xyz = robot_xyz + noise.reshape(m, 3) / 2048
    robot = PoseStream(stamps.astype(np.int64), robot_xyz, quat_from_yaw(at), "world", "robot")
    return gt, robot


@pytest.mark.slow
@settings(max_examples=150, deadline=None)
@given(gt_and_robot(), st.sampled_from([0, 20 * MS]), st.sampled_from([100 * MS, 500 * MS]))
def test_the_scores_audit_is_the_audits_own(
    streams: tuple[PoseStream, PoseStream], offset_ns: int, max_gap_ns: int
) -> None:
    gt, robot = streams
    config = TrajectoryConfig(allow_partial=True, offset_ns=offset_ns, max_gap_ns=max_gap_ns)
    try:
        result = score_streams(robot, gt, config, intervals=NO_DRAWS)
    except (ClockError, ScoringError):
        return  # no robot pose inside the GT: no audit to compare
    alone = estimate_offset(
        robot, gt, search_range_ns=config.offset_range_ns, max_gap_ns=max_gap_ns
    )
    assert dataclasses.astuple(result.audit) == dataclasses.astuple(alone)


def plain_mean_at_zero(robot: PoseStream, gt: PoseStream, max_gap_ns: int) -> tuple[float, int]:
    """Mean distance of the robot poses to the GT linearly interpolated at their stamps, for
    poses with GT samples on both sides no more than the max gap apart."""
    t = gt.t_ns.tolist()
    dists = []
    for q, p in zip(robot.t_ns.tolist(), robot.xyz.tolist(), strict=True):
        before = [i for i in range(len(t)) if t[i] <= q]
        after = [i for i in range(len(t)) if t[i] >= q]
        if not before or not after:
            continue
        a, b = before[-1], after[0]
        if t[b] - t[a] > max_gap_ns:
            continue
        w = (q - t[a]) / (t[b] - t[a]) if t[b] > t[a] else 0.0
        g = [gt.xyz[a][k] + w * (gt.xyz[b][k] - gt.xyz[a][k]) for k in range(3)]
        dists.append(math.dist(p, g))
    return (sum(dists) / len(dists), len(dists)) if dists else (math.inf, 0)


@pytest.mark.slow
@settings(max_examples=150, deadline=None)
@given(gt_and_robot(), st.sampled_from([100 * MS, 500 * MS]))
def test_the_pairs_taken_are_the_plain_rule(
    streams: tuple[PoseStream, PoseStream], max_gap_ns: int
) -> None:
    gt, robot = streams
    config = TrajectoryConfig(max_gap_ns=max_gap_ns)
    matched = associate(robot, gt, "linear", max_gap_ns)
    got = _audit_pairs(matched, config)
    assert got is not None
    # with no GT sample repeating the previous one, none is tracking-lost: the plain rule's
    if np.any(np.all(gt.xyz[1:] == gt.xyz[:-1], axis=1)):
        return
    want = plain_mean_at_zero(robot, gt, max_gap_ns)
    assert got[1] == want[1]
    # sums of up to 80 distances below 2 m, in another order: 1e-12 m is a thousand times
    # their rounding
    assert got[0] == pytest.approx(want[0], rel=0, abs=1e-12) or got[0] == want[0] == math.inf


@pytest.mark.parametrize(
    "change",
    [
        {"association": "hold"},
        {"association": "nearest"},
        {"offset_ns": 5 * MS},
        {"gaps": "compare"},
        {"before_gt": "first"},
        {"t_max_diff": 0.01, "association": "nearest"},
    ],
)
def test_other_rules_pair_otherwise(change: dict[str, object]) -> None:
    """Any other rule than the audit's: the audit pairs the poses itself."""
    t = T0 + np.arange(50, dtype=np.int64) * 8 * MS
    xyz = np.outer(np.arange(50) / 64, [1.0, 0.5, 0.0])
    gt = PoseStream(t, xyz, quat_from_yaw(np.zeros(50)), "world", "body")
    matched = associate(gt, gt, "linear", 100 * MS)
    assert _audit_pairs(matched, TrajectoryConfig(**change)) is None  # type: ignore[arg-type]
    assert _audit_pairs(matched, TrajectoryConfig()) == (0.0, 50)
