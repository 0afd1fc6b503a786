"""A ROS1 bag's index entries as arrays: parsed from its index-data records, and ordered as
rosbags yields the messages of several connections.
"""

from __future__ import annotations

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


def entries_of(parts: list[bytes | tuple[I64, I64]]) -> tuple[I64, Ints, Words | None]:
    """(record times, offsets in their chunks, time words) of one connection's index entries
    over several chunks. Offsets read from index data stay uint32 as stored (widened per
    group, where they are added to the chunk's place in the group's bytes); the time words
    are each entry's (sec, nsec) as one little-endian uint64, the bytes a message record's
    time field must hold (None for entries a scan found)."""
    if not all(isinstance(p, bytes) for p in parts):
        t, off = joined_entries(parts)
        return t, off, None
    arr = np.frombuffer(b"".join(p for p in parts if isinstance(p, bytes)), dtype=INDEX_DTYPE)
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


def merged_order(parts: list[I64]) -> I64 | None:
    """The order of the times ``parts`` (one array per connection, end to end) that a stable
    sort by time gives: equal times keep their connection's rank, then their own order. None
    when they are in that order already.

    Connections logged in time order (each part ascending) are merged by binary search, in
    linear time; otherwise one stable sort.
    """
    t_all = cat_arrays(parts)
    if bool(np.all(t_all[1:] >= t_all[:-1])):
        return None
    if not all(bool(np.all(p[1:] >= p[:-1])) for p in parts):
        return np.argsort(t_all, kind="stable")
    merged_t = parts[0]
    order = np.arange(len(merged_t), dtype=np.int64)
    done = len(merged_t)
    for part in parts[1:]:
        # each entry of ``part`` after every earlier entry of equal time
        at = np.searchsorted(merged_t, part, side="right") + np.arange(len(part))
        n = len(merged_t) + len(part)
        theirs = np.zeros(n, dtype=bool)
        theirs[at] = True
        new_order = np.empty(n, dtype=np.int64)
        new_t = np.empty(n, dtype=np.int64)
        new_order[at] = np.arange(done, done + len(part), dtype=np.int64)
        new_t[at] = part
        new_order[~theirs] = order
        new_t[~theirs] = merged_t
        order, merged_t = new_order, new_t
        done += len(part)
    return order
