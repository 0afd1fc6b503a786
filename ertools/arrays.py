"""The array types every module annotates with, defined once.

Times are int64 nanoseconds (:data:`I64`), lengths and angles float64 (:data:`F64`), raw bag
bytes uint8 (:data:`U8`).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

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
