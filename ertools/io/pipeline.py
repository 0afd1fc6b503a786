"""Groups of chunks loaded ahead, on worker threads, into rotating buffers.

Reading a pose topic is three steps per group of chunks: read the bytes, decompress them, and
decode the messages. File reads and lz4/zstd/bz2 decompression release the GIL, so worker
threads load the next groups while the calling thread decodes the current one: on two cores a
topic costs about the larger of decompressing and decoding, not their sum. The topics of one
read are decoded on lanes, a thread each (:func:`decoded_in_lanes`).

Each group is loaded whole into one buffer (its chunks end to end) that is reused once the
caller has moved on, so memory stays at a few groups whatever the size of the file, and fresh
pages are not faulted in for every chunk.
"""

from __future__ import annotations

import contextlib
import mmap
import os
import threading
from collections import Counter, deque
from collections.abc import Callable, Iterable, Iterator, Sequence
from queue import SimpleQueue
from typing import TYPE_CHECKING, Any, Generic, Protocol, TypeVar, cast

import numpy as np

from ertools.arrays import HUGE_PAGE, I64, U8, Bool, fresh
from ertools.cores import workers
from ertools.frozen_dataclass import frozen_dataclass
from ertools.io import mapguard
from ertools.io.model import Conn

if TYPE_CHECKING:
    from ertools.progress import Reporter

T = TypeVar("T")

# A group: (bytes of its chunks end to end, where each chunk starts in them, chunk sizes).
Group = tuple[U8, I64, I64]


def prefetched(
    count: int,
    load: Callable[[int, list[Any]], T],
    *,
    parallel: bool = True,
    progress: Reporter | None = None,
    weights: Sequence[int] = (),
    label: str = "reading",
    hold: int = 0,
) -> Iterator[T]:
    """``load(k, scratch)`` for k in 0..count-1, in order, computed ahead on worker threads.

    ``scratch`` is a slot: a list holding the buffer ``load`` may fill (and grow, see
    :func:`scratch_view`) and maps it read through (:func:`keep`); a result is valid until
    ``hold + 1`` more are asked for (the caller may still be decoding the ``hold`` before the
    one it holds), after which its slot is reused. Without ``parallel`` (reads with nothing
    to decompress: a second thread only competes with the decoder, measured) the loads run in
    turn on the calling thread.

    With ``progress``, ``weights[k]`` (the bytes load k reads from the file) is reported as
    each load is handed over, on the calling thread: one call per group of chunks.
    """
    # nothing to read (a window with no messages): no task, no bar flashing "0 B/0 B"
    report = progress if count and len(weights) == count else None
    if report is not None:
        report.task(label, sum(weights), "B")
    ahead = min(workers(), count) if parallel else 1
    if ahead <= 1:
        turns: list[list[Any]] = [[] for _ in range(hold + 1)]
        for k in range(count):
            got = load(k, turns[k % len(turns)])
            if report is not None:
                report.advance(weights[k])
            yield got
        return

    # ahead groups in flight plus the one the caller holds and the ``hold`` before it: none
    # shares a buffer.
    slots: list[list[Any]] = [[] for _ in range(ahead + 1 + hold)]
    # Loads taken in order by ``ahead`` threads (plain threads: concurrent.futures would
    # import logging, traceback and more for a queue and a result each).
    tasks: SimpleQueue[_Load[T] | None] = SimpleQueue()

    def work() -> None:
        while (task := tasks.get()) is not None:
            task.run(load)
            del task  # (its result is the caller's: no reference kept while waiting)

    threads = [
        threading.Thread(target=work, daemon=True, name=f"ertools-load-{n}") for n in range(ahead)
    ]
    for thread in threads:
        thread.start()
    try:
        pending: deque[_Load[T]] = deque()
        for k in range(ahead):
            pending.append(_Load(k, slots[k % len(slots)]))
            tasks.put(pending[-1])
        for k in range(count):
            got = pending.popleft().result()
            if k + ahead < count:
                pending.append(_Load(k + ahead, slots[(k + ahead) % len(slots)]))
                tasks.put(pending[-1])
            if report is not None:
                report.advance(weights[k])
            yield got
    finally:
        # loads in flight finish before their buffers can be let go (and no thread outlives
        # the read)
        for _thread in threads:
            tasks.put(None)
        for thread in threads:
            thread.join()


