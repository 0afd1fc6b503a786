"""Properties of the FBM2@Home errors and of the marker-to-robot composition."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from ertools.benchmarks.fbm2h.formula import robot_poses_at, segment_errors
from ertools.streams import PoseStream

pytestmark = pytest.mark.slow

angles = st.floats(-math.pi, math.pi, allow_nan=False)
coords = st.floats(-5.0, 5.0, allow_nan=False)


@given(angles, angles, coords, coords)
def test_wrapped_error_in_range_and_2015_differs_only_in_sign(
    yaw: float, theta: float, dx: float, dy: float
) -> None:
    robot = np.array([[dx, dy, yaw]])
    target = np.array([[0.0, 0.0, theta]])
    e = segment_errors(robot, target)
    e15 = segment_errors(robot, target, orientation_2015=True)
    assert 0.0 <= e.orientation[0] <= math.pi
    # 2015's atan2(sin|d|, cos|d|) is |d| wrapped to (-pi, pi]: same magnitude, maybe negative.
    assert abs(abs(e15.orientation[0]) - e.orientation[0]) < 1e-9
    assert abs(e.distance[0] - math.hypot(dx, dy)) < 1e-12


@settings(max_examples=50)
@given(coords, coords, angles, st.lists(st.floats(-1, 1), min_size=6, max_size=6))
def test_marker_pose_composed_back_gives_the_robot(
    x: float, y: float, yaw: float, m2r: list[float]
) -> None:
    # Any marker-to-robot transform: a marker placed at robot * inv(T) gives the robot back.
    t_mr = np.array(m2r[:3])
    r_mr = Rotation.from_rotvec(np.array(m2r[3:]) * 0.5)
    robot_r = Rotation.from_euler("z", yaw)
    inv_r = r_mr.inv()
    marker_xyz = np.array([x, y, 0.0]) + robot_r.apply(-inv_r.apply(t_mr))
    marker_q = (robot_r * inv_r).as_quat()
    stream = PoseStream(
        np.array([0, 10], dtype=np.int64),
        np.vstack([marker_xyz, marker_xyz]),
        np.vstack([marker_q, marker_q]),
    )
    got = robot_poses_at(stream, (t_mr, r_mr.as_quat()), np.array([5], dtype=np.int64), 10)
    assert got.ok[0]
    assert np.allclose(got.xyyaw[0, :2], [x, y], atol=1e-9)
    assert abs((got.xyyaw[0, 2] - yaw + math.pi) % (2 * math.pi) - math.pi) < 1e-9
