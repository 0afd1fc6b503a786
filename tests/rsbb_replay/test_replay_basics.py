"""The replays' Python 2 emulation and tf buffer, on values worked out by hand."""

from __future__ import annotations

import math

import pytest

from tests.helpers.rsbb_replay.hand import MS, T0, S, yaw_quat
from tests.helpers.rsbb_replay.py2 import (
    dump_none,
    dump_pose2d,
    euler_yaw,
    py2_round,
    py2_str,
    to_sec,
)
from tests.helpers.rsbb_replay.tf2 import Buffer, TfError


def test_python2_round_rounds_ties_away_from_zero() -> None:
    # 100 - 51/400*100 is exactly 87.25: Python 2 rounded it to 87.3, Python 3 to 87.2.
    x = 100 - 51 / 400.0 * 100
    assert x == 87.25
    assert py2_round(x, 1) == 87.3
    assert round(x, 1) == 87.2
    assert py2_round(0.125, 2) == 0.13  # an exact tie (0.125 is a binary fraction)
    assert py2_round(-0.125, 2) == -0.13
    # 2.675 is stored as 2.67499999999999982236431605997495353221893310546875: no tie.
    assert py2_round(2.675, 2) == 2.67
    assert py2_round(2 / 3.0 * 100, 2) == 66.67


def test_python2_str_of_floats() -> None:
    assert py2_str(60.0) == "60.0"
    assert py2_str(66.67) == "66.67"
    assert py2_str(100.0) == "100.0"
    assert (
        py2_str(0.1 + 0.2) == "0.3"
    )  # 12 significant digits, where repr gives 0.30000000000000004
    assert py2_str(1e16) == "1e+16"
    assert py2_str(1.0 / 3) == "0.333333333333"


def test_duration_to_sec_adds_seconds_and_nanoseconds() -> None:
    assert to_sec(41_200_000_000) == 41.0 + 200_000_000 / 1e9
    assert to_sec(-500_000_000) == -1.0 + 0.5  # genpy keeps nsecs in [0, 1e9)
    assert to_sec(0) == 0.0


def test_pyyaml_dumps_of_a_pose2d_and_of_none() -> None:
    assert dump_pose2d(-2.125, -1.607, 1.558) == (
        "!!python/object/new:geometry_msgs.msg._Pose2D.Pose2D\nstate: [-2.125, -1.607, 1.558]\n"
    )
    assert dump_pose2d(1, 0, 0) == (
        "!!python/object/new:geometry_msgs.msg._Pose2D.Pose2D\nstate: [1, 0, 0]\n"
    )
    assert dump_none() == "null\n...\n"


def test_euler_yaw() -> None:
    assert euler_yaw((0.0, 0.0, 0.0, 1.0)) == 0.0
    assert euler_yaw((0.0, 0.0, 1.0, 0.0)) == math.pi  # atan2(+0, -1)
    assert euler_yaw(yaw_quat(0.5)) == pytest.approx(0.5, abs=1e-15)
    assert euler_yaw((0.0, 0.0, 0.0, 2.0)) == 0.0  # not normalised: normalised first
    # 90 degrees of pitch: gimbal lock, yaw 0
    assert euler_yaw((0.0, math.sin(math.pi / 4), 0.0, math.cos(math.pi / 4))) == 0.0


def test_tf_interpolates_and_refuses_to_extrapolate() -> None:
    buf = Buffer()
    buf.add("testbed_origin", "a", T0, T0 + MS, ((0.0, 0.0, 0.0), yaw_quat(0.0)))
    buf.add("testbed_origin", "a", T0 + 100 * MS, T0 + 101 * MS, ((1.0, 2.0, 0.0), yaw_quat(0.4)))
    (x, y, _), q = buf.lookup("testbed_origin", "a", T0 + 25 * MS, T0 + S)
    assert (x, y) == (0.25, 0.5)
    assert euler_yaw(q) == pytest.approx(0.1, abs=1e-15)  # slerp at a quarter
    with pytest.raises(TfError):
        buf.lookup("testbed_origin", "a", T0 + 200 * MS, T0 + S)  # after the newest
    with pytest.raises(TfError):
        buf.lookup("testbed_origin", "a", T0 - 1, T0 + S)  # before the oldest
    with pytest.raises(TfError):  # the second sample has not arrived at this clock
        buf.lookup("testbed_origin", "a", T0 + 25 * MS, T0 + 50 * MS)


def test_tf_chains_and_latest_common_time() -> None:
    buf = Buffer()
    for k in range(11):
        t = T0 + k * 10 * MS
        buf.add("testbed_origin", "table", t, t, ((1.0, 0.0, 0.0), yaw_quat(math.pi)))
    for k in range(8):
        t = T0 + k * 10 * MS
        buf.add("testbed_origin", "object", t, t, ((3.0, 1.0, 0.5), yaw_quat(0.0)))
    assert buf.latest_common_time("table", "object", T0 + S) == T0 + 70 * MS
    (x, y, z), q = buf.lookup("table", "object", 0, T0 + S)
    # the object 2 m ahead and 1 m left of a table turned by pi: (-2, -1) in the table's frame
    assert (x, y, z) == pytest.approx((-2.0, -1.0, 0.5), abs=1e-15)
    assert abs(euler_yaw(q)) == pytest.approx(math.pi, abs=1e-12)


def test_tf_keeps_ten_seconds() -> None:
    buf = Buffer()
    buf.add("testbed_origin", "a", T0, T0, ((0.0, 0.0, 0.0), yaw_quat(0.0)))
    buf.add("testbed_origin", "a", T0 + 12 * S, T0 + 12 * S, ((1.0, 0.0, 0.0), yaw_quat(0.0)))
    # across a 12 s gap the old sample was pruned when the new one arrived
    assert buf.can_transform("testbed_origin", "a", T0 + 6 * S, T0 + 11 * S) is False
    assert buf.can_transform("testbed_origin", "a", T0, T0 + 11 * S) is True
    assert buf.can_transform("testbed_origin", "a", T0 + 6 * S, T0 + 13 * S) is False
