"""`ertools.arrays.fresh`: the read's large arrays placed where the kernel can give them huge
pages, and otherwise plain ``np.empty`` arrays (the reads' bit-for-bit tests use them)."""

from __future__ import annotations

import numpy as np
import pytest

from ertools.arrays import HUGE_PAGE, fresh, fresh_concat, fresh_repeat


@pytest.mark.parametrize(
    ("n", "dtype"),
    [(0, np.int64), (5, np.float64), (432_000, np.int64), (3 * 432_000, np.float64), (7, np.uint8)],
)
def test_fresh_is_an_empty_array_of_that_shape_and_type(n: int, dtype: type) -> None:
    a = fresh(n, dtype)
    assert a.shape == (n,)
    assert a.dtype == np.dtype(dtype)
    assert a.flags.c_contiguous and a.flags.writeable
    a[...] = np.arange(n).astype(dtype)  # every element its own: no overlap, all writable
    assert np.array_equal(a, np.arange(n).astype(dtype))


def test_large_arrays_start_on_a_huge_page_inside_whole_huge_pages() -> None:
    # 432,000 int64 (an hour of 120 Hz poses): 3,456,000 bytes, which NumPy alone would
    # place at any 4 KiB page and would not advise as huge (it does so from 4 MiB on)
    a = fresh(432_000, np.int64)
    assert a.ctypes.data % HUGE_PAGE == 0
    base = a.base
    while isinstance(base, np.ndarray) and base.base is not None:
        base = base.base
    assert isinstance(base, np.ndarray)
    assert base.nbytes >= 4 << 20  # NumPy advises huge pages from 4 MiB on
    # the array ends inside the allocation, its last huge page whole: 2 pages + 1 to align
    start = a.ctypes.data - base.ctypes.data
    assert start + 2 * HUGE_PAGE <= base.nbytes
    assert base.nbytes == 3 * HUGE_PAGE


def test_small_arrays_are_not_padded() -> None:
    a = fresh(1000, np.float64)
    assert a.base is None
    assert a.nbytes == 8000


def test_fresh_concat_and_repeat_equal_numpys() -> None:
    rng = np.random.default_rng(3)
    parts = [rng.integers(-(2**62), 2**62, size=k) for k in (0, 1, 200_000, 7)]
    joined = fresh_concat(parts, np.int64)
    assert joined.dtype == np.int64
    assert np.array_equal(joined, np.concatenate(parts))
    values, counts = [3, 70_000, 2], [150_000, 0, 5]
    repeated = fresh_repeat(values, counts, np.int32)
    assert repeated.dtype == np.int32
    assert np.array_equal(repeated, np.repeat(np.array(values, np.int32), counts))
