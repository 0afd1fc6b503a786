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
    measurement_source,
    noise_model,
    run_intervals,
    smooth,
)
from ertools.benchmarks.fbm3w.perturbed import RunSamples, perturbed_errors, perturbed_runs
from ertools.benchmarks.fbm3w.sample import eq1, target
from ertools.benchmarks.fbm3w.shapes import builtin_shapes


def _line_run(rng: np.random.Generator, sigma: float) -> tuple[np.ndarray, np.ndarray]:
    """A run along the Listing 15 line (world = run frame), 3 mm off it, with noise."""
    u = np.linspace(0.0, 1.0, 400)
    xy = target("line", u) + np.column_stack([np.zeros_like(u), 0.003 * np.sin(math.pi * u)])
    xy = xy + rng.normal(0.0, sigma, xy.shape)
    ref = np.array([-0.08, -0.024])  # the line's direction, 8 cm before its start
    return xy, ref


# The draws work in float32 (complex64 x + iy) relative to each run's first sample: the
# positions, within 0.2 m of it, are rounded to 0.2 m x 2^-24 = 1.2e-8 m, the target table
# is exact for the line, and each Eq. (1) term is a distance moved by a few such roundings:
# the seed's float64 loop on the same rounded positions agrees to 1e-7 m (measured: < 1e-9).
# Both keep the same samples: the draws' distances are within 1e-7 relative of the loop's,
# and no step of these logs lies that close to d_min.
ATOL = 1e-7


