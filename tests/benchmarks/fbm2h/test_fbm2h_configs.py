"""The FBM2@Home config formats: goal list, transform file, timing file."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from ertools.benchmarks.fbm2h.goal import goal_from_payload, parse_goal
from ertools.benchmarks.fbm2h.timing import parse_timing
from ertools.configs._yaml import parse_yaml
from ertools.configs.transform import (
    MarkerTransform,
    load_transform,
    parse_transform,
    transform_yaml,
)
from ertools.errors import ConfigError

S = 1_000_000_000


def test_goal_payload_without_goal_key_and_mapping_waypoints() -> None:
    # The 2015 BmBox sent yaml.dump(goal parameter): no "goal:" key; early configs used
    # {x, y, theta} mappings.
    g = goal_from_payload(
        "num_waypoints: 2\nwaypoints:\n- [1.0, 2.0, 0.5]\n- {x: 3, y: 4, theta: -1}\n", "p"
    )
    assert g.as_array().tolist() == [[1.0, 2.0, 0.5], [3.0, 4.0, -1.0]]
    assert g.starting_pose is None and g.timeout_time is None


def test_goal_rejects_non_numbers() -> None:
    with pytest.raises(ConfigError, match=r"waypoints\[0\]"):
        parse_goal({"goal": {"waypoints": [[1, "a", 0]]}}, "g.yaml")
    with pytest.raises(ConfigError, match="not a finite"):
        parse_goal({"goal": {"waypoints": [[1, float("nan"), 0]]}}, "g.yaml")


def test_2015_style_transform_file_with_extra_keys() -> None:
    # Shape of the files the 2015 acquirer dumped with rosparam: extra keys, no timestamp.
    r = Rotation.from_euler("xyz", [0.01, -0.02, 0.4])
    t = np.array([0.25, -0.01, -0.8])
    inv_r = r.inv()
    inv_t = -inv_r.apply(t)
    data = {
        "marker_to_robot_transform": [t.tolist(), r.as_quat().tolist()],
        "marker_to_robot_transform_2D": [0.1, 0.2, 0.3],
        "mocap": {"rigid_bodies": {"3": {"child_frame_id": "robot_markerset"}}},
        "robot_info": "team",
        "robot_pose": {"theta": 0.0, "x": 0.0, "y": 0.0},
        "robot_to_marker_transform": [inv_t.tolist(), inv_r.as_quat().tolist()],
    }
    tr = parse_transform(data, "transform-team.yaml")
    assert np.asarray(tr.translation) == pytest.approx(t, abs=1e-15)
    assert tr.robot_info == "team" and tr.timestamp == ""


def test_transform_yaml_round_trip() -> None:
    q = Rotation.from_euler("xyz", [0.02, 0.0, -2.9]).as_quat()
    quat = (float(q[0]), float(q[1]), float(q[2]), float(q[3]))
    tr = MarkerTransform("homer", "2015-11-20_10:00:00", (0.1, -0.2, -0.7), quat, "x")
    text = transform_yaml(tr)
    back = parse_transform(parse_yaml(text), "t.yaml")  # also checks the inverse written
    # written to 9 decimals (ertools.serialize): within half a unit of the 9th decimal (the
    # quaternion is normalised on reading, which moves it by ~1e-16)
    assert back.translation == pytest.approx(tr.translation, abs=5e-10 + 1e-15)
    assert back.quat_xyzw == pytest.approx(tr.quat_xyzw, abs=5e-10 + 1e-15)
    assert back.timestamp == "2015-11-20_10:00:00" and back.robot_info == "homer"
    # Robot at the origin <=> marker at inverse(T_marker_robot): composing gives identity.
    t_inv, q_inv = tr.inverse()
    rot = Rotation.from_quat(q_inv) * Rotation.from_quat(tr.quat_xyzw)
    assert rot.magnitude() == pytest.approx(0.0, abs=1e-12)
    moved = np.asarray(t_inv) + Rotation.from_quat(q_inv).apply(tr.translation)
    assert moved == pytest.approx([0, 0, 0], abs=1e-12)


def test_identity_listing_12_file() -> None:
    path = Path(__file__).resolve().parents[3] / "configs" / "transform-identity.yaml"
    tr = load_transform(path)
    assert tr.is_identity and tr.robot_info == "identity" and tr.timestamp == "0"


def test_timing_resolves_relative_and_epoch_seconds() -> None:
    start = 1_445_609_740 * S
    timing = parse_timing({"reached_waypoint_timing": [{"p0": 0.0}, {"p1": 1.5}]}, "t")
    assert (timing.resolve(start, start + 2 * S) - start).tolist() == [0, 1_500_000_000]
    epoch = parse_timing(
        {"reached_waypoint_timing": [{"p0": 1_445_609_741.0}, {"p1": 1_445_609_741.25}]}, "t"
    )
    # Epoch seconds as float64 carry ~0.2 us of rounding at 1.4e9 s: compare to 1 us.
    got = epoch.resolve(start, start + 2 * S) - start
    assert got.tolist() == pytest.approx([S, 1_250_000_000], abs=1000)


@pytest.mark.parametrize(
    ("data", "needle"),
    [
        ({}, "missing key"),
        ({"reached_waypoint_timing": [{"p0": 0.0}]}, "at least two"),
        ({"reached_waypoint_timing": [{"p0": 0.0, "p1": 1.0}, {"p2": 2.0}]}, "one 'pK"),
        ({"reached_waypoint_timing": [{"p0": 0.0}, {"p1": "soon"}]}, "not a number"),
        ({"reached_waypoint_timing": [{"p0": 1.0}, {"p1": 1.0}]}, "must increase"),
        ({"reached_waypoint_timing": [{"p0": 0.0}, {"p1": math.inf}]}, "not a finite number"),
    ],
)
def test_bad_timing(data: object, needle: str) -> None:
    with pytest.raises(ConfigError, match=needle):
        parse_timing(data, "t.yaml")
