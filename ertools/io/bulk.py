"""The fast path: pose topics decoded chunk by chunk with :mod:`ertools.io.decode.fast`.

Per format, the messages of the requested connections are located from the file's own index
(ROS1 index-data records, MCAP message-index records, rosbag2 sqlite rows), in the same order
the reference reader yields them; only chunks that overlap the time window and hold one of
the connections are read, and one uncompressed chunk at a time is held in memory. Anything
the decoders do not handle returns None, and the caller falls back to rosbags (logged at
INFO, visible with ``-v``).
"""

from __future__ import annotations

import logging
from collections.abc import Iterator, Sequence
from typing import TYPE_CHECKING, Any, cast

import numpy as np
import numpy.typing as npt

from ertools.arrays import I64, U8
from ertools.errors import BagError
from ertools.io import pipeline
from ertools.io.assemble import Assembler, Decoder, KnownSpans
from ertools.io.bagfile import BagFile
from ertools.io.decode.fast import (
    FAST_TYPES,
    LayoutMismatchError,
    decode_states,
    is_state_definition,
)
from ertools.io.decode.posebatch import PoseBatch
from ertools.io.model import Conn
from ertools.io.pipeline import (
    Group,
    Located,
    LocatedMany,
    Request,
    Run,
    joined,
    prefetched,
)
from ertools.io.ros1.runs import chunk_group, ros1_runs
from ertools.io.rosbag2.metadata import readable_files, sqlite_rows
from ertools.progress import current

if TYPE_CHECKING:
    # the readers call this module: their classes are annotations here, never imported
    from ertools.io.files import McapFile
    from ertools.io.mcap.index import McapIndex
    from ertools.io.ros1.index import Ros1Bag
    from ertools.progress import Reporter

log = logging.getLogger("ertools.io.bulk")


def mcap_index(bag: BagFile) -> McapIndex | None:
    """The MCAP index of a standalone MCAP file or of a rosbag2-mcap directory's storage
    files (decompressed when the bag is compressed file by file), None for other formats."""
    if bag.format not in ("mcap", "rosbag2-mcap"):
        return None
    from ertools.io.mcap.index import McapIndex  # lazy: 5 ms, MCAP files only

    if bag.format == "rosbag2-mcap":
        return McapIndex([f for f in readable_files(bag.path) if f.suffix == ".mcap"])
    return McapIndex.of(bag)


def _mcap_runs(
    bag: BagFile, requests: Sequence[Request], progress: Reporter | None = None, hold: int = 0
) -> LocatedMany | None:
    index = mcap_index(bag)
    if index is None:
        return None
    plans = index.plan_many(requests)
    count, load, weights = index.run_loader(plans)
    compressed = any(c.compression for plan in plans for chunks in plan.chunks for c in chunks)
    topics = list(dict.fromkeys(c.topic for r in requests for c in r.conns))
    runs = prefetched(
        count,
        load,
        parallel=compressed,
        progress=progress,
        weights=weights,
        label=f"reading {', '.join(topics) or '?'} from {bag.path.name}",
        hold=hold,
    )
    return LocatedMany([len(p.t_record) for p in plans], runs, [p.t_record for p in plans], count)


def _one_by_one(count: int, located: Iterator[tuple[int, Run]]) -> Iterator[list[Run | None]]:
    """Runs of several requests read one request after the other, as :class:`LocatedMany`
    gives them (the other requests None)."""
    for i, run in located:
        out: list[Run | None] = [None] * count
        out[i] = run
        yield out


def _sqlite_runs(bag: BagFile, requests: Sequence[Request]) -> LocatedMany | None:
    found = [sqlite_rows(bag.path, r.conns, r.lo, r.hi) for r in requests]
    if any(f is None for f in found):
        return None

    def runs() -> Iterator[tuple[int, Run]]:
        for i, (req, batches) in enumerate(zip(requests, found, strict=True)):
            assert batches is not None
            cid = req.conns[0].id if req.conns else 0  # rosbag2: one connection per topic
            done = 0
            for buf, start, length, t_rec in batches:
                pos = np.arange(done, done + len(start), dtype=np.int64)
                conn = np.full(len(start), cid, dtype=np.int64)
                yield i, Run(pos, buf, t_rec, conn, KnownSpans(buf, start, length))
                done += len(start)

    return LocatedMany([None] * len(requests), _one_by_one(len(requests), runs()))


def _scanned_runs(bag: BagFile, requests: Sequence[Request]) -> LocatedMany:
    """Messages of an MCAP file its indexes do not cover, read record by record: the runs
    of copied message bytes the scan gives, so the same decoders apply."""
    mcap = cast("McapFile", bag)  # only scanned MCAP files
    every = [list(mcap.scanned_runs(r.conns, r.lo, r.hi)) for r in requests]

    def runs() -> Iterator[tuple[int, Run]]:
        for i, found in enumerate(every):
            for pos, buf, start, length, t_rec, cid in found:
                yield i, Run(pos, buf, t_rec, cid, KnownSpans(buf, start, length))

    counts: list[int | None] = [sum(len(r[0]) for r in found) for found in every]
    return LocatedMany(counts, _one_by_one(len(requests), runs()))


