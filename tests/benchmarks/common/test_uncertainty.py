"""The shared interval engine: quantiles, the basic bootstrap, shares and reproducibility,
checked against numbers computed here by hand or from a known distribution."""

from __future__ import annotations

import math

import numpy as np
import pytest

from ertools.benchmarks.common.interval_output import (
    MAX_LINE,
    ScoreRow,
    interval_line,
    interval_lines,
)
from ertools.benchmarks.common.uncertainty import (
    Interval,
    Source,
    Uncertainty,
    basic_intervals,
    interval_keys,
    monte_carlo,
    sigma_from_epsilon,
    split_interval,
    uncertainty_rows,
    z_value,
)
from ertools.errors import UsageError


def test_z_value_is_the_normal_quantile() -> None:
    # Phi(1.959964) = 0.975, from math.erf
    z = z_value(0.95)
    assert 0.5 * (1 + math.erf(z / math.sqrt(2))) == pytest.approx(0.975, abs=1e-9)
    with pytest.raises(UsageError, match="between 0 and 1"):
        z_value(1.0)


def test_basic_interval_reflects_the_draws_around_the_estimate() -> None:
    # draws 0..100 (101 values): the 2.5% and 97.5% quantiles are 2.5 and 97.5 (linear).
    draws = np.arange(101.0).reshape(101, 1)
    low, high = basic_intervals(np.array([10.0]), draws, 0.95)
    assert low[0] == pytest.approx(2 * 10 - 97.5)
    assert high[0] == pytest.approx(2 * 10 - 2.5)


def test_basic_interval_needs_two_finite_draws() -> None:
    draws = np.array([[np.nan, 1.0], [np.nan, 3.0], [5.0, np.nan]])
    low, high = basic_intervals(np.array([1.0, 2.0]), draws, 0.5)
    assert math.isnan(low[0]) and math.isnan(high[0])
    # finite draws of the second score: 1 and 3, quantiles 0.25/0.75 -> 1.5 and 2.5
    assert (low[1], high[1]) == pytest.approx((2 * 2 - 2.5, 2 * 2 - 1.5))


def test_sigma_from_epsilon_on_simulated_noise() -> None:
    rng = np.random.default_rng(1)
    sigma = 0.0004
    xy = rng.normal(0.0, sigma, size=(200_000, 2))
    epsilon = float(np.mean(np.hypot(*np.diff(xy, axis=0).T)))
    # 200,000 pairs: the mean's relative standard error is ~0.2%
    assert sigma_from_epsilon(epsilon) == pytest.approx(sigma, rel=0.01)


def _mean_score(truth: np.ndarray, sigma: float, offset_sigma: float):  # type: ignore[no-untyped-def]
    """A score = mean of N measured values, perturbed by per-sample noise and one offset."""

    def perturbed(rng: np.random.Generator, sources: frozenset[str], n: int) -> np.ndarray:
        draws = np.zeros((n, 1))
        if "noise" in sources:
            draws += rng.normal(0.0, sigma, size=(n, truth.size)).mean(axis=1, keepdims=True)
        if "offset" in sources:
            draws += rng.normal(0.0, offset_sigma, size=(n, 1))
        return draws + truth.mean()

    return perturbed


def test_monte_carlo_width_matches_the_analytic_interval() -> None:
    truth = np.linspace(0.0, 1.0, 100)
    sigma, offset = 0.01, 0.002
    f = _mean_score(truth, sigma, offset)
    (iv,) = monte_carlo([0.5], f, ("noise", "offset"), draws=20_000, seed=3, nonnegative=False)
    assert iv is not None
    # the mean of 100 samples has sigma 0.001; with the offset sd = sqrt(1e-6 + 4e-6)
    sd = math.sqrt((sigma / 10) ** 2 + offset**2)
    half = 1.959964 * sd
    # 20,000 draws: the 2.5% quantile's standard error is ~1.2% of sd
    assert iv.low == pytest.approx(0.5 - half, abs=0.05 * sd)
    assert iv.high == pytest.approx(0.5 + half, abs=0.05 * sd)
    shares = iv.share_dict()
    assert shares["noise"] == pytest.approx(1 / 5, abs=0.02)
    assert shares["offset"] == pytest.approx(4 / 5, abs=0.02)


def test_monte_carlo_shares_from_a_given_variance_and_the_remainder() -> None:
    """The offset's variance given (4e-6), no pass of draws is run for shares: the noise's
    share is what the together pass's variance leaves, 1e-6 of the 5e-6 (the same 1/5 and
    4/5 as above, within the together pass's variance error: 20,000 draws, 1%)."""
    truth = np.linspace(0.0, 1.0, 100)
    f = _mean_score(truth, 0.01, 0.002)
    calls: list[frozenset[str]] = []

    def counted(rng: np.random.Generator, sources: frozenset[str], n: int) -> np.ndarray:
        calls.append(sources)
        return np.asarray(f(rng, sources, n))

    (iv,) = monte_carlo(
        [0.5],
        counted,
        ("noise", "offset"),
        draws=20_000,
        seed=3,
        nonnegative=False,
        alone_variance={"offset": lambda: np.array([4e-6])},
    )
    assert calls == [frozenset({"noise", "offset"})]
    assert iv is not None
    shares = iv.share_dict()
    assert shares["noise"] == pytest.approx(1 / 5, abs=0.03)
    assert shares["offset"] == pytest.approx(4 / 5, abs=0.03)


