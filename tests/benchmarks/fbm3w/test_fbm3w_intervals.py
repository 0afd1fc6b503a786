"""FBM3@Work's perturbed scorer and intervals (issue 28): the all-draws-at-once Eq. (1)
against the simulator's plain loop of the seed's formulas, and the sources' sizes."""

from __future__ import annotations

import math

import numpy as np
import pytest

from ertools.benchmarks.common.epsilon import noise_statistics
from ertools.benchmarks.common.uncertainty import D_MIN, MOCAP_NOISE
from ertools.benchmarks.fbm3w.intervals import (
    RAYLEIGH_CV,
    RunSamples,
    measurement_source,
    noise_model,
    perturbed_errors,
    perturbed_runs,
    run_intervals,
    smooth,
)
from ertools.configs.shapes import builtin_shapes
from ertools.samples.fbm3w import eq1, target


def _line_run(rng: np.random.Generator, sigma: float) -> tuple[np.ndarray, np.ndarray]:
    """A run along the Listing 15 line (world = run frame), 3 mm off it, with noise."""
    u = np.linspace(0.0, 1.0, 400)
    xy = target("line", u) + np.column_stack([np.zeros_like(u), 0.003 * np.sin(math.pi * u)])
    xy = xy + rng.normal(0.0, sigma, xy.shape)
    ref = np.array([-0.08, -0.024])  # the line's direction, 8 cm before its start
    return xy, ref


def test_vectorised_eq1_matches_the_seed_loop_draw_by_draw() -> None:
    rng = np.random.default_rng(4)
    xy, ref = _line_run(rng, 5e-5)
    shape = builtin_shapes()["line"]
    run = RunSamples(xy, np.arange(len(xy)), ref, shape)
    d_mins = np.array([0.00033, 0.0005, 0.0001, 0.002])
    got = perturbed_errors(run, np.zeros(4), d_mins, rng, noisy=False)
    for g, d in zip(got, d_mins, strict=True):
        assert g == pytest.approx(eq1(ref, xy, "line", float(d))[0], rel=1e-12)


def test_noisy_draws_match_the_seed_loop_on_the_same_positions() -> None:
    # The draws' positions are xy + sigma * z with z drawn in a documented order: recompute
    # them from the same generator state and score each with the seed's loop.
    xy, ref = _line_run(np.random.default_rng(5), 5e-5)
    shape = builtin_shapes()["line"]
    run = RunSamples(xy, np.arange(len(xy)), ref, shape)
    sigmas = np.array([1e-4, 2e-4, 5e-5])
    got = perturbed_errors(run, sigmas, np.full(3, 0.00033), np.random.default_rng(9), True)
    again = np.random.default_rng(9)
    eps = again.standard_normal((3, len(xy), 2)) * sigmas[:, None, None]
    ref_eps = again.standard_normal((3, 2)) * sigmas[:, None]
    for k in range(3):
        want = eq1(ref + ref_eps[k], xy + eps[k], "line", 0.00033)[0]
        assert got[k] == pytest.approx(want, rel=1e-12)


def test_repeated_poses_carry_the_measurement_they_repeat() -> None:
    repeats = np.array([False, True, True, False, True])
    assert measurement_source(repeats).tolist() == [0, 1, 1, 1, 4, 4]


def test_smoothing_keeps_a_quadratic_path_and_removes_noise() -> None:
    t = np.linspace(0.0, 1.0, 200)
    path = np.column_stack([0.1 * t**2, 0.05 * t])
    # a quadratic fit over 9 samples reproduces a quadratic exactly (inside the edges)
    assert smooth(path)[4:-4] == pytest.approx(path[4:-4], abs=1e-15)
    noise = np.random.default_rng(0).normal(0.0, 1.0, (100_000, 2))
    # residual variance of the fit's centre: 59/231 of the noise's
    assert np.var(smooth(noise)[4:-4]) == pytest.approx(59 / 231, rel=0.03)


def test_sources_measured_from_the_noise_estimate_or_defaults() -> None:
    rng = np.random.default_rng(2)
    xy = rng.normal(0.0, 1e-4, (5001, 2))
    t = np.arange(5001, dtype=np.int64) * 8_333_333
    noise = noise_statistics(t, xy)
    model = noise_model(noise, 0.00033)
    pairs = noise.distances.size
    assert model.sigma == pytest.approx(noise.epsilon / math.sqrt(math.pi))
    assert model.sigma_rel == pytest.approx(RAYLEIGH_CV / math.sqrt(pairs / 2))
    assert [s.name for s in model.sources] == [MOCAP_NOISE, D_MIN]
    assert all(s.measured for s in model.sources)
    default = noise_model(None, 0.00033)
    assert default.sigma == pytest.approx(0.00011 / math.sqrt(math.pi))
    assert not any(s.measured for s in default.sources)