def locate_many(
    bag: BagFile, requests: Sequence[Request], progress: Reporter | None = None, hold: int = 0
) -> LocatedMany | None:
    """The messages of each request (connections, record-time window), located in one pass
    over the file's index and loaded in one pass over the chunks any of them touches; None
    when the format has no bulk access (then the caller reads per message).

    ROS1 and MCAP reads report the bytes of each group of chunks to ``progress`` (default:
    the reporter made current by :func:`ertools.progress.reporting`, if any). A group's runs
    stay valid until ``hold + 1`` more groups are asked for (see
    :func:`ertools.io.pipeline.prefetched`).

    Raises:
        LayoutMismatchError: the file lacks the index records the bulk path needs.
    """
    if progress is None:
        progress = current()
    if bag.format in ("ros1", "ros1-active"):
        return ros1_runs(cast("Ros1Bag", bag), requests, progress, hold)
    if bag.format == "rosbag2-sqlite3":
        return _sqlite_runs(bag, requests)
    if getattr(bag, "scanned", False):
        return _scanned_runs(bag, requests)
    if bag.format in ("mcap", "rosbag2-mcap"):
        return _mcap_runs(bag, requests, progress, hold)
    return None


def locate(
    bag: BagFile,
    conns: Sequence[Conn],
    start_ns: int | None,
    end_ns: int | None,
    progress: Reporter | None = None,
) -> Located | None:
    """The messages of ``conns`` with record time in [start_ns, end_ns]: one request of
    :func:`locate_many`."""
    found = locate_many(bag, [Request(tuple(conns), start_ns, end_ns)], progress)
    return None if found is None else found.only(0)


def load_all_chunks(bag: BagFile, progress: Reporter | None = None) -> int:
    """Uncompressed bytes of every chunk of a ROS1 or MCAP file, loaded through the same
    pipeline as a topic read but not decoded: the floor of any read of that file (what the
    benchmark compares the extraction with on compressed files). The bytes read from the
    file (compressed) are reported to ``progress`` group by group."""
    total = 0
    if bag.format in ("ros1", "ros1-active"):
        ros1 = cast("Ros1Bag", bag)
        chunks = ros1.layout.chunks
        for chunk in chunks:
            if chunk.data_pos < 0:
                ros1.chunk_record(chunk)
        step = max(
            1, pipeline.GROUP_BYTES // max(1, max((c.data_len for c in chunks), default=1) * 4)
        )
        todo = [chunks[i : i + step] for i in range(0, len(chunks), step)]

        def load(k: int, scratch: list[Any]) -> Group:
            return chunk_group(ros1, todo[k], scratch)

        weights = [sum(c.data_len for c in part) for part in todo]
        label = f"reading {bag.path.name}"
        for _buf, _base, sizes in prefetched(
            len(todo), load, progress=progress, weights=weights, label=label
        ):
            total += int(sizes.sum())
        return total
    index = mcap_index(bag)
    if index is None:
        raise BagError(f"no chunks to load in a {bag.format} file", path=bag.path)
    jobs = index.all_chunks()
    step = 4

    def load_mcap(k: int, scratch: list[Any]) -> Group:
        part = jobs[k * step : (k + 1) * step]
        return joined([index.inflated_bytes(path, chunk) for path, chunk in part], scratch)

    count = (len(jobs) + step - 1) // step
    weights = [
        sum(int(c.compressed_size) for _p, c in jobs[k * step : (k + 1) * step])
        for k in range(count)
    ]
    label = f"reading {bag.path.name}"
    for buf, _base, _sizes in prefetched(
        count, load_mcap, progress=progress, weights=weights, label=label
    ):
        total += len(buf)
    return total


def _fast_type(bag: BagFile, conns: Sequence[Conn]) -> str | None:
    """The pose type the bulk decoders read ``conns`` as, None (logged) when they do not."""
    types = {c.msgtype for c in conns}
    encodings = {c.encoding for c in conns}
    if len(types) != 1 or len(encodings) != 1 or next(iter(types)) not in FAST_TYPES:
        log.info(
            "%s: %s decoded per message by rosbags (no bulk decoder)",
            bag.path,
            ", ".join(sorted(types)),
        )
        return None
    return next(iter(types))


