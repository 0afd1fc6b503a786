"""``ertools acquire transform`` on a simulated robot standing on the testbed origin."""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml
from scipy.spatial.transform import Rotation

from ertools.cli.main import main
from ertools.configs.transform import load_transform
from ertools.samples.mocap import MocapNoise, frame_times, publish_mocap, simulate_mocap
from ertools.samples.writer import BagWriter

T0 = 1_448_000_000 * 1_000_000_000
# Truth: T_marker_robot (robot centre 0.85 m below the marker set, offset and turned).
M2R_T = np.array([0.12, -0.05, -0.85])
M2R_R = Rotation.from_euler("xyz", [0.02, -0.015, -0.3])


@pytest.fixture(scope="module")
def origin_bag(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """4 s standing on the origin, then 2 s driving 1 m along x."""
    out = tmp_path_factory.mktemp("acquire") / "origin.bag"
    t = frame_times(T0, 6.0)
    s = np.clip((t - T0 - 4_000_000_000) / 2e9, 0.0, 1.0)
    robot_xyz = np.column_stack([s, np.zeros_like(s), np.zeros_like(s)])
    # T_world_marker = T_world_robot * inv(T_marker_robot); the robot frame is not rotated.
    r2m = M2R_R.inv()
    marker_xyz = robot_xyz + (-r2m.apply(M2R_T))
    marker_q = np.tile(r2m.as_quat(), (t.size, 1))
    pub = simulate_mocap(
        t,
        marker_xyz,
        marker_q,
        rng=np.random.default_rng(5),
        noise=MocapNoise(sigma_m=2e-4, sigma_rad=5e-4),
    )
    with BagWriter(out, "ros1") as bag:
        publish_mocap(bag, "fbm2h", "robot_at_home", pub)
    return out


def _acquire(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    code = main(["acquire", "transform", *argv])
    out = capsys.readouterr()
    return code, out.out, out.err


def test_detected_window(origin_bag: Path, tmp_path: Path, capsys: Any) -> None:
    code, out, err = _acquire(
        capsys, str(origin_bag), "--team", "homer", "--out-dir", str(tmp_path)
    )
    assert code == 0, err
    path = tmp_path / "transform-homer.yaml"
    assert out == path.read_text()
    tr = load_transform(path)  # also checks robot_to_marker is the inverse
    # Averaging ~400 samples: position noise 0.2 mm and 0.5 mrad over a 0.86 m lever arm shrink
    # to ~0.03 mm; 0.5 mm is a wide margin.
    assert np.asarray(tr.translation) == pytest.approx(M2R_T, abs=5e-4)
    angle = (Rotation.from_quat(tr.quat_xyzw).inv() * M2R_R).magnitude()
    assert angle < 5e-4
    assert tr.robot_info == "homer"
    data = yaml.safe_load(path.read_text())
    assert list(data) == [
        "robot_info",
        "transform_timestamp",
        "marker_to_robot_transform",
        "robot_to_marker_transform",
    ]
    assert re.fullmatch(r"2015-11-20_\d\d:\d\d:\d\d", str(data["transform_timestamp"]))
    assert "spread: position" in err and "warning" not in err


def test_given_window_on_motion_warns(origin_bag: Path, tmp_path: Path, capsys: Any) -> None:
    code, _, err = _acquire(
        capsys,
        str(origin_bag),
        "--team",
        "homer",
        "--out-dir",
        str(tmp_path),
        "--at",
        "4.5",
        "--duration",
        "1",
    )
    assert code == 0
    assert "moved during the window" in err


def test_existing_file_needs_force(origin_bag: Path, tmp_path: Path, capsys: Any) -> None:
    (tmp_path / "transform-homer.yaml").write_text("keep me\n")
    code, _, err = _acquire(capsys, str(origin_bag), "--team", "homer", "--out-dir", str(tmp_path))
    assert code == 1 and "--force" in err
    assert (tmp_path / "transform-homer.yaml").read_text() == "keep me\n"


def test_bad_team_name(origin_bag: Path, tmp_path: Path, capsys: Any) -> None:
    code, _, err = _acquire(capsys, str(origin_bag), "--team", "a b", "--out-dir", str(tmp_path))
    assert code == 1 and "team name" in err
