"""A ROS1 bag's index entries as arrays: parsed from its index-data records, and ordered as
rosbags yields the messages of several connections.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
import numpy.typing as npt

from ertools.arrays import I64
from ertools.io.ros1.layout import INDEX_DTYPE, cat_arrays, joined_entries

Ints = npt.NDArray[np.integer[Any]]
Words = npt.NDArray[np.uint64]
# One request's messages, in its reference order: (chunk indices touched, chunk index, conn
# rank, record time, record offset in its chunk, and the record time as its record stores it,
# (sec, nsec) in one uint64, when the index gave it, per message)
Selection = tuple[list[int], Ints, Ints, I64, Ints, Words | None]


def entries_of(
    parts: Sequence[bytes | memoryview | tuple[I64, I64]],
) -> tuple[I64, Ints, Words | None]:
    """(record times, offsets in their chunks, time words) of one connection's index entries
    over several chunks (raw index data, or the entries a scan found). Offsets read from
    index data stay uint32 as stored (widened per group, where they are added to the chunk's
    place in the group's bytes); the time words are each entry's (sec, nsec) as one
    little-endian uint64, the bytes a message record's time field must hold (None for
    entries a scan found)."""
    data = [p for p in parts if not isinstance(p, tuple)]
    if len(data) != len(parts):
        t, off = joined_entries([bytes(p) if not isinstance(p, tuple) else p for p in parts])
        return t, off, None
    arr = np.frombuffer(b"".join(data), dtype=INDEX_DTYPE)
    # Computed in place: fresh memory is slow to fault in, and an hour's entries are 5 MB.
    t = np.multiply(arr["sec"], 1_000_000_000, dtype=np.int64)
    np.add(t, arr["nsec"], out=t)
    words = np.ndarray((len(arr),), "<u8", buffer=arr, strides=(INDEX_DTYPE.itemsize,))
    return t, np.ascontiguousarray(arr["off"]), np.ascontiguousarray(words)


def run_starts(a: Ints) -> I64:
    """Where each run of equal values of ``a`` starts."""
    if not len(a):
        return np.empty(0, np.int64)
    return np.concatenate([[0], np.flatnonzero(a[1:] != a[:-1]) + 1])


def merged_columns(times: list[I64], columns: list[list[Any]]) -> list[npt.NDArray[Any]]:
    """Each column (one array per connection, as ``times``; the first column is ``times``
    itself) end to end in the order a stable sort by ``times`` gives them: equal times keep
    their connection's rank, then their own order.

    Connections logged in time order (each part ascending) are merged one into the others by
    binary search, every column placed by one mask and one scatter (no sort, no gather of the
    whole); otherwise one stable sort of the times orders every column.
    """
    t_all = cat_arrays(times)
    if bool(np.all(t_all[1:] >= t_all[:-1])):
        # already in order (one connection in time order, or none overlapping)
        return [t_all, *(_joined(parts) for parts in columns[1:])]
    if not all(bool(np.all(p[1:] >= p[:-1])) for p in times):
        order = np.argsort(t_all, kind="stable")
        return [t_all[order], *(_joined(parts)[order] for parts in columns[1:])]
    merged = [parts[0] for parts in columns]
    for k in range(1, len(times)):
        # each entry of part k after every earlier entry of equal time
        at = np.searchsorted(merged[0], times[k], side="right") + np.arange(len(times[k]))
        earlier = np.ones(len(merged[0]) + len(times[k]), dtype=bool)
        earlier[at] = False
        out = []
        for column, parts in zip(merged, columns, strict=True):
            new = np.empty(len(earlier), dtype=column.dtype)
            new[earlier] = column
            new[at] = parts[k]
            out.append(new)
        merged = out
    return merged


def _joined(parts: list[Any]) -> npt.NDArray[Any]:
    return parts[0] if len(parts) == 1 else np.concatenate(parts)
