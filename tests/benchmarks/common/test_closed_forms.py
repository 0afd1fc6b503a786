"""The closed forms of the intervals (issue 39) against brute-force Monte Carlo of the same
model: every pose's noise drawn, the statistic computed as the scorer does, with a fixed
seed. Tolerances count the Monte Carlo's own standard errors: with N draws a mean is known
to sd / sqrt(N) and a quantile at p to sqrt(p (1 - p) / N) / density; each check allows
5 of them, so a correct formula passes for any seed and an error of that size fails."""

from __future__ import annotations

import math

import numpy as np
import pytest

from ertools.benchmarks.common.closed_forms import (
    angle_moments,
    chi3_moments,
    chi3_squared_moments,
    circular_mean_moments,
    lag_mixture,
    lag_nodes,
    mean_moments,
    mix_angles,
)
from ertools.benchmarks.common.draws import order_band

pytestmark = pytest.mark.slow  # whole module: make test only

N = 400_000  # draws of one pose's term
Z = 5.0  # standard errors allowed


def _raw_close(got: float, samples: np.ndarray) -> None:
    se = float(np.std(samples)) / math.sqrt(len(samples))
    assert abs(got - float(np.mean(samples))) <= Z * se + 1e-15, (got, np.mean(samples), se)


@pytest.mark.parametrize(("d", "s"), [(0.0, 1.0), (0.5, 1.0), (2.0, 1.0), (9.0, 1.0), (0.02, 2e-4)])
def test_noisy_distance_moments(d: float, s: float) -> None:
    rng = np.random.default_rng(1)
    e = np.array([d, 0.0, 0.0])
    r = np.linalg.norm(e + s * rng.standard_normal((N, 3)), axis=1)
    raw = chi3_moments(np.array([d]), np.array([s]))
    for p, m in ((1, raw.m1), (2, raw.m2), (3, raw.m3)):
        _raw_close(float(m[0]), r**p)
    sq = chi3_squared_moments(np.array([d]), np.array([s]))
    for p, m in ((1, sq.m1), (2, sq.m2), (3, sq.m3)):
        _raw_close(float(m[0]), r ** (2 * p))


def test_distance_moments_continuous_where_the_form_changes() -> None:
    # nu = 10 switches to the exact large-nu form: both sides agree to float precision
    raw = chi3_moments(np.array([10.0 - 1e-9, 10.0 + 1e-9]), np.ones(2))
    mean, var, k3 = raw.central()
    assert mean[0] == pytest.approx(mean[1], abs=1e-8)
    assert var[0] == pytest.approx(var[1], abs=1e-8)
    assert k3[0] == pytest.approx(k3[1], abs=1e-6)
    # no noise: the distance itself
    exact = chi3_moments(np.array([0.0, 3.0]), np.zeros(2))
    assert exact.m1.tolist() == [0.0, 3.0] and exact.central()[1].tolist() == [0.0, 0.0]


@pytest.mark.parametrize(
    ("theta", "s", "unwrapped"),
    [
        (0.0, 1e-3, False),
        (2e-3, 1e-3, False),
        (0.4, 0.05, False),
        (math.pi - 1e-3, 2e-3, False),
        (-2.0, 0.1, False),
        (1e-3, 2e-3, True),
        (2.5, 0.05, True),
        (4.0, 0.05, True),
        (-5.0, 0.1, True),
    ],
)
def test_angle_term_moments(theta: float, s: float, unwrapped: bool) -> None:
    rng = np.random.default_rng(2)
    x = theta + s * rng.standard_normal(N)
    if unwrapped:
        a = np.sin(np.abs(x))  # 2015: the unwrapped difference
    else:
        a = np.sin(np.abs(np.remainder(x + math.pi, 2 * math.pi) - math.pi))
    b = np.cos(x)
    m = angle_moments(np.array([theta]), np.array([s]), unwrapped=unwrapped)
    _raw_close(float(m.ea[0]), a)
    _raw_close(float(m.ea2[0]), a * a)
    _raw_close(float(m.eb[0]), b)
    _raw_close(float(m.eb2[0]), b * b)
    _raw_close(float(m.eab[0]), a * b)


REPS = 20_000  # brute-force replicates of a whole comparison


def _quantiles_close(draw: np.ndarray, brute: np.ndarray) -> None:
    """The closed form's 2.5, 50 and 97.5 % points (from its own 200,000 draws, known to a
    fifth of the brute force's error) against the brute force's, within 5 standard errors of
    a quantile of REPS draws (the density estimated as normal from the brute force's sd)."""
    sd = float(np.std(brute))
    for p in (0.025, 0.5, 0.975):
        dens = math.exp(-0.5 * (np.quantile((brute - brute.mean()) / sd, p)) ** 2)
        dens /= sd * math.sqrt(2 * math.pi)
        se = math.sqrt(p * (1 - p) / REPS) / dens
        got, want = float(np.quantile(draw, p)), float(np.quantile(brute, p))
        assert abs(got - want) <= Z * se * 1.05, (p, got, want, se)


def _errors(rng: np.random.Generator, n: int, scale: float) -> np.ndarray:
    return rng.normal(0.0, scale, (n, 3))


