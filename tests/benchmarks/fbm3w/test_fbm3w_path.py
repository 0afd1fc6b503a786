"""The 2015 computation on arrays: d_min subsampling, run frame, Eq. (1), invariances."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from ertools.benchmarks.fbm3w.auto_runs import _match
from ertools.benchmarks.fbm3w.config import Fbm3wOptions
from ertools.benchmarks.fbm3w.formula import (
    arc_fractions,
    frame_errors,
    kept_flags,
    run_frame,
    score_path,
    subsample_d_min,
)
from ertools.benchmarks.fbm3w.pipeline import score_paths
from ertools.benchmarks.fbm3w.settings import Fbm3wConfig
from ertools.benchmarks.fbm3w.shapes import builtin_shapes, parse_shape
from ertools.errors import ScoringError
from tests.benchmarks.fbm3w.fbm3w_synth import one_run, place

# the path arithmetic is the subject, not the intervals: no Monte Carlo draws
NO_DRAWS = Fbm3wOptions(draws=0)


def naive_subsample(xy: np.ndarray, d_min: float) -> list[int]:
    """The 2015 mocap_callback rule, one sample at a time."""
    kept = [0]
    for i in range(1, len(xy)):
        last = xy[kept[-1]]
        if math.sqrt((xy[i, 0] - last[0]) ** 2 + (xy[i, 1] - last[1]) ** 2) >= d_min:
            kept.append(i)
    return kept


def test_subsample_by_hand() -> None:
    x = [0.0, 0.1, 0.25, 0.31, 0.35, 0.9, 0.95, 1.25]
    xy = np.column_stack([x, np.zeros(len(x))])
    # 0 kept; 0.1, 0.25 < 0.3 from 0; 0.31 kept; 0.35 is 0.04 from it; 0.9 kept; 0.95 no;
    # 1.25 is 0.35 from 0.9: kept
    assert subsample_d_min(xy, 0.3).tolist() == [0, 3, 5, 7]
    # exactly d_min away counts as moved (2015: >= D_MIN)
    assert subsample_d_min(np.array([[0.0, 0.0], [0.5, 0.0]]), 0.5).tolist() == [0, 1]
    assert subsample_d_min(np.empty((0, 2)), 0.1).tolist() == []
    assert subsample_d_min(np.zeros((5, 2)), 0.0).tolist() == [0, 1, 2, 3, 4]


@pytest.mark.parametrize("sigma", [1e-5, 1e-4, 4e-4, 1e-3])
def test_subsample_equals_the_sequential_rule(sigma: float) -> None:
    rng = np.random.default_rng(5)
    n = 5000
    xy = rng.normal(0.0, sigma, (n, 2))
    xy[:, 0] += np.concatenate([np.zeros(1000), np.linspace(0, 0.1, 3000), np.full(1000, 0.1)])
    assert subsample_d_min(xy, 0.00033).tolist() == naive_subsample(xy, 0.00033)


@pytest.mark.parametrize("sigma", [1e-5, 4e-4])
def test_paths_side_by_side_keep_what_each_keeps_alone(sigma: float) -> None:
    # the intervals' sweep (W columns at once) is the rule of one path, column by column;
    # shorter paths are padded with NaN at the end, never kept
    rng = np.random.default_rng(8)
    n, w = 900, 6
    x = rng.normal(0.0, sigma, (n, w)) + np.linspace(0.0, 0.05, n)[:, None]
    y = rng.normal(0.0, sigma, (n, w))
    x[700:, 2] = y[700:, 2] = np.nan
    d_mins = np.array([0.00033, 0.0001, 0.00033, 0.001, 0.0, 0.00066])
    flags = kept_flags(x, y, d_mins)
    for k in range(w):
        alone = naive_subsample(
            np.column_stack([x[:, k], y[:, k]])[: 700 if k == 2 else n], d_mins[k]
        )
        assert np.flatnonzero(flags[:, k]).tolist() == alone
        assert np.array_equal(
            kept_flags(x[:, k : k + 1], y[:, k : k + 1], d_mins[k : k + 1])[:, 0], flags[:, k]
        )


def test_arc_fractions_and_frame_errors_by_hand() -> None:
    # two kept paths end to end: 3-4-5 steps (L = 10) and one 1 m step
    xk = np.array([0.0, 3.0, 3.0, 1.0, 1.0])
    yk = np.array([0.0, 4.0, 9.0, 1.0, 2.0])
    counts = np.array([3, 2])
    l_norm, total = arc_fractions(xk, yk, counts)
    assert l_norm.tolist() == [0.0, 0.5, 1.0, 0.0, 1.0]
    assert total.tolist() == [10.0, 1.0]
    # path 1 in a frame turned +90 degrees: its step (0, 1) is (1, 0) there; target (1, 0.5)
    target = np.array([[9.0, 9.0], [3.0, 4.0], [3.0, 8.0], [7.0, 7.0], [1.0, 0.5]])
    cos_yaw, sin_yaw = np.array([1.0, 0.0]), np.array([0.0, 1.0])
    err = frame_errors(xk, yk, counts, target, cos_yaw, sin_yaw)
    # each start counts 0; (3, 4) on target; (3, 9) is 1 from (3, 8); (1, 0) is 0.5 from (1, 0.5)
    assert err == pytest.approx([0.0, 0.0, 1.0, 0.0, 0.5], abs=1e-15)


def test_auto_runs_match_is_eq1_in_the_protocol_frame() -> None:
    # --runs auto's protocol-frame error is the score's Eq. (1) on the same path and d_min
    rng = np.random.default_rng(3)
    shape = builtin_shapes()["semi_ellipse"].by_arc_length()
    frame_pts = shape(np.linspace(0.0, 1.0, 400)) + rng.normal(0.0, 2e-4, (400, 2))
    frame_pts[0] = 0.0
    origin, yaw = (0.4, 0.3), -0.7
    world = place(frame_pts, origin, yaw)
    ref = place(np.array([[-0.1, 0.0]]), origin, yaw)[0]
    _, e_frame = _match(world, world[0], ref, shape, 0.001)
    assert e_frame == pytest.approx(score_path(world, ref, shape, 0.001).distance_error, rel=1e-12)


def test_eq1_by_hand() -> None:
    shape = parse_shape("ten", {"x": "0.1*l", "y": "0"})
    frame_pts = np.array([[0.0, 0.0], [0.03, 0.004], [0.06, 0.004], [0.1, 0.0]])
    origin, yaw = (0.7, -0.2), 2.0
    world = place(frame_pts, origin, yaw)
    ref = place(np.array([[-0.05, 0.0]]), origin, yaw)[0]
    s1 = math.hypot(0.03, 0.004)
    s2 = 0.03
    s3 = math.hypot(0.04, 0.004)
    total = s1 + s2 + s3
    e1 = math.hypot(0.03 - 0.1 * s1 / total, 0.004)
    e2 = math.hypot(0.06 - 0.1 * (s1 + s2) / total, 0.004)
    e3 = 0.0  # the last point is at l/L = 1, exactly on the target's end
    expected = (0.0 + e1 + e2 + e3) / 4  # N = 4 kept points, the start counting with 0
    score = score_path(world, ref, shape, 0.001)
    assert score.distance_error == pytest.approx(expected, abs=1e-15)
    assert score.path_length == pytest.approx(total, abs=1e-15)
    assert score.frame.yaw == pytest.approx(yaw, abs=1e-12)


@pytest.mark.parametrize("name", ["line", "semi_ellipse"])
def test_robot_exactly_on_target_scores_zero(name: str) -> None:
    shape = builtin_shapes()[name]
    path = shape(np.linspace(0.0, 1.0, 3000))
    stream, window = one_run(path, spec=name, yaw=-1.1, origin=(3.0, -4.0))
    result = score_paths(stream, [window], Fbm3wConfig(), options=NO_DRAWS)
    # 0 up to the d_min quantisation: the last kept point may stop up to d_min short of the
    # end, which rescales l/L by < d_min / L and moves the compared target by < d_min
    assert result.runs[0].distance_error is not None
    assert result.runs[0].distance_error < 0.00033
    assert result.failures == ()
    # with d_min = 0 every sample is kept and the quantisation vanishes
    exact = score_paths(stream, [window], Fbm3wConfig(), options=Fbm3wOptions(d_min=0.0, draws=0))
    assert exact.runs[0].distance_error == pytest.approx(0.0, abs=1e-12)


def test_sine_scores_its_floor_unless_arc_length() -> None:
    shape = builtin_shapes()["spline"]
    path = shape(np.linspace(0.0, 1.0, 4000))
    stream, window = one_run(path, spec="spline")
    result = score_paths(stream, [window], Fbm3wConfig(), options=NO_DRAWS)
    run = result.runs[0]
    # the 2015 sine is parametrised by x, not by length: a perfect robot scores its floor
    # (computed on 10001 samples; with 4000 the kept points fall elsewhere: ~0.1 mm apart)
    assert run.distance_error == pytest.approx(run.shape_floor, abs=2e-4)
    assert run.distance_error > 0.008
    assert any("not parametrised by arc length" in w for w in result.warnings)
    fixed = score_paths(
        stream, [window], Fbm3wConfig(), options=Fbm3wOptions(arc_length=True, draws=0)
    )
    # arc-length target vs a path sampled uniformly in the shape's own parameter: 0 up to the
    # d_min quantisation and the 4097-sample reparametrisation table
    assert fixed.runs[0].distance_error < 0.0004
    assert any("--arc-length" in d for d in fixed.deviations)


RNG_PATH = np.random.default_rng(11)


def _wobbly_path() -> tuple[np.ndarray, np.ndarray]:
    shape = builtin_shapes()["semi_ellipse"]
    u = np.linspace(0.0, 1.0, 1500)
    path = shape(u) + 0.002 * np.column_stack([np.sin(7 * u), np.sin(np.pi * u)])
    path += RNG_PATH.normal(0.0, 1e-4, path.shape)
    path[0] = 0.0
    return path, np.array([[-0.04, 0.0]])


PATH, REF = _wobbly_path()
BASE = score_path(PATH, REF[0], builtin_shapes()["semi_ellipse"], 0.00033)


@settings(max_examples=40, deadline=None)
@given(
    yaw=st.floats(-math.pi, math.pi),
    tx=st.floats(-1e3, 1e3),
    ty=st.floats(-1e3, 1e3),
)
def test_rigid_motion_of_the_recording_changes_nothing(yaw: float, tx: float, ty: float) -> None:
    moved = place(PATH, (tx, ty), yaw)
    ref = place(REF, (tx, ty), yaw)[0]
    score = score_path(moved, ref, builtin_shapes()["semi_ellipse"], 0.00033)
    # distances are invariant; only rounding of coordinates up to 1e3 m (~1e-13 m) differs
    assert score.kept.tolist() == BASE.kept.tolist()
    assert score.distance_error == pytest.approx(BASE.distance_error, abs=1e-9)
    assert score.path_length == pytest.approx(BASE.path_length, abs=1e-9)


def test_bad_paths() -> None:
    line = builtin_shapes()["line"]
    with pytest.raises(ScoringError, match="1 pose sample"):
        score_path(np.zeros((1, 2)), np.array([-0.1, 0.0]), line, 0.00033)
    with pytest.raises(ScoringError, match="zero length"):
        score_path(np.zeros((50, 2)), np.array([-0.1, 0.0]), line, 0.00033)
    with pytest.raises(ScoringError, match="non-finite"):
        score_path(np.array([[0.0, 0.0], [np.nan, 1.0]]), np.array([-0.1, 0.0]), line, 0.0)
    with pytest.raises(ScoringError, match="coincide"):
        run_frame(np.array([1.0, 1.0]), np.array([1.0, 1.0]))


def test_long_path_is_warned() -> None:
    u = np.linspace(0.0, 1.0, 3000)
    # a 5 mm zigzag of 20 periods along the 157 mm line: about 60% longer than the target
    zigzag = builtin_shapes()["line"](u) + 0.005 * np.column_stack(
        [np.zeros_like(u), np.sin(40 * np.pi * u)]
    )
    stream, window = one_run(zigzag)
    result = score_paths(stream, [window], Fbm3wConfig(), options=NO_DRAWS)
    run = result.runs[0]
    assert run.score is not None and run.target_length is not None
    ratio = run.score.path_length / run.target_length
    assert ratio > 1.5
    assert any(f"{ratio - 1:.0%} longer than the target" in w for w in result.warnings)
