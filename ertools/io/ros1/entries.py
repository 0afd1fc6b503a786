"""A ROS1 bag's index entries as arrays: parsed from its index-data records (each
connection's on a thread of its own), and ordered as rosbags yields the messages of several
connections.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
import numpy.typing as npt

from ertools.arrays import I64, fresh, fresh_repeat
from ertools.io.pipeline import Request, in_window, prefetched
from ertools.io.ros1.layout import (
    INDEX_DTYPE,
    Ros1Layout,
    cat_arrays,
    joined_entries,
    outside_chunk_info,
)

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
    # Fresh memory is slow to fault in (an hour's entries of one topic are 5 MB): the parts are
    # joined into huge pages, the times computed in place, offsets and words left as views.
    joined = fresh(sum(len(p) for p in data), np.uint8)
    at = 0
    for part in data:
        joined[at : at + len(part)] = np.frombuffer(part, np.uint8)
        at += len(part)
    arr = joined.view(INDEX_DTYPE)
    t = fresh(len(arr), np.int64)
    np.multiply(arr["sec"], 1_000_000_000, out=t, dtype=np.int64)
    np.add(t, arr["nsec"], out=t)
    words = np.ndarray((len(arr),), "<u8", buffer=joined, strides=(INDEX_DTYPE.itemsize,))
    return t, arr["off"], words


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
            new = fresh(len(earlier), column.dtype)
            new[earlier] = column
            new[at] = parts[k]
            out.append(new)
        merged = out
    return merged


def _joined(parts: list[Any]) -> npt.NDArray[Any]:
    return parts[0] if len(parts) == 1 else np.concatenate(parts)


Entries = dict[int, tuple[I64, Ints, Ints, Words | None]]


def connection_entries(
    raw: dict[int, list[bytes | memoryview | tuple[I64, I64]]],
    where: dict[int, list[tuple[int, int]]],
    layout: Ros1Layout,
) -> tuple[Entries, str | None]:
    """Per connection of ``raw`` (its index data chunk by chunk; ``where``: (chunk, count) of
    each part): (record times, offsets, chunk index, time words) of its entries, the
    connections side by side on threads (NumPy and the join release the GIL); and why the
    index contradicts its chunk infos, or None."""
    cids = [cid for cid in sorted(raw) if raw[cid]]

    def one(cid: int) -> tuple[I64, Ints, Ints, Words | None] | str:
        t, off, words = entries_of(raw[cid])
        if layout.indexed:
            outside = outside_chunk_info(layout.chunks, cid, t, where[cid])
            if outside is not None:
                return outside
        c = fresh_repeat([w[0] for w in where[cid]], [w[1] for w in where[cid]], np.int32)
        return t, off, c, words

    # (one connection, or a single core: on the calling thread)
    found = list(prefetched(len(cids), lambda k, _scratch: one(cids[k])))
    entries: Entries = {}
    for cid, got in zip(cids, found, strict=True):
        if isinstance(got, str):
            return {}, got
        entries[cid] = got
    return entries, None


def kept(mask: npt.NDArray[np.bool_] | None) -> slice | npt.NDArray[np.bool_] | None:
    """What a window keeps of a connection's entries: None (all of them), a slice (one
    stretch, as a window over time-ordered entries keeps: views, no copies), or the mask."""
    if mask is None:
        return None
    # a count and the first and last True, not the kept positions (an hour's are 3.5 MB of
    # fresh memory, faulted in page by page in a fresh process)
    n = int(np.count_nonzero(mask))
    if n == len(mask):
        return None
    if not n:
        return slice(0, 0)
    first = int(np.argmax(mask))
    last = len(mask) - 1 - int(np.argmax(mask[::-1]))
    return slice(first, last + 1) if last - first + 1 == n else mask


def ordered(request: Request, entries: Entries) -> Selection:
    """One request's messages, in rosbags' order, from every wanted connection's entries."""
    rank = {c.id: i for i, c in enumerate(request.conns)}
    tt: list[I64] = []
    oo: list[Ints] = []
    ck: list[Ints] = []
    ww: list[Words | None] = []
    rk: list[npt.NDArray[np.integer[Any]]] = []
    for cid, r in rank.items():
        if cid not in entries:
            continue
        t, off, c, words = entries[cid]
        keep = kept(in_window(t, request.lo, request.hi))
        if keep is not None:
            t, off, c = t[keep], off[keep], c[keep]
            words = None if words is None else words[keep]
        tt.append(t)
        oo.append(off)
        ck.append(c)
        ww.append(words)
        rk.append(np.full(len(t), r, dtype=np.int8 if len(rank) < 128 else np.int64))
    if not tt or not sum(len(t) for t in tt):
        e = np.empty(0, np.int64)
        return [], e, e, e, e, None
    # each connection's chunk indices ascend (its entries are gathered chunk by chunk)
    touched = sorted({ci for c in ck for ci in c[run_starts(c)].tolist()})
    # rosbags: per connection sorted by time (stable over chunk and index order), then a
    # heap merge over connections in the order given (ties: the earlier connection).
    known = [w for w in ww if w is not None]
    columns: list[list[Any]] = [tt, ck, rk, oo, *([known] if len(known) == len(ww) else [])]
    t_all, c_all, r_all, o_all, *w_all = merged_columns(tt, columns)
    return touched, c_all, r_all, t_all, o_all, (w_all[0] if w_all else None)
