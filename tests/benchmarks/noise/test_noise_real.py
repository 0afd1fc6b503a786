"""``ertools noise`` on the real 2015 bag, checked against a direct rosbags read."""

from __future__ import annotations

import itertools
import json
import math
from pathlib import Path

import pytest
from rosbags.highlevel import AnyReader

from ertools.cli.main import main

pytestmark = pytest.mark.slow

REAL = Path(__file__).resolve().parents[3] / ".." / "shared" / "real_bags"
BAG = REAL / "log_fbm2h_mocap_2015-10-23-16-15-40_0.bag"
TOPIC = "/fbm2h/robot_at_home/pose2d"


def _pose2d_by_rosbags() -> list[tuple[float, float, float]]:
    with AnyReader([BAG]) as reader:
        conns = [c for c in reader.connections if c.topic == TOPIC]
        return [
            (m.x, m.y, m.theta)
            for m in (reader.deserialize(raw, c.msgtype) for c, _, raw in reader.messages(conns))
        ]


@pytest.mark.real
def test_noise_of_the_real_bag(capsys: pytest.CaptureFixture[str]) -> None:
    if not BAG.exists():
        pytest.skip("../shared/real_bags not present")
    poses = _pose2d_by_rosbags()
    steps = [math.hypot(b[0] - a[0], b[1] - a[1]) for a, b in itertools.pairwise(poses)]
    lost = sum(1 for a, b in itertools.pairwise(poses) if a == b)
    moving = [d for d, a, b in zip(steps, poses, poses[1:], strict=False) if a != b]
    assert main(["noise", str(BAG), "--topic", TOPIC, "--format", "json"]) == 0
    data = json.loads(capsys.readouterr().out)
    # whole recording, as the 2015 tool: counts exact, mean up to float summation order
    assert data["samples"] == len(poses) == 6887
    assert data["lost"] == lost
    assert data["epsilon"] == pytest.approx(sum(moving) / len(moving), abs=1e-12)
    assert (
        main(["noise", str(BAG), "--topic", TOPIC, "--stationary", "auto", "--format", "json"]) == 0
    )
    still = json.loads(capsys.readouterr().out)
    # the robot drives most of the time: the still phases hold far fewer, far shorter steps
    assert 0 < still["samples"] < data["samples"]
    assert still["epsilon"] < data["epsilon"]