def try_fast_batches(bag: BagFile, requests: Sequence[Request]) -> list[PoseBatch | None]:
    """Pose rows of each request decoded in bulk, from one pass over the file; None for a
    request the fast path does not apply to (the caller reads it per message)."""
    out: list[PoseBatch | None] = [None] * len(requests)
    kinds = [_fast_type(bag, r.conns) for r in requests]
    mine = [i for i, k in enumerate(kinds) if k is not None]
    if not mine:
        return out
    # a lone request's runs are decoded on two lanes where their rows have fixed places
    split = bag.format in ("ros1", "mcap")
    try:
        hold = pipeline.lanes_for(len(mine), split)
        found = locate_many(bag, [requests[i] for i in mine], hold=hold)
    except LayoutMismatchError as err:
        log.info("%s: not read in bulk (%s); decoding per message", bag.path, err)
        return out
    if found is None:
        log.info("%s: no bulk reader for %s files; decoding per message", bag.path, bag.format)
        return out
    times = found.times or [None] * len(mine)
    assemblers = [
        Assembler(cast(str, kinds[i]), n, t)
        for i, n, t in zip(mine, found.counts, times, strict=True)
    ]
    decoders: list[Decoder | None] = [
        Decoder(
            cast(str, kinds[i]),
            requests[i].conns[0].encoding == "cdr",
            [c.id for c in requests[i].conns],
            a,
        )
        for i, a in zip(mine, assemblers, strict=True)
    ]
    failed: list[LayoutMismatchError | None] = [None] * len(mine)

    def decode_run(k: int, run: Run) -> None:
        dec = decoders[k]
        if dec is None or failed[k] is not None:
            return
        try:
            dec.run(run)
        except LayoutMismatchError as err:
            failed[k] = err

    # the requests side by side, each on a thread of its own (NumPy releases the GIL); a
    # lone request's groups on two lanes, unless it has one group (the robot's hour: the
    # calling thread decodes it, rather than start two threads and wait for one)
    try:
        split = split and all(a.direct for a in assemblers) and found.groups != 1
        pipeline.decoded_in_lanes(found.runs, decode_run, len(mine), split)
    except LayoutMismatchError as err:
        log.info("%s: not read in bulk (%s); decoding per message", bag.path, err)
        return out
    for k, why in enumerate(failed):
        if why is not None:
            log.info(
                "%s: %s on %s not in the standard layout (%s); decoding per message",
                bag.path,
                kinds[mine[k]],
                requests[mine[k]].conns[0].topic,
                why,
            )
            decoders[k] = None
    for k, i in enumerate(mine):
        if decoders[k] is not None:
            out[i] = assemblers[k].result()
    return out


def try_fast_batch(
    bag: BagFile, conns: Sequence[Conn], start_ns: int | None, end_ns: int | None
) -> PoseBatch | None:
    """Pose rows of ``conns`` decoded in bulk, or None when the fast path does not apply."""
    return try_fast_batches(bag, [Request(tuple(conns), start_ns, end_ns)])[0]


States = tuple[npt.NDArray[np.int64], npt.NDArray[np.uint8], list[str]]


def bulk_states(bag: BagFile, conns: list[Conn]) -> States | None:
    """(record times, states, payloads) decoded in bulk, None when the layout is not the 2015
    one or the format has no bulk access."""
    return bulk_states_many(bag, [conns])[0]


def bulk_states_many(bag: BagFile, topics: Sequence[list[Conn]]) -> list[States | None]:
    """:func:`bulk_states` of several topics, from one pass over the file."""
    out: list[States | None] = [None] * len(topics)
    mine = [
        i
        for i, conns in enumerate(topics)
        if len({c.encoding for c in conns}) == 1
        and all(is_state_definition(c.msgdef) for c in conns)
    ]
    if not mine:
        return out
    try:
        found = locate_many(bag, [Request(tuple(topics[i])) for i in mine])
    except LayoutMismatchError as err:
        log.info("%s: state topics not read in bulk (%s)", bag.path, err)
        return out
    if found is None:
        return out
    parts: list[list[tuple[I64, I64, U8, list[str]]] | None] = [[] for _ in mine]
    try:
        for runs in found.runs:
            for k, run in enumerate(runs):
                got = parts[k]
                if run is None or got is None:
                    continue
                conns = topics[mine[k]]
                try:
                    start, length = run.spans()
                    cdr = conns[0].encoding == "cdr"
                    state, text = decode_states(run.buf, start, length, cdr)
                except LayoutMismatchError as err:
                    log.info(
                        "%s: %s not in the 2015 state layout (%s)", bag.path, conns[0].topic, err
                    )
                    parts[k] = None
                    continue
                got.append((run.pos, run.t_record, state, text))
    except LayoutMismatchError as err:
        log.info("%s: state topics not read in bulk (%s)", bag.path, err)
        return out
    for k, i in enumerate(mine):
        got = parts[k]
        if got is not None:
            out[i] = _ordered_states(got)
    return out


def _ordered_states(parts: list[tuple[I64, I64, U8, list[str]]]) -> States:
    """The runs of one state topic in the reference order, then by record time."""
    if not parts:
        return np.empty(0, np.int64), np.empty(0, np.uint8), []
    pos = np.concatenate([p[0] for p in parts])
    t_all = np.concatenate([p[1] for p in parts])
    payloads = [text for p in parts for text in p[3]]
    order = np.argsort(pos, kind="stable")
    t = t_all[order]
    if len(t) > 1 and np.any(t[1:] < t[:-1]):
        order = order[np.argsort(t, kind="stable")]
        t = t_all[order]
    states = np.concatenate([p[2] for p in parts])[order]
    return t, states, [payloads[i] for i in order.tolist()]