class _Load(Generic[T]):
    """Load ``k`` into ``scratch`` on a loading thread: its result, or the error it raised,
    once done."""

    def __init__(self, k: int, scratch: list[Any]) -> None:
        self.k, self.scratch = k, scratch
        self.done = threading.Event()
        self.value: T | None = None
        self.error: BaseException | None = None

    def run(self, load: Callable[[int, list[Any]], T]) -> None:
        try:
            self.value = load(self.k, self.scratch)
        except BaseException as err:  # raised by the caller (as itself)
            self.error = err
        finally:
            self.done.set()

    def result(self) -> T:
        self.done.wait()
        if self.error is not None:
            try:
                raise self.error
            finally:
                self.error = None  # (no cycle through the traceback's frames)
        return cast(T, self.value)


# Groups a lane of :func:`decoded_in_lanes` may lag behind the one being loaded.
LANE_HOLD = 1


def lanes_for(count: int, split: bool = False) -> int:
    """The ``hold`` a read of ``count`` requests passes to its loads: :data:`LANE_HOLD` when
    :func:`decoded_in_lanes` runs them on lanes, else 0."""
    return LANE_HOLD if (count > 1 or (split and count == 1)) and workers() > 1 else 0


def decoded_in_lanes(
    groups: Iterable[Sequence[T | None]],
    decode: Callable[[int, T], None],
    count: int,
    split: bool = False,
) -> None:
    """``decode(i, item)`` for every item of every group, item i (request i's run) of each
    group on lane i: a thread of its own that takes request i's runs in group order. The
    requests of a group, and of the group before it, are so decoded side by side with no
    wait for the slowest at every group: NumPy releases the GIL in its loops, and each
    request has its own decoder and result. A group is asked for only once the group
    :data:`LANE_HOLD` + 1 before it is decoded (its buffer is reused then: ``groups`` comes
    from loads made with ``hold`` = :func:`lanes_for`).

    With ``split`` (``decode`` may run on two groups of one request at once: its rows go to
    places of their own), a lone request's groups alternate between two lanes, so one source
    is decoded on two cores too.

    The error raised is the one a single thread decoding the groups in turn, items in request
    order, meets first (a load's error comes after the decoding errors of the groups before
    it); no group after it is asked for.
    """
    if lanes_for(count, split) == 0:
        for group in groups:
            for i, item in enumerate(group):
                if item is not None:
                    decode(i, item)
        return
    lanes = count if count > 1 else 2
    cond = threading.Condition()
    outstanding: Counter[int] = Counter()
    errors: list[tuple[int, int, Exception]] = []
    queues: list[SimpleQueue[tuple[int, int, T] | None]] = [SimpleQueue() for _ in range(lanes)]

    def lane(n: int) -> None:
        while (got := queues[n].get()) is not None:
            k, i, item = got
            try:
                with cond:
                    after = any(e[0] < k for e in errors)  # one thread had stopped before
                if not after:
                    decode(i, item)
            except Exception as err:  # raised by the caller, in order
                with cond:
                    errors.append((k, i, err))
            finally:
                # the run is let go before waiting for the next: its buffer (a map) can then
                # be closed when its slot is reused
                del got, item
                with cond:
                    outstanding[k] -= 1
                    cond.notify_all()

    threads = [
        threading.Thread(target=lane, args=(n,), daemon=True, name=f"ertools-lane-{n}")
        for n in range(lanes)
    ]
    for thread in threads:
        thread.start()
    k = 0
    try:
        for group in groups:
            for i, item in enumerate(group):
                if item is not None:
                    with cond:
                        outstanding[k] += 1
                    queues[i if count > 1 else k % lanes].put((k, i, item))
            k += 1
            reused = k - 1 - LANE_HOLD  # the group whose buffer the next load reuses
            with cond:
                while not errors and outstanding[reused]:
                    cond.wait()
                if errors:
                    break
    except Exception as err:  # a load's: after the lanes' errors of earlier groups
        with cond:
            errors.append((k, -1, err))
    finally:
        for q in queues:
            q.put(None)
        for thread in threads:
            thread.join()
    if errors:
        raise min(errors, key=lambda e: (e[0], e[1]))[2]


