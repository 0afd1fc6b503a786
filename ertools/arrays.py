"""The array types every module annotates with, defined once.

Times are int64 nanoseconds (:data:`I64`), lengths and angles float64 (:data:`F64`), raw bag
bytes uint8 (:data:`U8`).
"""

from __future__ import annotations

import warnings
from collections.abc import Sequence
from typing import Any, TypeVar

import numpy as np
import numpy.typing as npt

F64 = npt.NDArray[np.float64]
I64 = npt.NDArray[np.int64]
I32 = npt.NDArray[np.int32]
U8 = npt.NDArray[np.uint8]
Bool = npt.NDArray[np.bool_]
IntArr = npt.NDArray[np.intp]

# Fresh memory comes in 4 KiB pages, each a page fault (and, on this project's VMs, an exit to
# the hypervisor: ~1.5 us). NumPy asks the kernel for 2 MiB pages (transparent huge pages,
# ``madvise``) for allocations of 4 MiB and more, but only the 2 MiB-aligned stretches inside
# one get them: an hour's 3.5 MB column of 432,000 times gets none.
HUGE_PAGE = 2 << 20
_HUGE_FROM = 1 << 20


def fresh(n: int, dtype: npt.DTypeLike) -> npt.NDArray[Any]:
    """``np.empty(n, dtype)``, its pages 2 MiB huge pages where the system gives them: an
    array of a megabyte or more is placed at a 2 MiB boundary inside an allocation of whole
    huge pages (at least 4 MiB, so that NumPy advises the kernel), ~500 times fewer page
    faults for the same memory. The spare pages around it are never touched."""
    kind = np.dtype(dtype)
    size = n * kind.itemsize
    if size < _HUGE_FROM:
        return np.empty(n, kind)
    pages = -(-size // HUGE_PAGE) + 1  # whole pages, plus one to align in
    raw = np.empty(max(pages * HUGE_PAGE, 2 * HUGE_PAGE), np.uint8)
    skip = -raw.ctypes.data % HUGE_PAGE
    return raw[skip : skip + size].view(kind)


def fresh_concat(parts: Sequence[npt.NDArray[Any]], dtype: npt.DTypeLike) -> npt.NDArray[Any]:
    """``np.concatenate(parts)`` (1-d parts) as ``dtype``, into :func:`fresh` memory."""
    out = fresh(sum(len(p) for p in parts), dtype)
    at = 0
    for part in parts:
        out[at : at + len(part)] = part
        at += len(part)
    return out


def fresh_repeat(
    values: Sequence[int], counts: Sequence[int], dtype: npt.DTypeLike
) -> npt.NDArray[Any]:
    """``np.repeat(values, counts)`` as ``dtype``, into :func:`fresh` memory."""
    out = fresh(sum(counts), dtype)
    at = 0
    for value, count in zip(values, counts, strict=True):
        out[at : at + count] = value
        at += count
    return out


# np.median, np.percentile, np.quantile, np.nanquantile and np.unique import NumPy's masked
# arrays (``numpy.ma``, ~9 ms of a command's start-up) for a check of their input; these give
# the same numbers without.


def median(values: npt.ArrayLike, axis: int | None = None) -> Any:
    """``np.median(values, axis=axis)``: the middle value, or the mean of the two middle
    values, NaN where a NaN is; the same bits."""
    a = np.asarray(values)
    if axis is None:
        a, axis = a.ravel(), 0
    n = a.shape[axis]
    if n == 0:
        return np.mean(a, axis=axis)  # NaN and "Mean of empty slice", as np.median
    half = n // 2
    middle = [half - 1, half] if n % 2 == 0 else [half]
    if a.ndim == 1 and _orderable(a):
        part = a.copy()
        _select(part, middle)
        return np.mean(np.take(part, middle, axis=axis), axis=axis)
    nan_aware = a.dtype.kind in "fc"
    # NaN sorts last: partitioning at the last place too puts one there when there is one
    part = np.partition(a, [*middle, n - 1] if nan_aware else middle, axis=axis)
    out = np.mean(np.take(part, middle, axis=axis), axis=axis)
    if not nan_aware:
        return out
    last = np.take(part, n - 1, axis=axis)
    nan = np.isnan(last)
    if not nan.any():
        return out
    return last if np.ndim(out) == 0 else np.where(nan, last, out)


def quantiles(values: npt.ArrayLike, q: npt.ArrayLike) -> F64:
    """``np.quantile(values, q)`` of 1-d float values, NumPy's default (linear) method: at
    ``(n - 1) q`` in the sorted values, interpolated between its two neighbours from the nearer
    one; all NaN when a value is NaN. The same bits."""
    return _quantiles(values, q, with_median=False)[0]


def percentiles_and_median(values: npt.ArrayLike, q: Sequence[float]) -> tuple[F64, Any]:
    """(:func:`percentiles`, :func:`median`) of 1-d float64 values, the same bits as each, from
    one partition of one copy instead of two."""
    return _quantiles(values, np.asarray(q, dtype=np.float64) / 100, with_median=True)


def _quantiles(values: npt.ArrayLike, q: npt.ArrayLike, *, with_median: bool) -> tuple[F64, Any]:
    """:func:`quantiles`, and with ``with_median`` :func:`median` of float64 values (the
    middle values are order statistics: the same values wherever else the copy is
    partitioned), else None."""
    a = np.array(values).ravel()  # a copy: partitioned in place
    if a.dtype.kind != "f":
        a = a.astype(np.float64)
    n = len(a)
    if n == 0:
        raise IndexError("quantiles of no values")
    at = (n - 1) * np.asarray(q, dtype=np.float64)
    below = np.floor(at)
    above = below + 1
    # past the last value (q = 1), and before the first: that value itself
    below[at >= n - 1] = above[at >= n - 1] = n - 1
    below[at < 0] = above[at < 0] = 0
    lo_at, hi_at = below.astype(np.intp), above.astype(np.intp)
    half = n // 2
    middle = ([half - 1, half] if n % 2 == 0 else [half]) if with_median else []
    places = np.concatenate([lo_at, hi_at, middle]).astype(np.intp)
    orderable = _orderable(a)
    if orderable:
        _select(a, distinct(places).tolist())
    else:
        a.partition(distinct(np.concatenate([[0, n - 1], places])))
    lo, hi = a[lo_at], a[hi_at]
    t = at - lo_at
    step = hi - lo  # in the values' type, then float64 with t
    out: F64 = np.where(t >= 0.5, hi - step * (1 - t), lo + step * t)
    mid = np.mean(a[middle]) if with_median else None  # as median: the mean of the middle
    if not orderable and np.isnan(a[n - 1]):
        out[:] = np.nan
        mid = a[n - 1] if with_median else None  # median's NaN, the last value
    return out, mid


def _orderable(a: npt.NDArray[Any]) -> bool:
    """Whether the values of ``a`` that sort equal have equal bits (integers, or floats with
    no NaN and no -0.0): each order statistic is then one bit pattern, however the array was
    partitioned to find it."""
    if a.dtype.kind in "iu":
        return True
    if a.dtype.kind != "f":
        return False
    return not (np.isnan(a).any() or (np.signbit(a) & (a == 0)).any())


def _select(a: npt.NDArray[Any], places: Sequence[int]) -> None:
    """Partition ``a`` (1-d) in place so that each of the increasing ``places`` holds its
    order statistic: one partition per place, over the part after the place before (NumPy's
    partition given several places at once takes several times as long: 0.56 against
    0.07 ms for the two middle places of 36,000 values)."""
    start = 0
    for k in places:
        a[start:].partition(k - start)
        start = k + 1


def percentiles(values: npt.ArrayLike, q: Sequence[float]) -> F64:
    """``np.percentile(values, q)``: :func:`quantiles` at ``q / 100``."""
    return quantiles(values, np.asarray(q, dtype=np.float64) / 100)


def nanquantiles(values: npt.ArrayLike, q: Sequence[float]) -> F64:
    """``np.nanquantile(values, q, axis=0)`` of a 2-d array: (len(q), columns), each column's
    :func:`quantiles` of its values that are not NaN; NaN for a column of NaN only."""
    a = np.asarray(values)
    out = np.full((len(q), a.shape[1]), np.nan)
    for col in range(a.shape[1]):  # a score per column: a few
        kept = a[:, col][~np.isnan(a[:, col])]
        if kept.size:
            out[:, col] = quantiles(kept, q)
        else:
            warnings.warn("All-NaN slice encountered", RuntimeWarning, stacklevel=2)
    return out


Int = TypeVar("Int", bound=np.integer[Any])


def distinct(values: npt.NDArray[Int]) -> npt.NDArray[Int]:
    """``np.unique(values)`` of an integer array: its distinct values, sorted."""
    s = np.sort(values, axis=None)
    keep = np.empty(len(s), dtype=bool)
    keep[:1] = True
    np.not_equal(s[1:], s[:-1], out=keep[1:])
    return s[keep]