@pytest.mark.parametrize(("n", "scale", "sigma"), [(300, 0.01, 2e-4), (25, 3e-4, 2e-4)])
def test_mean_distance_and_rmse_against_brute_force(n: int, scale: float, sigma: float) -> None:
    """Robot errors of ~1 cm against 0.2 mm of noise (the usual case), and a near-perfect
    robot on 25 poses (errors of the noise's size: skewed, the Cornish-Fisher term works)."""
    rng = np.random.default_rng(3)
    e = _errors(rng, n, scale)
    s = sigma * rng.uniform(0.7, 1.0, n)  # interpolation's averaging
    noisy = e[None] + s[None, :, None] * rng.standard_normal((REPS, n, 3))
    dist = np.linalg.norm(noisy, axis=-1)
    d = np.linalg.norm(e, axis=1)
    z = np.random.default_rng(4).standard_normal(200_000)
    _quantiles_close(mean_moments(chi3_moments(d, s)).draw(z), dist.mean(axis=1))
    rmse = np.sqrt(np.maximum(mean_moments(chi3_squared_moments(d, s)).draw(z), 0.0))
    _quantiles_close(rmse, np.sqrt(np.mean(dist**2, axis=1)))


@pytest.mark.parametrize("unwrapped", [False, True])
def test_circular_mean_against_brute_force(unwrapped: bool) -> None:
    """Yaw errors of a few degrees, some near 0 (folded by the noise), some across +-pi
    (wrapped; the unwrapped 2015 difference keeps them near 2 pi)."""
    rng = np.random.default_rng(5)
    n = 200
    theta = rng.normal(0.0, 0.05, n)
    theta[:20] = rng.normal(0.0, 0.002, 20)
    theta[20:30] = math.pi - np.abs(rng.normal(0.0, 0.01, 10))
    if unwrapped:
        theta[20:30] += 2.0  # 2015's difference of two unwrapped yaws: beyond pi
    s = np.full(n, 0.004)
    x = theta[None] + s * np.random.default_rng(6).standard_normal((REPS, n))
    if unwrapped:
        a = np.sin(np.abs(x))
    else:
        a = np.sin(np.abs(np.remainder(x + math.pi, 2 * math.pi) - math.pi))
    brute = np.arctan2(a.sum(axis=1), np.cos(x).sum(axis=1))
    stat = circular_mean_moments(angle_moments(theta, s, unwrapped=unwrapped))
    _quantiles_close(stat.draw(np.random.default_rng(7).standard_normal(200_000)), brute)


def test_a_uniform_lag_mixture_against_brute_force() -> None:
    """``hold`` (2015): the GT compared was measured up to a frame period before the robot
    pose, a lag uniform over [-1, 0] periods moving it by the velocity; with noise."""
    rng = np.random.default_rng(8)
    n = 150
    e = _errors(rng, n, 0.01)
    v = rng.normal(0.0, 0.5, (n, 3))
    period = np.full(n, 1 / 120)
    theta = rng.normal(0.0, 0.05, n)
    omega = rng.normal(0.0, 1.0, n)
    s, sy = np.full(n, 2e-4), np.full(n, 1e-3)
    lag = np.random.default_rng(9).uniform(-1.0, 0.0, (REPS, n)) * period
    gen = np.random.default_rng(10)
    noisy = e[None] - lag[..., None] * v + s[None, :, None] * gen.standard_normal((REPS, n, 3))
    brute_d = np.linalg.norm(noisy, axis=-1).mean(axis=1)
    x = theta[None] - lag * omega + sy * gen.standard_normal((REPS, n))
    a = np.sin(np.abs(np.remainder(x + math.pi, 2 * math.pi) - math.pi))
    brute_o = np.arctan2(a.sum(axis=1), np.cos(x).sum(axis=1))
    dist, ang = [], []
    for node in lag_nodes(-1.0, 0.0):
        shift = node * period
        dist.append(chi3_moments(np.linalg.norm(e - shift[:, None] * v, axis=1), s))
        ang.append(angle_moments(theta - shift * omega, sy))
    z = np.random.default_rng(11).standard_normal(200_000)
    _quantiles_close(mean_moments(lag_mixture(dist)).draw(z), brute_d)
    _quantiles_close(circular_mean_moments(mix_angles(ang)).draw(z), brute_o)


def test_order_band_gives_the_same_order_statistics() -> None:
    """Values moved by at most their bound: the order statistics of the band, at the shifted
    ranks, are exactly those of all the values, draw by draw."""
    rng = np.random.default_rng(12)
    values = rng.gamma(3.0, 1.0, 2000)
    bound = rng.uniform(0.0, 0.05, 2000)
    n = len(values)
    for percent in (50.0, 90.0, 99.0, 100.0):
        h = (n - 1) * percent / 100
        lo, hi = math.floor(h), min(math.floor(h) + 1, n - 1)
        keep, ranks = order_band(values, bound, np.array([lo, hi]))
        assert len(keep) < n / 5  # the point: few values can move the statistic
        for _ in range(50):
            moved = values + bound * rng.uniform(-1.0, 1.0, n)
            every = np.sort(moved)
            band = np.sort(moved[keep])
            assert band[ranks[0]] == every[lo] and band[ranks[1]] == every[hi]
