"""The mocap config (seed Listings 2/3): IDs, topics under a namespace, clear errors."""

from __future__ import annotations

from pathlib import Path

import pytest

from ertools.configs.mocap import load_mocap_config, normalize_namespace, parse_mocap_config
from ertools.errors import ConfigError

pytestmark = pytest.mark.xdist_group("timing")

REPO = Path(__file__).resolve().parents[2]


def test_listing_2_home_config() -> None:
    cfg = load_mocap_config(REPO / "configs" / "mocap_home.yaml")
    # Listing 2 leaves IDs 3, 6 and 7 active (1, 2, 4, 5 commented out).
    assert [b.body_id for b in cfg.bodies] == [3, 6, 7]
    robot = cfg.by_id()[3]
    assert robot.pose_topic("/fbm2h") == "/fbm2h/robot_at_home/pose"
    assert robot.pose2d_topic("fbm2h/") == "/fbm2h/robot_at_home/pose2d"
    assert (robot.child_frame_id, robot.parent_frame_id) == ("robot_at_home", "world")
    assert robot.pose_topic("") == "/robot_at_home/pose"
    assert cfg.group == "224.0.0.1" and cfg.data_port == 1511
    assert "/tf" in cfg.topics("/fbm2h")


def test_listing_3_work_config() -> None:
    cfg = load_mocap_config(REPO / "configs" / "mocap_work.yaml")
    assert [b.body_id for b in cfg.bodies] == [1, 2, 4, 5]
    assert cfg.by_id()[4].pose_topic("/fbm3w") == "/fbm3w/robot/pose"
    assert cfg.by_id()[5].child_frame_id == "robot_at_work"


def test_namespace_and_absolute_topics() -> None:
    assert normalize_namespace("/") == "" and normalize_namespace(" fbm1h/ ") == "/fbm1h"
    cfg = parse_mocap_config(
        "rigid_bodies: {'9': {pose: /abs/pose, child_frame_id: x}}\n"
        "optitrack_config: {multicast_address: 239.255.42.99, data_port: 1600}"
    )
    assert cfg.bodies[0].pose_topic("/ns") == "/abs/pose"
    assert cfg.bodies[0].pose2d_topic("/ns") is None
    assert (cfg.group, cfg.data_port) == ("239.255.42.99", 1600)


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("rigid_bodies:\n'3':\n  pose: a/pose\n", "indent them"),  # Listing 2 as printed
        ("rigid_bodies: {}", "no entries"),
        ("bodies: {}", "rigid_bodies"),
        ("rigid_bodies: {'x': {pose: a}}", "not a Motive ID"),
        ("rigid_bodies: {'1': {pose: a, colour: red}}", "unknown key"),
        ("rigid_bodies: {'1': {parent_frame_id: world}}", "publishes nothing"),
        ("rigid_bodies: {'1': {pose: a}, '01': {pose: b}}", "twice"),
        ("rigid_bodies: {'1': {pose: a}, '2': {pose: a}}", "used by two bodies"),
        ("rigid_bodies: {'1': {pose: 'a b'}}", "without spaces"),
        ("rigid_bodies: [", "malformed"),
    ],
)
def test_bad_configs_say_what_is_wrong(text: str, message: str) -> None:
    with pytest.raises(ConfigError, match=message):
        parse_mocap_config(text)