def test_an_interval_reaches_its_score_when_the_bias_passes_the_spread() -> None:
    """Draws biased by +5 with spread 1 about a score of 10: the basic interval is
    [2 * 10 - q97.5, 2 * 10 - q2.5] = [3.04, 6.96], wholly below 10; it is widened to 10."""

    def perturbed(rng: np.random.Generator, sources: frozenset[str], n: int) -> np.ndarray:
        return (15.0 + rng.standard_normal(n)).reshape(n, 1)

    (iv,) = monte_carlo([10.0], perturbed, ("noise",), draws=20_000, seed=1)
    assert iv is not None
    # 20,000 draws: the 97.5% quantile 16.96 known to ~0.02
    assert iv.low == pytest.approx(20.0 - 16.96, abs=0.08)
    assert iv.high == 10.0


def test_monte_carlo_is_reproducible_and_seeded() -> None:
    f = _mean_score(np.ones(10), 0.1, 0.01)
    a = monte_carlo([1.0], f, ("noise", "offset"), draws=200, seed=5)
    b = monte_carlo([1.0], f, ("noise", "offset"), draws=200, seed=5)
    c = monte_carlo([1.0], f, ("noise", "offset"), draws=200, seed=6)
    assert a == b
    assert a != c


def test_monte_carlo_clips_nonnegative_scores_and_skips_unscored() -> None:
    def perturbed(rng: np.random.Generator, sources: frozenset[str], n: int) -> np.ndarray:
        return np.column_stack([rng.normal(0.0, 1.0, n), np.full(n, np.nan)])

    iv, none = monte_carlo([0.0, math.nan], perturbed, ("noise",), draws=500, seed=0)
    assert iv is not None and iv.low == 0.0 and iv.high > 1.5
    assert iv.shares == (("noise", 1.0),)
    assert none is None
    assert monte_carlo([1.0], perturbed, ("noise",), draws=0) == [None]


def test_interval_keys_follow_their_score() -> None:
    data = {"a": 1.0, "b": 2.0, "c": 3.0}
    out = interval_keys(data, {"b": Interval(1.5, 2.5), "c": None})
    assert list(out) == ["a", "b", "b_interval", "c", "c_interval"]
    assert out["b_interval"] == [1.5, 2.5] and out["c_interval"] is None


def test_interval_line_states_value_interval_method_and_shares() -> None:
    sources = (Source("mocap_noise", 1e-4, "m", True), Source("d_min", 3.3e-4, "m", False))
    u = Uncertainty(0.95, "Monte Carlo (details)", 400, 0, sources, {})
    iv = Interval(0.00041, 0.00088, (("d_min", 0.29), ("mocap_noise", 0.71)))
    row = ScoreRow("best_distance_error", 0.000639, iv, 1000.0, "mm")
    # the score, its interval at the level, the method, the sources by share (largest first)
    assert interval_line(row, u) == (
        "interval: best_distance_error 0.639 mm [0.41, 0.88] mm at 95% "
        "(Monte Carlo, 400 draws, seed 0; mocap_noise 71%, d_min 29%)"
    )
    assert interval_line(ScoreRow("x", 1.0, None), u) == (
        "interval: x 1: no 95% interval (Monte Carlo, 400 draws, seed 0: too few draws scored)"
    )
    # a score without a value has no line; the sources close the list
    lines = interval_lines([row, ScoreRow("run 1 distance_error", None, None)], u)
    assert lines == [
        interval_line(row, u),
        "interval sources: mocap_noise 0.0001 m (measured); d_min 0.00033 m (default)",
    ]
    assert interval_lines([row], None) == []
    # the line stays within the CLI's 200 characters: the smallest shares go first
    many = tuple((f"source_with_a_long_name_{k}", 0.2 - 0.01 * k) for k in range(5))
    long_row = ScoreRow("segment 12345 orientation_error", 1.0, Interval(0.5, 1.5, many))
    long_u = Uncertainty(0.95, "Monte Carlo", 400, 2**62, sources, {})
    line = interval_line(long_row, long_u)
    assert len(line) <= MAX_LINE
    assert "source_with_a_long_name_0 20%" in line
    assert "source_with_a_long_name_2" not in line


def test_split_interval_and_uncertainty_rows() -> None:
    row = {"run": 0, "distance_error": 1.0, "distance_error_interval": [0.5, 1.5], "status": "ok"}
    split_interval(row, "distance_error")
    assert list(row) == [
        "run",
        "distance_error",
        "distance_error_low",
        "distance_error_high",
        "status",
    ]
    assert (row["distance_error_low"], row["distance_error_high"]) == (0.5, 1.5)
    u = Uncertainty(0.9, "m", 10, 1, (Source("a", 2.0, "m", False, "default"),), {"k": {"a": 1.0}})
    (only,) = uncertainty_rows(u)
    assert only["score"] == "k" and only["share"] == 1.0 and only["measured"] is False