def test_intervals_are_seeded_and_cover_the_best_run() -> None:
    xy, ref = _line_run(np.random.default_rng(6), 5e-5)
    shape = builtin_shapes()["line"]
    run = RunSamples(xy, np.arange(len(xy)), ref, shape, smooth(xy), ref)
    est = eq1(ref, xy, "line", 0.00033)[0]
    model = noise_model(None, 0.00033)
    a = run_intervals([run, None], [est, None], model, draws=100, seed=3, confidence=0.95)
    b = run_intervals([run, None], [est, None], model, draws=100, seed=3, confidence=0.95)
    assert a == b
    per_run, best = a
    assert per_run[1] is None and per_run[0] is not None and best is not None
    # one run: the best run's interval is that run's
    assert (best.low, best.high) == pytest.approx((per_run[0].low, per_run[0].high))
    assert per_run[0].low <= est <= per_run[0].high
    assert run_intervals([run], [est], model, draws=0, seed=0, confidence=0.95) == ([None], None)


def test_a_repeated_pose_repeats_its_noise_in_every_draw() -> None:
    # samples 5-7 repeat sample 4 (tracking lost): in each draw they stay equal to it
    xy, ref = _line_run(np.random.default_rng(7), 5e-5)
    source = np.arange(len(xy))
    source[5:8] = 4
    xy[5:8] = xy[4]
    run = RunSamples(xy, source, ref, builtin_shapes()["line"])
    sigmas = np.full(2, 1e-4)
    got = perturbed_errors(run, sigmas, np.full(2, 0.00033), np.random.default_rng(3), True)
    again = np.random.default_rng(3)
    eps = again.standard_normal((2, len(xy), 2))[:, source, :] * 1e-4
    ref_eps = again.standard_normal((2, 2)) * 1e-4
    for k in range(2):
        assert np.all(eps[k, 5:8] == eps[k, 4])
        want = eq1(ref + ref_eps[k], xy + eps[k], "line", 0.00033)[0]
        assert got[k] == pytest.approx(want, rel=1e-12)


@pytest.mark.parametrize("budget", [2_000_000, 900, 1])
def test_runs_scored_in_one_pass_equal_each_run_alone_and_the_seed_loop(budget: int) -> None:
    # Three runs of different lengths (one with repeated poses), their draws side by side in
    # one d_min pass (or split in groups and batches by a small budget): each column equals
    # the seed's plain loop on positions drawn from the generator in the documented order:
    # run by run, in batches of budget // samples draws, the samples' noise then the
    # reference's.
    line = builtin_shapes()["line"]
    runs = []
    for k, n in enumerate((400, 150, 260)):
        xy, ref = _line_run(np.random.default_rng(20 + k), 5e-5)
        idx = np.linspace(0, len(xy) - 1, n).astype(int)
        source = np.arange(n)
        if k == 1:
            source[40:44] = 39
        runs.append(RunSamples(xy[idx][source], source, ref, line))
    sigmas = np.array([1e-4, 5e-5, 2e-4, 1.5e-4])
    d_mins = np.array([0.00033, 0.0005, 0.0002, 0.00033])
    got = perturbed_runs(runs, sigmas, d_mins, np.random.default_rng(11), True, budget=budget)
    assert got.shape == (4, 3)
    again = np.random.default_rng(11)
    for col, run in enumerate(runs):
        measured = int(run.source.max()) + 1
        batch = max(1, budget // len(run.xy))
        eps, ref_eps = np.empty((4, len(run.xy), 2)), np.empty((4, 2))
        for lo in range(0, 4, batch):
            hi = min(4, lo + batch)
            z = again.standard_normal((hi - lo, measured, 2))[:, run.source, :]
            eps[lo:hi] = z * sigmas[lo:hi, None, None]
            ref_eps[lo:hi] = again.standard_normal((hi - lo, 2)) * sigmas[lo:hi, None]
        for k in range(4):
            want = eq1(run.reference_xy + ref_eps[k], run.xy + eps[k], "line", float(d_mins[k]))
            assert got[k, col] == pytest.approx(want[0], rel=1e-12)
    if budget >= 2_000_000:  # unbatched: equal to each run alone, bit for bit
        rng = np.random.default_rng(11)
        alone = [perturbed_errors(r, sigmas, d_mins, rng, True) for r in runs]
        assert np.array_equal(got, np.column_stack(alone))
