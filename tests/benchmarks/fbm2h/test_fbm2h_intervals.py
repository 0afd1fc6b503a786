"""FBM2@Home's perturbed scorer (issue 28): the spread of each source against the one
computed by hand for a robot far from its waypoint (where the distance is linear in the
noise)."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml

import ertools
from ertools.benchmarks.common.uncertainty import (
    MOCAP_NOISE,
    TIME_ASSOCIATION,
    TRANSFORM,
    Source,
)
from ertools.benchmarks.fbm2h import sample as sim
from ertools.benchmarks.fbm2h.config import Fbm2hOptions
from ertools.benchmarks.fbm2h.goal import parse_goal
from ertools.benchmarks.fbm2h.intervals import (
    DEFAULT_EPSILON_M,
    Model,
    Moments,
    intervals,
    measure_model,
    perturbed_scores,
    with_intervals,
)
from ertools.benchmarks.fbm2h.pipeline import compute
from ertools.benchmarks.fbm2h.runs import ReachedMoments
from ertools.configs.transform import SPREAD_KEY, parse_transform
from ertools.streams import PoseStream

N = 20_000  # draws: the sd of a sample sd is 1/sqrt(2N) = 0.5% of it


def _moments(lever: tuple[float, float, float], averaging: float = 1.0) -> Moments:
    # the robot 1 m from its waypoint along x, heading 0.2 rad off the waypoint's theta
    return Moments(
        robot=np.array([[1.0, 0.0, 0.2]]),
        target=np.array([[0.0, 0.0, 0.0]]),
        lever=np.array([lever]),
        heading=np.array([0.0]),
        averaging=np.array([averaging]),
        velocity=np.array([[0.5, 0.0, 0.0]]),
    )


def _model(sigma: float, tilt: float, yaw: float, half: float) -> Model:
    return Model(sigma, tilt, yaw, half, ())


def _sd(m: Moments, model: Model, source: str) -> tuple[float, float]:
    d = perturbed_scores(
        m,
        model,
        np.random.default_rng(1),
        frozenset({source}),
        N,
        orientation_2015=False,
        divide_by=1,
    )
    return float(np.std(d[:, 2])), float(np.std(d[:, 3]))


def test_position_noise_is_averaged_by_interpolation() -> None:
    # radial component of isotropic noise: sigma; interpolated at w = 0.5: sigma / sqrt(2)
    sd, _ = _sd(_moments((0.0, 0.0, 0.0), math.sqrt(0.5)), _model(2e-4, 0, 0, 0), MOCAP_NOISE)
    assert sd == pytest.approx(2e-4 / math.sqrt(2), rel=0.03)


def test_tilt_noise_swings_a_vertical_lever() -> None:
    # the robot 0.85 m below the marker: a tilt of r rad about y moves it r * 0.85 along x
    sd, angle_sd = _sd(_moments((0.0, 0.0, -0.85)), _model(0.0, 5e-4, 1e-3, 0), MOCAP_NOISE)
    assert sd == pytest.approx(0.85 * 5e-4, rel=0.03)
    assert angle_sd == pytest.approx(1e-3, rel=0.03)


def test_time_association_is_velocity_times_half_a_frame() -> None:
    # 0.5 m/s along the error direction, uniform +-4.17 ms: sd = 0.5 * 4.17e-3 / sqrt(3)
    sd, _ = _sd(_moments((0.0, 0.0, 0.0)), _model(0, 0, 0, 1 / 240), TIME_ASSOCIATION)
    assert sd == pytest.approx(0.5 / 240 / math.sqrt(3), rel=0.03)


def test_transform_error_is_common_to_every_segment() -> None:
    # two segments with the same geometry: the transform's offset moves both alike, so the
    # mean distance spreads as one segment does (independent noise would give 1/sqrt(2))
    one = _moments((0.0, 0.0, 0.0))
    two = Moments(*(np.repeat(getattr(one, f), 2, axis=0) for f in Moments.__dataclass_fields__))
    d = perturbed_scores(
        two,
        _model(2e-4, 0, 0, 0),
        np.random.default_rng(2),
        frozenset({TRANSFORM}),
        N,
        orientation_2015=False,
        divide_by=2,
    )
    assert np.std(d[:, 0]) == pytest.approx(2e-4, rel=0.03)
    e = perturbed_scores(
        two,
        _model(2e-4, 0, 0, 0),
        np.random.default_rng(2),
        frozenset({MOCAP_NOISE}),
        N,
        orientation_2015=False,
        divide_by=2,
    )
    assert np.std(e[:, 0]) == pytest.approx(2e-4 / math.sqrt(2), rel=0.03)


def test_interval_width_and_shares() -> None:
    # distance 1 m, noise sigma per axis: the 95% interval is +-1.96 sigma around it
    m = _moments((0.0, 0.0, 0.0))
    model = Model(2e-4, 0, 1e-3, 0, (Source(MOCAP_NOISE, 2e-4, "m", True),))
    found = intervals(
        m,
        [0],
        [1.0, 0.2, 1.0, 0.2],
        model,
        orientation_2015=False,
        divide_by=1,
        draws=N,
        seed=0,
        confidence=0.95,
    )
    assert found.distance[0] is not None
    half = (found.distance[0].high - found.distance[0].low) / 2
    assert half == pytest.approx(1.959964 * 2e-4, rel=0.03)
    assert found.uncertainty.shares["position_accuracy"] == {MOCAP_NOISE: 1.0}


def test_a_robot_never_still_gets_the_stated_defaults() -> None:
    t = np.arange(500, dtype=np.int64) * 8_333_333  # 120 Hz, moving 0.6 m/s throughout
    xyz = np.column_stack([np.linspace(0.0, 5.0, 500), np.zeros(500), np.zeros(500)])
    model = measure_model(PoseStream(t, xyz, np.tile([0.0, 0.0, 0.0, 1.0], (500, 1))))
    assert model.sigma == pytest.approx(DEFAULT_EPSILON_M / math.sqrt(math.pi))
    mocap, timing, transform = model.sources
    assert not mocap.measured and "default" in mocap.note
    assert timing.measured and timing.value == pytest.approx(8_333_333 / 2e9)
    assert not transform.measured


def test_draws_0_leaves_the_result_as_it_was() -> None:
    run = sim.simulate(0)
    pub = run.bodies[sim.BODY]
    marker = PoseStream(pub.t_header_ns, pub.xyz, pub.quat_xyzw)
    goal = parse_goal(yaml.safe_load(run.configs["fbm2h_goal.yaml"]))
    transform = parse_transform(yaml.safe_load(run.configs[f"transform-{sim.TEAM}.yaml"]))
    segs = run.truth["segments"]
    moments = ReachedMoments(
        "states",
        np.array([s["start_ns"] for s in segs]),
        np.array([s["end_ns"] for s in segs]),
        tuple("" for _ in segs),
    )
    plain = compute(goal, transform, marker, moments)
    assert with_intervals(plain, marker, transform, moments, Fbm2hOptions(draws=0)) is plain
    full = with_intervals(plain, marker, transform, moments, Fbm2hOptions(draws=50))
    assert full.intervals is not None
    listing = list(plain.to_dict())
    assert list(full.to_dict())[: len(listing)] == listing
    assert full.position_accuracy == plain.position_accuracy  # the score itself unchanged


SAMPLE = Path(__file__).resolve().parents[3] / "sample_bags" / "fbm2h"


def _score_with_spread(tmp_path: Path, spread: tuple[float, float, int] | None) -> dict[str, Any]:
    """The sample scored with its transform file, carrying ``(position std, rotation std,
    samples)`` as ``ertools acquire transform`` writes it (None: the file as it is)."""
    text = (SAMPLE / "transform-simbot.yaml").read_text()
    if spread is not None:
        p, r, n = spread
        text += (
            f"{SPREAD_KEY}:\n  position_std: [{p}, {p}, {p}]\n  rotation_std: [{r}, {r}, {r}]\n"
            f"  samples: {n}\n  effective_samples: {n}\n"
        )
    transform = tmp_path / "transform-simbot.yaml"
    transform.write_text(text)
    result = ertools.score(
        "fbm2h",
        SAMPLE / "log_fbm2h_mocap_2015-11-20-12-00-00_0.bag",
        goal=SAMPLE / "fbm2h_goal.yaml",
        transform=transform,
        draws=200,
    )
    data: dict[str, Any] = result.to_dict()
    return data


def test_the_transform_source_is_the_acquisitions_spread(tmp_path: Path) -> None:
    """A transform file with the acquisition's spread makes the transform source measured:
    its size the spread over sqrt(samples), its share of the intervals growing with it; a
    file without it keeps the stated default."""
    default = _score_with_spread(tmp_path, None)
    (t_default,) = [s for s in default["uncertainty"]["sources"] if s["name"] == TRANSFORM]
    assert not t_default["measured"] and t_default["note"].startswith("default: ")
    shares = []
    for p_std in (2e-4, 1e-3, 5e-3):
        data = _score_with_spread(tmp_path, (p_std, 2.5 * p_std, 100))
        (t,) = [s for s in data["uncertainty"]["sources"] if s["name"] == TRANSFORM]
        assert t["measured"] is True
        assert t["value"] == pytest.approx(p_std / 10.0, rel=1e-12)  # spread / sqrt(100)
        assert "100 poses" in t["note"]
        # the scores do not move, only their intervals
        assert data["position_accuracy"] == default["position_accuracy"]
        shares.append(data["uncertainty"]["shares"]["position_accuracy"][TRANSFORM])
    assert shares[0] < shares[1] < shares[2]
