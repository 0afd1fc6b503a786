"""``ertools acquire transform`` on a simulated robot standing on the testbed origin."""

from __future__ import annotations

import math
import re
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml
from scipy.spatial.transform import Rotation
from scipy.stats import chi2

from ertools.cli.main import main
from ertools.configs.transform import SPREAD_KEY, load_transform, transform_yaml
from ertools.errors import ConfigError
from ertools.simulator.mocap import MocapNoise, frame_times, publish_mocap, simulate_mocap
from ertools.simulator.writer import BagWriter

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
    # Listing 11's keys first, as before; the acquisition's spread after them
    assert list(data) == [
        "robot_info",
        "transform_timestamp",
        "marker_to_robot_transform",
        "robot_to_marker_transform",
        "acquisition_spread",
    ]
    assert path.read_text().startswith(transform_yaml(replace(tr, spread=None)))
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


# The simulated mocap's noise (origin_bag): white, per world axis (isotropic, so per marker
# axis too) and as a rotation vector about the marker's axes.
SIGMA_M, SIGMA_RAD = 2e-4, 5e-4


def test_the_file_carries_the_measured_spread(
    origin_bag: Path, tmp_path: Path, capsys: Any
) -> None:
    """The written spread is the known noise: with n white samples, (n - 1) s^2 / sigma^2 is
    chi-square with n - 1 degrees of freedom, so each of the six standard deviations lies in
    sigma * sqrt(chi2(p; n - 1) / (n - 1)) for p = 1e-4 and 1 - 1e-4 (the six together fail
    by chance 1.2e-3 of the time; the seed is fixed, so never in practice)."""
    code, _, err = _acquire(capsys, str(origin_bag), "--team", "homer", "--out-dir", str(tmp_path))
    assert code == 0, err
    tr = load_transform(tmp_path / "transform-homer.yaml")
    s = tr.spread
    assert s is not None
    n = s.samples
    assert n >= 300  # ~3.5 s of the 4 s standing at 120 Hz
    low = math.sqrt(chi2.ppf(1e-4, n - 1) / (n - 1))
    high = math.sqrt(chi2.ppf(1 - 1e-4, n - 1) / (n - 1))
    for got in s.position_std:
        assert SIGMA_M * low <= got <= SIGMA_M * high
    for got in s.rotation_std:
        assert SIGMA_RAD * low <= got <= SIGMA_RAD * high
    # white noise: the pooled lag-1 autocorrelation of six series is ~N(0, 1/(6n)); 4 sd of
    # it leaves n (1 - rho) / (1 + rho) at least this many of the n samples
    rho = 4.0 / math.sqrt(6 * n)
    assert n * (1 - rho) / (1 + rho) - 1 <= s.effective_samples <= n
    data = yaml.safe_load((tmp_path / "transform-homer.yaml").read_text())
    assert data[SPREAD_KEY]["samples"] == n


def test_a_file_without_spread_and_a_malformed_one(tmp_path: Path) -> None:
    body = (
        "robot_info: t\ntransform_timestamp: 0\n"
        "marker_to_robot_transform:\n- [0.1, 0.0, -0.8]\n- [0.0, 0.0, 0.0, 1.0]\n"
    )
    path = tmp_path / "transform-t.yaml"
    path.write_text(body)
    assert load_transform(path).spread is None  # a hand-written file: the stated default
    path.write_text(body + f"{SPREAD_KEY}:\n  position_std: [0.001, 0.001]\n")
    with pytest.raises(ConfigError, match="missing rotation_std, samples"):
        load_transform(path)
    path.write_text(
        body + f"{SPREAD_KEY}:\n  position_std: [0.001, 0.001, 0.001]\n"
        "  rotation_std: [0.001, 0.001, 0.001]\n  samples: 0\n"
    )
    with pytest.raises(ConfigError, match="samples: expected a whole number >= 1"):
        load_transform(path)
