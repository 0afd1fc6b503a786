"""FBM2@Home scoring on hand-built streams: transform composition, wrapping, gaps."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest

from ertools.benchmarks.fbm2h.formula import segment_errors
from ertools.benchmarks.fbm2h.goal import GoalList
from ertools.benchmarks.fbm2h.pipeline import compute
from ertools.benchmarks.fbm2h.runs import ReachedMoments, from_states, unreached_reasons
from ertools.configs.transform import MarkerTransform, identity_transform
from ertools.errors import SegmentationError
from ertools.states import BmBoxState, ClientState, Machine, RefBoxState
from ertools.streams import PoseStream, StateStream

S = 1_000_000_000
T0 = 1_445_609_740 * S


def _quat_yaw(yaw: float) -> list[float]:
    return [0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2)]


def _stream(t_s: list[float], xyz: list[list[float]], yaw: list[float]) -> PoseStream:
    return PoseStream(
        T0 + np.round(np.asarray(t_s) * S).astype(np.int64),
        np.asarray(xyz, dtype=float),
        np.asarray([_quat_yaw(y) for y in yaw]),
        "world",
        "robot_at_home",
        "test",
    )


def _moments(start_s: list[float], end_s: list[float]) -> ReachedMoments:
    return ReachedMoments(
        "timing",
        T0 + np.round(np.asarray(start_s) * S).astype(np.int64),
        T0 + np.round(np.asarray(end_s) * S).astype(np.int64),
        tuple("" for _ in end_s),
    )


# Marker at yaw +90 deg; robot 0.2 m ahead of the marker along the marker's x, 0.5 m below it,
# turned -90 deg: by hand, robot = marker + Rz(90)(0.2, 0, -0.5) = marker + (0, 0.2, -0.5),
# robot yaw = 90 - 90 = 0.
_Q = _quat_yaw(-math.pi / 2)
TRANSFORM = MarkerTransform(
    "team", "2015-10-23_16:15:40", (0.2, 0.0, -0.5), (_Q[0], _Q[1], _Q[2], _Q[3]), "test"
)


def test_non_identity_transform_hand_computed() -> None:
    # The marker moves from (2, 1) to (4, 1) in 1 s; at 0.5 s it is at (3, 1) (linear).
    marker = _stream([0.0, 1.0], [[2, 1, 0.5], [4, 1, 0.5]], [math.pi / 2, math.pi / 2])
    goal = GoalList(((3.1, 1.2, 0.1),), source="g")
    result = compute(goal, TRANSFORM, marker, _moments([0.0], [0.5]), max_gap_s=0.6)
    seg = result.segments[0]
    assert seg.status == "ok"
    # Robot at (3, 1.2, yaw 0): by hand 0.1 m and 0.1 rad from the target (float rounding only).
    assert seg.robot == pytest.approx((3.0, 1.2, 0.0), abs=1e-12)
    assert seg.distance_error == pytest.approx(0.1, abs=1e-12)
    assert seg.orientation_error == pytest.approx(0.1, abs=1e-12)
    assert result.position_accuracy == pytest.approx(0.1, abs=1e-12)
    assert result.execution_time == pytest.approx(0.5, abs=1e-9)
    assert not any("identity" in w for w in result.warnings)
    listing = result.to_dict()
    assert listing["details"]["marker-robot transform"][0] == [0.2, 0.0, -0.5]
    assert listing["details"]["segments_details"]["0"]["dinstance_error"] == pytest.approx(0.1)


def test_slerp_between_samples_and_identity_warning() -> None:
    # Yaw turns from 0 to 90 deg between samples; halfway it is 45 deg (SLERP about z).
    marker = _stream([0.0, 0.1], [[0, 0, 0], [0, 0, 0]], [0.0, math.pi / 2])
    goal = GoalList(((0.0, 0.0, 0.0),), source="g")
    result = compute(goal, identity_transform(), marker, _moments([0.0], [0.05]))
    assert result.segments[0].orientation_error == pytest.approx(math.pi / 4, abs=1e-9)
    assert any("identity" in w for w in result.warnings)


@pytest.mark.parametrize(
    ("robot_yaw", "target", "wrapped", "as_2015"),
    [
        # 3.1 - (-3.1) = 6.2 rad unwrapped; the headings are 2 pi - 6.2 = 0.0832 rad apart.
        (3.1, -3.1, 2 * math.pi - 6.2, math.atan2(math.sin(6.2), math.cos(6.2))),
        (-3.0, 3.0, 2 * math.pi - 6.0, math.atan2(math.sin(6.0), math.cos(6.0))),
        (0.3, -0.2, 0.5, 0.5),
    ],
)
def test_orientation_across_the_seam(
    robot_yaw: float, target: float, wrapped: float, as_2015: float
) -> None:
    robot = np.array([[0.0, 0.0, robot_yaw]])
    tgt = np.array([[0.0, 0.0, target]])
    assert segment_errors(robot, tgt).orientation[0] == pytest.approx(wrapped, abs=1e-12)
    e15 = segment_errors(robot, tgt, orientation_2015=True)
    assert e15.orientation[0] == pytest.approx(as_2015, abs=1e-12)


def test_orientation_accuracy_is_circular_mean_of_errors() -> None:
    robot = np.array([[0.0, 0.0, 0.1], [0.0, 0.0, math.pi - 0.05]])
    tgt = np.array([[0.0, 0.0, 0.0], [0.0, 0.0, -math.pi + 0.05]])
    e = segment_errors(robot, tgt)
    # Errors 0.1 and 0.1 (across the seam): their circular mean is 0.1.
    assert e.orientation == pytest.approx([0.1, 0.1], abs=1e-12)
    assert e.orientation_accuracy == pytest.approx(0.1, abs=1e-12)
    e15 = segment_errors(robot, tgt, orientation_2015=True)
    # 2015: sin/cos of |dtheta| = 0.1 and 2 pi - 0.1 -> sines cancel, accuracy 0.
    assert e15.orientation_accuracy == pytest.approx(0.0, abs=1e-12)


def test_no_gt_near_moment_is_a_failure_not_a_guess() -> None:
    # Tracking lost between 1 s and 3 s; the waypoint is reached at 2 s.
    marker = _stream([0.0, 1.0, 3.0], [[0, 0, 0], [1, 0, 0], [1, 0, 0]], [0.0, 0.0, 0.0])
    goal = GoalList(((0.0, 0.0, 0.0), (1.0, 0.0, 0.0)), source="g")
    result = compute(
        goal, identity_transform(), marker, _moments([0.0, 0.5], [0.5, 2.0]), max_gap_s=0.6
    )
    assert [s.status for s in result.segments] == ["ok", "no_gt"]
    assert len(result.failures) == 1 and "segment 1" in result.failures[0]
    assert result.position_accuracy is None
    assert result.to_dict()["details"]["segments_details"]["1"]["dinstance_error"] is None


def test_nearest_sample_used_when_only_one_neighbour_is_close() -> None:
    # Samples at 0.95 s and 5 s: at 1.0 s only the first is within 0.1 s: it is used as is.
    marker = _stream([0.95, 5.0], [[1, 0, 0], [9, 0, 0]], [0.0, 0.0])
    goal = GoalList(((1.0, 0.0, 0.0),), source="g")
    result = compute(goal, identity_transform(), marker, _moments([0.0], [1.0]))
    assert result.segments[0].distance_error == pytest.approx(0.0, abs=1e-12)


def test_count_mismatch_is_an_error() -> None:
    marker = _stream([0.0, 1.0], [[0, 0, 0], [1, 0, 0]], [0.0, 0.0])
    goal = GoalList(((0.0, 0.0, 0.0),), source="g")
    with pytest.raises(SegmentationError, match="2 reached moments"):
        compute(goal, identity_transform(), marker, _moments([0.0, 0.2], [0.2, 0.4]))


def _states(machine: Any, events: list[tuple[float, int, str]]) -> StateStream:
    return StateStream(
        machine,
        np.array([T0 + round(t * S) for t, _, _ in events], dtype=np.int64),
        np.array([s for _, s, _ in events], dtype=np.uint8),
        tuple(p for _, _, p in events),
        "/fbm2h/x",
        "test",
    )


def test_states_segments_and_refbox_timeout() -> None:
    bm = _states(
        Machine.BMBOX,
        [
            (0.0, BmBoxState.READY, ""),
            (1.0, BmBoxState.TRANSMITTING_GOAL, "waypoints: []"),
            (1.2, BmBoxState.EXECUTING_GOAL, ""),
            (1.21, BmBoxState.WAITING_RESULT, ""),
            (4.0, BmBoxState.READY, ""),
            (5.0, BmBoxState.TRANSMITTING_GOAL, ""),
            (5.3, BmBoxState.EXECUTING_GOAL, ""),
            (5.31, BmBoxState.WAITING_RESULT, ""),
            (9.0, BmBoxState.END, ""),
        ],
    )
    cl = _states(
        Machine.CLIENT,
        [
            (0.0, ClientState.WAITING_GOAL, ""),
            (1.1, ClientState.EXECUTING_GOAL, ""),
            (3.9, ClientState.COMPLETED_GOAL, "{}"),
            (4.1, ClientState.WAITING_GOAL, ""),
            (5.2, ClientState.EXECUTING_GOAL, ""),
        ],
    )
    rb = _states(
        Machine.REFBOX,
        [(0.0, RefBoxState.EXECUTING_GOAL, ""), (8.9, RefBoxState.END, "reason: timeout")],
    )
    moments = from_states(bm, cl, rb)
    # Segment 0: from the BmBox EXECUTING_GOAL (1.2 s) to the Client COMPLETED_GOAL (3.9 s).
    assert (moments.start_ns - T0).tolist() == [1_200_000_000]
    assert (moments.end_ns - T0).tolist() == [3_900_000_000]
    assert moments.goal_payload == "waypoints: []"
    unreached = unreached_reasons(moments, 3, rb)
    assert len(unreached) == 2 and "timeout" in unreached[0]
    marker = _stream([0.0, 10.0], [[0, 0, 0], [0, 0, 0]], [0.0, 0.0])
    goal = GoalList(((0.0, 0.0, 0.0), (1.0, 0.0, 0.0), (2.0, 0.0, 0.0)), source="g")
    result = compute(
        goal, identity_transform(), marker, moments, max_gap_s=20.0, unreached=unreached
    )
    assert [s.status for s in result.segments] == ["ok", "unreached", "unreached"]
    assert result.timeout_segments == 2 and len(result.failures) == 2
    assert result.execution_time == pytest.approx(2.7, abs=1e-9)
    # An END with no reason still ends the benchmark there, but not as a timeout.
    rb_normal = _states(Machine.REFBOX, [(8.9, RefBoxState.END, "")])
    plain = from_states(bm, cl, rb_normal)
    reasons = unreached_reasons(plain, 3)
    assert reasons == (
        "segment 1: not completed (the benchmark ended without a RefBox reason)",
        "segment 2: waypoint never reached (the benchmark ended without a RefBox reason)",
    )
    result = compute(goal, identity_transform(), marker, plain, max_gap_s=20.0, unreached=reasons)
    assert result.timeout_segments == 0 and len(result.failures) == 2
