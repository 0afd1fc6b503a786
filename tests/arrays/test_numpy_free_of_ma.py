"""ertools.arrays.median, quantiles, percentiles, nanquantiles and distinct: NumPy's numbers
without its import of its masked arrays (issue 39, start-up)."""

from __future__ import annotations

import subprocess
import sys
from typing import Any

import numpy as np
import numpy.typing as npt
import pytest

from ertools.arrays import (
    distinct,
    median,
    nanquantiles,
    percentiles,
    percentiles_and_median,
    quantiles,
)


def test_by_hand() -> None:
    assert median([3.0, 1.0, 2.0]) == 2.0
    assert median([4, 1, 3, 2]) == 2.5  # integers: the mean of 2 and 3, a float
    assert median(np.array([[1.0, 9.0], [3.0, 5.0], [2.0, 7.0]]), axis=0).tolist() == [2.0, 7.0]
    assert median(np.array([[1.0, 9.0, 4.0, 0.5]]), axis=1).tolist() == [2.5]
    assert np.isnan(median([1.0, np.nan, 2.0]))
    nan_column = median(np.array([[1.0, np.nan], [2.0, 3.0]]), axis=0)
    assert nan_column[0] == 1.5 and np.isnan(nan_column[1])
    with pytest.warns(RuntimeWarning):
        assert np.isnan(median(np.array([], np.float64)))
    # 0..10: at (n - 1) q / 100 = 10 q / 100; 25 % at 2.5 between 2 and 3, 100 % the last
    assert percentiles(np.arange(11.0)[::-1], [0, 25, 50, 100]).tolist() == [0.0, 2.5, 5.0, 10.0]
    assert percentiles([7.0], [50, 99]).tolist() == [7.0, 7.0]
    assert np.isnan(percentiles([1.0, np.nan, 3.0], [10, 90])).all()
    assert distinct(np.array([5, -1, 5, 3, -1])).tolist() == [-1, 3, 5]
    assert distinct(np.array([], np.intp)).tolist() == []


@pytest.mark.parametrize("seed", range(40))
def test_the_same_bits_as_numpy(seed: int) -> None:
    # NumPy's own functions are the independent reference: identical values, dtypes, shapes
    rng = np.random.default_rng(seed)
    n = int(rng.integers(1, 80))
    with_nan = rng.normal(size=(n, 2))
    with_nan[rng.integers(0, n), rng.integers(0, 2)] = np.nan
    cases: list[npt.NDArray[Any]] = [
        rng.normal(size=n) * 10.0 ** rng.integers(-6, 6),
        rng.integers(-(10**15), 10**15, size=n),  # int64 ns differences: the mean in float64
        rng.normal(size=(n, 3)).astype(np.float32),
        np.round(rng.normal(size=(n, 4)), 1),  # ties
        with_nan,
    ]
    for a in cases:
        for axis in [None, *range(a.ndim)]:
            ours, theirs = median(a, axis=axis), np.median(a, axis=axis)
            assert np.asarray(ours).dtype == np.asarray(theirs).dtype
            np.testing.assert_array_equal(ours, theirs)  # bit for bit, NaN where NaN
    q = [50.0, 90.0, 95.0, 99.0, *rng.uniform(0, 100, 4), 0.0, 100.0]
    for a in (cases[0], np.round(cases[0], 1), cases[2].ravel(), with_nan.ravel()):
        np.testing.assert_array_equal(percentiles(a, q), np.percentile(a, q))
        if a.dtype == np.float64:  # one partition for both: each as NumPy's
            both, middle = percentiles_and_median(a, q)
            np.testing.assert_array_equal(both, np.percentile(a, q))
            np.testing.assert_array_equal(middle, np.median(a))
            assert type(middle) is type(np.median(a))
        fractions = np.asarray(q) / 100 + rng.uniform(-1e-3, 1e-3, len(q))
        fractions = np.clip(fractions, 0.0, 1.0)
        np.testing.assert_array_equal(quantiles(a, fractions), np.quantile(a, fractions))
    draws = rng.normal(size=(n + 1, 5))
    draws[rng.random(draws.shape) < 0.2] = np.nan  # draws that could not be scored
    draws[:, 4] = np.nan  # a score no draw gave
    alpha = float(rng.uniform(0.001, 0.2))
    with pytest.warns(RuntimeWarning, match="All-NaN slice"):
        ours = nanquantiles(draws, [alpha, 1 - alpha])
    with pytest.warns(RuntimeWarning, match="All-NaN slice"):
        theirs = np.nanquantile(draws, [alpha, 1 - alpha], axis=0)
    np.testing.assert_array_equal(ours, theirs)
    ints = rng.integers(-5, 5, size=n)
    np.testing.assert_array_equal(distinct(ints), np.unique(ints))


def test_they_import_no_masked_arrays() -> None:
    code = (
        "import sys\n"
        "from ertools.arrays import distinct, median, nanquantiles, percentiles\n"
        "median([1.0, 2.0]); percentiles([1.0, 2.0], [50]); distinct(median([[1, 2]], axis=1))\n"
        "nanquantiles([[1.0], [float('nan')], [3.0]], [0.1, 0.9])\n"
        "print(sorted(sys.modules))\n"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert "'numpy.ma'" not in done.stdout and "'numpy'" in done.stdout


@pytest.mark.parametrize("seed", range(30))
def test_one_place_at_a_time_gives_numpys_bits(seed: int) -> None:
    """median and the quantiles partition at one place at a time where equal values have
    equal bits, and as NumPy does where not (NaN, or -0.0 next to 0.0): NumPy's bits, the
    sign of a zero included, on values with many ties, both zeros, integers and NaN."""
    rng = np.random.default_rng(100 + seed)
    n = int(rng.integers(1, 3000))
    ties = np.round(rng.normal(size=n), 1)
    zeros = ties * rng.choice([0.0, 1.0], size=n)  # +0.0 and -0.0 (negative times 0)
    with_nan = ties.copy()
    with_nan[rng.integers(0, n)] = np.nan
    q = [50.0, 90.0, 95.0, 99.0, *rng.uniform(0, 100, 3), 0.0, 100.0]
    for a in (rng.normal(size=n), ties, np.abs(ties), zeros, with_nan, rng.integers(-9, 9, n)):
        ours, theirs = median(a), np.median(a)
        np.testing.assert_array_equal(ours, theirs)
        assert np.signbit(ours) == np.signbit(theirs)
        got, want = percentiles(a, q), np.percentile(a, q)
        np.testing.assert_array_equal(got, want)
        assert (np.signbit(got) == np.signbit(want)).all()
        if a.dtype == np.float64:
            both, middle = percentiles_and_median(a, q)
            np.testing.assert_array_equal(both, want)
            np.testing.assert_array_equal(middle, theirs)