def scratch_view(scratch: list[Any], size: int) -> memoryview:
    """The first ``size`` bytes of the reused buffer (grown when too small).

    A slot is ``[buffer, *maps]`` (the buffer a uint8 array): maps a load read through
    (``keep``) are released here, when the slot is reused.
    """
    release(scratch)
    if not scratch or len(scratch[0]) < size:
        # not zero-filled, in huge pages, whole ones (fewer regrowths: groups vary in size)
        buffer = fresh(-(-size // HUGE_PAGE) * HUGE_PAGE, np.uint8)
        if scratch:
            scratch[0] = buffer
        else:
            scratch.append(buffer)
    return memoryview(scratch[0])[:size]


def keep(scratch: list[Any], mapping: mmap.mmap, path: object) -> None:
    """Hold ``mapping`` (of ``path``) in the slot until the slot is reused; while it is
    held, the file cut short ends the process in one error line (:mod:`mapguard`)."""
    release(scratch)
    if not scratch:
        scratch.append(np.empty(0, np.uint8))
    mapguard.watch(mapping, path)
    scratch.append(mapping)


def release(scratch: list[Any]) -> None:
    for old in scratch[1:]:
        mapguard.unwatch(old)
        with contextlib.suppress(BufferError):  # a view still alive keeps it until collected
            old.close()
    del scratch[1:]


def joined(parts: Sequence[bytes], scratch: list[Any]) -> Group:
    """Chunks' uncompressed bytes copied end to end into the reused buffer."""
    sizes = np.array([len(p) for p in parts], dtype=np.int64)
    base = np.zeros(len(parts), dtype=np.int64)
    np.cumsum(sizes[:-1], out=base[1:])
    total = int(sizes.sum())
    out = np.frombuffer(scratch_view(scratch, total), dtype=np.uint8)
    for at, part in zip(base.tolist(), parts, strict=True):
        # a NumPy copy releases the GIL (a memoryview copy holds it): the decoder runs meanwhile
        out[at : at + len(part)] = np.frombuffer(part, dtype=np.uint8)
    return out, base, sizes


_SEEK_LOCK = threading.Lock()


def read_at(fd: int, into: memoryview, offset: int) -> int:
    """Read into ``into`` from ``offset`` without racing other threads over the file
    position: a positional read where the system has one, else seek + read under a lock
    (Windows). Returns the bytes read (fewer at the end of the file)."""
    if hasattr(os, "preadv"):
        return os.preadv(fd, [into], offset)
    data = pread(fd, len(into), offset)
    into[: len(data)] = data
    return len(data)


def pread(fd: int, size: int, offset: int) -> bytes:
    """``size`` bytes from ``offset`` (fewer at the end of the file), thread-safe."""
    if hasattr(os, "pread"):
        return os.pread(fd, size, offset)
    with _SEEK_LOCK:
        os.lseek(fd, offset, os.SEEK_SET)
        parts = []
        while size > 0:
            part = os.read(fd, size)
            if not part:
                break
            parts.append(part)
            size -= len(part)
        return b"".join(parts)


# Uncompressed bytes decoded in one go (chunks are ~768 KiB): large enough that the per-call
# overhead of NumPy vanishes, small enough to keep memory bounded.
GROUP_BYTES = 4 * 1024 * 1024


def ascending(a: I64) -> bool:
    return bool(np.all(a[1:] > a[:-1]))


def group_positions(keys: I64) -> list[tuple[int, I64]]:
    """(key, positions) for each distinct key, positions ascending (one sort, not N scans)."""
    if len(keys) == 0:
        return []
    if bool(np.all(keys[1:] >= keys[:-1])):
        order = np.arange(len(keys), dtype=np.int64)  # already grouped (one connection)
    else:
        order = np.argsort(keys, kind="stable")
    sorted_keys = keys[order]
    cuts = np.flatnonzero(sorted_keys[1:] != sorted_keys[:-1]) + 1
    starts = np.concatenate([[0], cuts])
    ends = np.concatenate([cuts, [len(keys)]])
    return [(int(sorted_keys[a]), order[a:b]) for a, b in zip(starts, ends, strict=True)]


class Records(Protocol):
    """Where the data of a run's messages lies in its buffer, found and checked by the format
    that located them (ROS1 message records, MCAP message records, or spans known already)."""

    def spans(self) -> tuple[I64, I64]:
        """(data start, data length) of every message, each record checked (the general
        path: any record layout the format allows; a damaged record raises BagError)."""
        ...

    def size_hint(self, i: int) -> int | None:
        """The data length of message ``i`` as its record's head gives it, unchecked (what
        :meth:`rows` is then asked for and checks); None when the head is unusual."""
        ...

    def rows(
        self, idx: I64 | None, size: int, conn: int, member: Bool | None = None
    ) -> tuple[U8, int] | None:
        """The messages ``idx`` (None: all), all of connection ``conn``, as rows of one
        gather: ``(rows, skip)``, each row the record's head (``skip`` bytes) then its
        ``size`` data bytes, when every one of them is a record in the format's usual layout
        whose data is ``size`` bytes long and whose head carries the time (and connection) it
        was located by. None otherwise: the caller then goes through :meth:`spans`, which
        handles (or refuses) every other case.

        With ``member`` (``idx`` None), only the messages where it is True must be so; the
        others are gathered as far as the width reaches (inside the buffer), unchecked."""
        ...


@frozen_dataclass(eq=False)
class Run:
    """The messages of one read in one group of chunks, in its reference order.

    ``pos``: each message's reference position in the whole read; ``buf``: the group's bytes
    (valid only until the next run of the same read is asked for: it may be reused);
    ``t_record``: record times; ``conn``: each message's connection id; ``records``: how to
    find each message's data in ``buf``; ``consecutive``: ``pos`` is known to be a range.
    """

    pos: I64
    buf: U8
    t_record: I64
    conn: I64
    records: Records
    consecutive: bool = False

    def spans(self) -> tuple[I64, I64]:
        return self.records.spans()


@frozen_dataclass
class Located:
    """Messages of some connections located from a file's index, in the reference order.

    ``count`` is the number of messages when the index tells it up front (ROS1, MCAP), None
    otherwise (sqlite rows come as they are fetched); ``runs`` reads the data a few chunks at
    a time.
    """

    count: int | None
    runs: Iterator[Run]


@frozen_dataclass
class Request:
    """One read of several sharing a pass over a file: some connections, and the record
    time window [lo, hi] (None: open) of their messages."""

    conns: tuple[Conn, ...]
    lo: int | None = None
    hi: int | None = None


@frozen_dataclass
class LocatedMany:
    """The messages of several requests located in one pass over a file's index.

    ``counts[i]`` is request i's number of messages (None: unknown up front), ``times[i]``
    their record times in the reference order when the index gives them up front; each item
    of ``runs`` is one group of chunks loaded once, with one :class:`Run` per request (None
    for a request with no message in that group); ``groups`` is how many there are, when
    known up front.
    """

    counts: list[int | None]
    runs: Iterator[list[Run | None]]
    times: list[I64 | None] | None = None
    groups: int | None = None

    def only(self, i: int) -> Located:
        """Request ``i`` alone (the others' runs are skipped, their groups still loaded)."""

        def runs() -> Iterator[Run]:
            for group in self.runs:
                run = group[i]
                if run is not None:
                    yield run

        return Located(self.counts[i], runs())


def window(requests: Sequence[Request]) -> tuple[int | None, int | None]:
    """The record-time window covering every request's."""
    los = [r.lo for r in requests if r.lo is not None]
    his = [r.hi for r in requests if r.hi is not None]
    lo = min(los) if los and len(los) == len(requests) else None
    hi = max(his) if his and len(his) == len(requests) else None
    return lo, hi


def in_window(t: I64, lo: int | None, hi: int | None) -> Bool | None:
    """Which of ``t`` lie in [lo, hi]; None when the window is open on both sides."""
    if lo is None and hi is None:
        return None
    keep = np.ones(len(t), dtype=bool)
    if lo is not None:
        keep &= t >= lo
    if hi is not None:
        keep &= t <= hi
    return keep
