"""The FBM1 interval model's parts against numbers computed here: the sigma of a window's
mean, the pooled autocorrelation of AR(1) noise, and the output keys."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.stats import t as student_t

from ertools.benchmarks.fbm1.intervals import pooled_rho, run_noise


def test_sigma_of_the_mean_of_independent_samples() -> None:
    rng = np.random.default_rng(4)
    n, sigma = 400, 3e-4
    xy = rng.normal(0.0, sigma, (n, 2)) + np.array([0.3, 0.2])
    yaw = 0.5 + rng.normal(0.0, 1e-3, n)
    got = run_noise(xy, yaw, lookup=False, confidence=0.95, gt_yaw=0.5, rho=0.0)
    widen = student_t.ppf(0.975, n - 1) / 1.959964
    # the sample sd of 400 normal values is within 3.5% (1 sd); 12% is over 3 sd
    assert got.mean_sigma[0] == pytest.approx(sigma / math.sqrt(n) * widen, rel=0.12)
    assert got.mean_sigma[2] == pytest.approx(1e-3 / math.sqrt(n) * widen, rel=0.12)
    # one lookup: the sigma of one sample
    one = run_noise(xy, yaw, lookup=True, confidence=0.95, gt_yaw=0.5, rho=0.0)
    assert one.mean_sigma[1] == pytest.approx(sigma * widen, rel=0.12)


def test_correlated_samples_count_as_fewer() -> None:
    rng = np.random.default_rng(5)
    rho = 0.5
    windows = []
    for _ in range(10):
        e = np.zeros((200, 3))
        e[0] = rng.normal(size=3)
        for i in range(1, 200):
            e[i] = rho * e[i - 1] + math.sqrt(1 - rho**2) * rng.normal(size=3)
        windows.append((e[:, :2] * 1e-4, e[:, 2] * 1e-3, 0.0))
    got = pooled_rho(windows)
    # 6,000 AR(1) pairs: the estimate's sd is about sqrt((1 - rho^2) / 6000) = 0.011
    assert got == pytest.approx(rho, abs=0.05)
    noise = run_noise(*windows[0][:2], lookup=False, confidence=0.95, gt_yaw=0.0, rho=got)
    # n (1 - rho) / (1 + rho): 200 / 3 for rho = 0.5
    assert noise.n_eff == pytest.approx(200 * (1 - got) / (1 + got))
    # anti-correlation is not credited
    alternating = [(np.array([[1.0, 1.0], [-1.0, -1.0]] * 50), np.array([1.0, -1.0] * 50), 0.0)]
    assert pooled_rho(alternating) == 0.0