def _draw_positions(
    run: RunSamples, noise: np.ndarray, sigmas: np.ndarray, ref_noise: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """(D, N, 2) sample and (D, 2) reference positions of the draws, as the draws compute
    them: standard normal noise x + iy scaled by each draw's sigma in complex64, a repeated
    pose repeating its sample's noise, added to the positions relative to the first sample."""
    origin = run.xy[0]
    rel = ((run.xy[:, 0] - origin[0]) + 1j * (run.xy[:, 1] - origin[1])).astype(np.complex64)
    z = noise * sigmas.astype(np.float32)  # (N, D) complex64
    z = z[run.source] + rel[:, None]
    ref = complex(*(run.reference_xy - origin)) + (ref_noise * sigmas.astype(np.float32))
    z64 = z.T.astype(np.complex128) + complex(*origin)
    r64 = ref.astype(np.complex128) + complex(*origin)
    return np.stack([z64.real, z64.imag], axis=-1), np.column_stack([r64.real, r64.imag])


def _standard_noise(
    rng: np.random.Generator, rows: list[int], widths: list[int], ways: int = 4
) -> tuple[np.ndarray, np.ndarray]:
    """The documented order of the draws' noise (perturbed._noise): piece after piece (rows
    samples, w draws), its samples' x (rows, q), their y, then its reference's x and y, q =
    ceil(w / 4), in float32; its first q draws take that noise z, the next -z, then iz =
    -y + ix, then -iz (``ways`` 1: each draw its own). Returned as (max rows, sum of widths)
    and (sum of widths,) complex, a shorter piece's missing rows 0."""
    cols, ref_cols = [], []
    for n, w in zip(rows, widths, strict=True):
        q = -(-w // ways)
        x, y = rng.standard_normal((2, n, q), dtype=np.float32)
        rx, ry = rng.standard_normal((2, q), dtype=np.float32)
        z, rz = x + 1j * y, rx + 1j * ry
        turned = np.concatenate([z, -z, 1j * z, -1j * z][:ways], axis=1)[:, :w]
        turned_ref = np.concatenate([rz, -rz, 1j * rz, -1j * rz][:ways])[:w]
        cols.append(np.vstack([turned, np.zeros((max(rows) - n, w))]))
        ref_cols.append(turned_ref)
    return (
        np.concatenate(cols, axis=1).astype(np.complex64),
        np.concatenate(ref_cols).astype(np.complex64),
    )


def test_vectorised_eq1_matches_the_seed_loop_draw_by_draw() -> None:
    rng = np.random.default_rng(4)
    xy, ref = _line_run(rng, 5e-5)
    shape = builtin_shapes()["line"]
    run = RunSamples(xy, np.arange(len(xy)), ref, shape)
    d_mins = np.array([0.00033, 0.0005, 0.0001, 0.002])
    got = perturbed_errors(run, np.zeros(4), d_mins, rng, noisy=False)
    for g, d in zip(got, d_mins, strict=True):
        assert g == pytest.approx(eq1(ref, xy, "line", float(d))[0], abs=ATOL)


def test_noisy_draws_match_the_seed_loop_on_the_same_positions() -> None:
    # The draws' positions are xy + sigma * z with z drawn in a documented order: recompute
    # them from the same generator state and score each with the seed's loop.
    xy, ref = _line_run(np.random.default_rng(5), 5e-5)
    shape = builtin_shapes()["line"]
    run = RunSamples(xy, np.arange(len(xy)), ref, shape)
    sigmas = np.array([1e-4, 2e-4, 5e-5])
    got = perturbed_errors(run, sigmas, np.full(3, 0.00033), np.random.default_rng(9), True)
    noise, ref_noise = _standard_noise(np.random.default_rng(9), [len(xy)], [3])
    pos, refs = _draw_positions(run, noise, sigmas, ref_noise)
    for k in range(3):
        want = eq1(refs[k], pos[k], "line", 0.00033)[0]
        assert got[k] == pytest.approx(want, abs=ATOL)
    # the second draw is the first's noise negated, the third turned by 90 degrees (x, y ->
    # -y, x), each its own sigma
    first = (pos[0] - xy) / 1e-4
    assert np.allclose((pos[1] - xy) / 2e-4, -first, atol=3e-4)
    assert np.allclose((pos[2] - xy) / 5e-5, first[:, ::-1] * [-1, 1], atol=3e-4)


def test_independent_draws_on_request() -> None:
    xy, ref = _line_run(np.random.default_rng(5), 5e-5)
    run = RunSamples(xy, np.arange(len(xy)), ref, builtin_shapes()["line"])
    sigmas = np.full(2, 1e-4)
    got = perturbed_runs(
        [run], sigmas, np.full(2, 0.00033), np.random.default_rng(9), True, fourfold=False
    )[:, 0]
    noise, ref_noise = _standard_noise(np.random.default_rng(9), [len(xy)], [2], ways=1)
    pos, r = _draw_positions(run, noise, sigmas, ref_noise)
    for k in range(2):
        assert got[k] == pytest.approx(eq1(r[k], pos[k], "line", 0.00033)[0], abs=ATOL)


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
    noise, ref_noise = _standard_noise(np.random.default_rng(3), [len(xy)], [2])
    pos, refs = _draw_positions(run, noise, sigmas, ref_noise)
    for k in range(2):
        assert np.all(pos[k, 5:8] == pos[k, 4])
        want = eq1(refs[k], pos[k], "line", 0.00033)[0]
        assert got[k] == pytest.approx(want, abs=ATOL)


@pytest.mark.parametrize("budget", [2_000_000, 900, 1])
def test_runs_scored_in_one_pass_equal_the_seed_loop(budget: int) -> None:
    # Three runs of different lengths (one with repeated poses), their draws side by side in
    # one d_min pass (or split in groups and batches by a small budget): without noise each
    # column equals the seed's plain loop at its own d_min, however the draws are grouped;
    # with noise, in one group, equal to the loop on the positions drawn in the documented
    # order (piece after piece, each drawn noise used four ways).
    line = builtin_shapes()["line"]
    runs = []
    for k, n in enumerate((400, 150, 260)):
        xy, ref = _line_run(np.random.default_rng(20 + k), 5e-5)
        idx = np.linspace(0, len(xy) - 1, n).astype(int)
        source = np.arange(n)
        if k == 1:
            source[40:44] = 39
        runs.append(RunSamples(xy[idx][source], source, ref, line))
    d_mins = np.array([0.00033, 0.0005, 0.0002, 0.00033])
    got = perturbed_runs(runs, np.zeros(4), d_mins, np.random.default_rng(11), False, budget=budget)
    assert got.shape == (4, 3)
    for col, run in enumerate(runs):
        for k in range(4):
            want = eq1(run.reference_xy, run.xy, "line", float(d_mins[k]))
            assert got[k, col] == pytest.approx(want[0], abs=ATOL)
    if budget < 2_000_000:
        return
    sigmas = np.array([1e-4, 5e-5, 2e-4, 1.5e-4])
    got = perturbed_runs(runs, sigmas, d_mins, np.random.default_rng(11), True, budget=budget)
    lengths = [len(r.xy) for r in runs]
    noise, ref_noise = _standard_noise(np.random.default_rng(11), lengths, [4, 4, 4])
    for col, run in enumerate(runs):
        cols = slice(4 * col, 4 * col + 4)
        pos, refs = _draw_positions(run, noise[: len(run.xy), cols], sigmas, ref_noise[cols])
        for k in range(4):
            want = eq1(refs[k], pos[k], "line", float(d_mins[k]))
            assert got[k, col] == pytest.approx(want[0], abs=ATOL)


def test_fourfold_draws_score_as_independent_draws() -> None:
    # Each drawn noise used four ways (z, -z, iz, -iz) leaves every draw's distribution the
    # model's: the distance errors of 4,000 draws have the mean, spread and 2.5% and 97.5%
    # quantiles of 4,000 independent ones. Tolerances: 5 standard errors of a difference of
    # two independent estimates (the fourfold ones' own standard error taken twice that of
    # independent draws: their groups of four are correlated); a quantile's standard error
    # from the normal's density at it, sqrt(p (1 - p) / n) / phi(z_p) times the spread.
    # a run on the line itself: its score is the noise's alone, and grows with sigma
    xy = target("line", np.linspace(0.0, 1.0, 400))
    ref = np.array([-0.08, 0.0])  # the run frame's x axis: the world's
    run = RunSamples(xy, np.arange(len(xy)), ref, builtin_shapes()["line"])
    n = 4000
    sigmas, d_mins = np.full(n, 1e-4), np.full(n, 0.00033)
    four = perturbed_errors(run, sigmas, d_mins, np.random.default_rng(1), True)
    one = perturbed_runs([run], sigmas, d_mins, np.random.default_rng(2), True, fourfold=False)
    one = one[:, 0]
    spread = float(np.std(one))
    se = math.sqrt(1.0**2 + 2.0**2) * spread / math.sqrt(n)
    assert abs(np.mean(four) - np.mean(one)) < 5 * se
    assert abs(np.std(four) - spread) < 5 * se / math.sqrt(2)  # sd's se: sd / sqrt(2 n)
    z = 1.959964
    se_q = math.sqrt(0.025 * 0.975 / n) / (math.exp(-z * z / 2) / math.sqrt(2 * math.pi))
    for p in (2.5, 97.5):
        gap = abs(np.percentile(four, p) - np.percentile(one, p))
        assert gap < 5 * math.sqrt(1.0 + 4.0) * se_q * spread


def test_samples_no_draw_keeps_are_left_out_of_eq1_exactly() -> None:
    # The robot stands still for 150 samples mid-run (jitter far below d_min): no draw keeps
    # them, Eq. (1) leaves those rows out (blocks partly and wholly skipped), and every draw
    # still equals the seed's loop at its d_min.
    u = np.concatenate([np.linspace(0.0, 0.4, 200), np.full(150, 0.4), np.linspace(0.4, 1, 200)])
    xy = target("line", u) + np.random.default_rng(12).normal(0.0, 2e-6, (u.size, 2))
    ref = np.array([-0.08, -0.024])
    run = RunSamples(xy, np.arange(len(xy)), ref, builtin_shapes()["line"])
    d_mins = np.array([0.00033, 0.0005, 0.0002])
    got = perturbed_errors(run, np.zeros(3), d_mins, np.random.default_rng(0), noisy=False)
    for g, d in zip(got, d_mins, strict=True):
        assert g == pytest.approx(eq1(ref, xy, "line", float(d))[0], abs=ATOL)


def test_a_draw_of_sigma_zero_takes_no_random_numbers() -> None:
    # Draw 1 of 9 has sigma 0 (a clipped sigma draw, or a smoothed path riding along): it is
    # the positions as they are, and the other 8 take the documented noise in their order
    # (2 drawn, used four ways: the first use falls on draws 0 and 2, not side by side).
    xy, ref = _line_run(np.random.default_rng(13), 5e-5)
    run = RunSamples(xy, np.arange(len(xy)), ref, builtin_shapes()["line"])
    sigmas = np.array([1e-4, 0.0, 2e-4, 5e-5, 1.5e-4, 1e-4, 8e-5, 1.2e-4, 6e-5])
    got = perturbed_errors(run, sigmas, np.full(9, 0.00033), np.random.default_rng(4), True)
    noise, ref_noise = _standard_noise(np.random.default_rng(4), [len(xy)], [8])
    at = [0, 2, 3, 4, 5, 6, 7, 8]
    pos, refs = _draw_positions(run, noise, sigmas[at], ref_noise)
    for k, col in enumerate(at):
        assert got[col] == pytest.approx(eq1(refs[k], pos[k], "line", 0.00033)[0], abs=ATOL)
    assert got[1] == pytest.approx(eq1(ref, xy, "line", 0.00033)[0], abs=ATOL)
