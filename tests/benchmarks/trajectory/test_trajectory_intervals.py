"""The trajectory interval sources against numbers computed here: the GT noise measured on a
moving and on a still body, and the offset's spread."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from ertools.benchmarks.common.clocks import OffsetEstimate
from ertools.benchmarks.trajectory.intervals import mocap_sigma, offset_spread
from ertools.cli.main import main
from ertools.geometry import quat_from_yaw
from ertools.streams import PoseStream

T0 = 1_448_000_000 * 10**9


def _stream(xyz: np.ndarray, yaw: np.ndarray) -> PoseStream:
    t = T0 + np.round(np.arange(len(yaw)) * 1e9 / 120).astype(np.int64)
    return PoseStream(t, xyz, quat_from_yaw(yaw), "world", "body", "gt")


def test_noise_of_a_moving_body_from_second_differences() -> None:
    rng = np.random.default_rng(2)
    s = np.arange(12_000) / 120.0
    w = 2 * math.pi / 20
    xyz = np.column_stack([1.6 * np.cos(w * s), np.sin(w * s), 0.4 + 0 * s])
    yaw = np.arctan2(np.cos(w * s), -1.6 * np.sin(w * s))
    noisy = _stream(xyz + rng.normal(0.0, 2e-4, xyz.shape), yaw + rng.normal(0.0, 1e-3, s.size))
    got = mocap_sigma(noisy)
    # 36,000 second differences; the MAD's relative sd is ~1.7 / sqrt(36000) < 1%: 5% is wide
    assert got.position == pytest.approx(2e-4, rel=0.05)
    assert got.yaw == pytest.approx(1e-3, rel=0.05)
    assert got.measured and "second differences" in got.note


def test_noise_of_a_still_body_from_its_stationary_phase() -> None:
    rng = np.random.default_rng(3)
    n = 2400
    xyz = np.array([0.5, 0.2, 0.3]) + rng.normal(0.0, 3e-4, (n, 3))
    got = mocap_sigma(_stream(xyz, np.zeros(n)))
    # epsilon / sqrt(pi) of 2,399 pairs: a few percent
    assert got.position == pytest.approx(3e-4, rel=0.08)
    assert "stationary" in got.note


def test_offset_spread_is_the_least_squares_standard_error() -> None:
    rng = np.random.default_rng(6)
    n = 500
    vel = rng.normal(0.0, 0.4, (n, 3))
    resid = rng.normal(0.0, 0.01, (n, 3))
    audit = OffsetEstimate(2_000_000, 9_000_000, 5 * 10**9, n, 0.01, 0.02)
    sd, centre = offset_spread(resid, np.zeros((n, 3)), vel, audit, 1_000_000)
    # independent residuals r: the least-squares step sum(v.r) / sum|v|^2 has sd
    # sigma_r sqrt(sum |v|^2) / sum |v|^2 = 0.01 / sqrt(sum |v|^2)
    assert sd == pytest.approx(0.01 / math.sqrt(float(np.sum(vel**2))), rel=0.1)
    assert centre == pytest.approx(0.001)


SAMPLE = Path(__file__).resolve().parents[3] / "sample_bags" / "robotlog"
SAMPLE_ROBOT = SAMPLE / "FBM2H_201511201200_homer.bag"
TOP_LEVEL = ("position_error", "orientation_error", "rmse", "median", "max")


def _scored(capsys: pytest.CaptureFixture[str], *extra: str) -> tuple[dict, list[str]]:
    argv = ["score", "trajectory", str(SAMPLE_ROBOT), str(SAMPLE), "--format", "json", *extra]
    assert main(argv) == 0
    captured = capsys.readouterr()
    return json.loads(captured.out), captured.err.splitlines()


def test_a_score_outside_its_interval_says_why(capsys: pytest.CaptureFixture[str]) -> None:
    """The sample robot's clock runs 0.349 s ahead: scored at offset 0, its mean error is
    147 mm, while the intervals are of the score at the offset the data supports (17 mm).
    A referee is told so, not left with `146.58 mm [17.53, 18.33]`."""
    out, err = _scored(capsys)
    outside = [
        k for k in TOP_LEVEL if not out[f"{k}_interval"][0] <= out[k] <= out[f"{k}_interval"][1]
    ]
    assert outside  # the case exists: the clock offset not applied moves every interval
    shift_ms = out["clock_audit"]["estimated_offset"] * 1000
    assert shift_ms == pytest.approx(-349.0, abs=1.0)  # sample_bags/README.md: 0.35 s ahead
    (note,) = [w for w in out["warnings"] if "outside" in w]
    assert set(outside) <= set(note.split(" outside ")[0].split(", "))
    assert f"({shift_ms:+.1f} ms from the one applied)" in note
    assert f"ertools: warning: {note}" in err
    # scored at that offset, every score lies inside its interval and nothing is said
    out, err = _scored(capsys, "--offset", "auto", "--apply-offset")
    assert all(out[f"{k}_interval"][0] <= out[k] <= out[f"{k}_interval"][1] for k in TOP_LEVEL)
    assert not [w for w in out["warnings"] if "outside" in w]
