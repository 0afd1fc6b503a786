"""associate (linear, the default rules) against a plain reading of its rules, pose by pose, on
hostile streams (gaps, repeated stamps, tracking lost, robot poses before and after the GT).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation, Slerp

from ertools.benchmarks.trajectory.association import (
    COMPARED,
    GAP,
    TRACKING_LOST,
    UNCOVERED,
    associate,
)
from ertools.geometry import wrap_angle, yaw_from_quat
from ertools.streams import PoseStream
from tests.benchmarks.trajectory.test_trajectory_audit_pairs import MS, gt_and_robot


@pytest.mark.slow
@settings(max_examples=150, deadline=None)
@given(gt_and_robot(), st.sampled_from([100 * MS, 500 * MS]))
def test_linear_association_is_the_plain_rules(
    streams: tuple[PoseStream, PoseStream], max_gap_ns: int
) -> None:
    gt, robot = streams
    got = associate(robot, gt, "linear", max_gap_ns)
    t, rows = gt.t_ns.tolist(), gt.xyz.tolist()
    n = len(t)
    for i, q in enumerate(robot.t_ns.tolist()):
        lo = max([k for k in range(n) if t[k] <= q], default=-1)
        hi = min([k for k in range(n) if t[k] >= q], default=n)
        if lo < 0 or hi >= n:
            status = UNCOVERED
        elif t[hi] - t[lo] > max_gap_ns:
            status = GAP
        elif hi >= 1 and rows[hi - 1] == rows[hi]:  # the 2015 pair: the same position twice
            status = TRACKING_LOST
        else:
            status = COMPARED
        assert int(got.status[i]) == status
        if status != COMPARED:
            assert np.isnan(got.gt_xyz[i]).all() and math.isnan(got.position_error[i])
            continue
        w = (q - t[lo]) / (t[hi] - t[lo]) if t[hi] > t[lo] else 0.0
        at = [rows[lo][k] + w * (rows[hi][k] - rows[lo][k]) for k in range(3)]
        assert got.gt_xyz[i].tolist() == at  # the same operations: equal to the bit
        d = [robot.xyz[i][k] - at[k] for k in range(3)]
        assert float(got.position_error[i]) == math.sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2])
        quats = gt.quat_xyzw[[lo, hi]]
        yaw = float(yaw_from_quat(Slerp([0.0, 1.0], Rotation.from_quat(quats))([w]).as_quat()[0]))
        want = abs(float(wrap_angle(float(yaw_from_quat(robot.quat_xyzw[i])) - yaw)))
        # scipy's and NumPy's trigonometry differ by a few ulps of the angle
        assert float(got.yaw_error[i]) == pytest.approx(want, abs=1e-9)
