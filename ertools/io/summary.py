"""``summary(path)``: what a bag holds, from the file's own index, without message data.

- ROS1: the bag header record, then the connection and chunk-info records at the index
  position (plus the first chunk's record header for its compression). A bag with no index
  (``.bag.active``) or a damaged or truncated one is scanned record by record instead and
  flagged (``indexed=False``, ``problems``).
- MCAP: the summary section (statistics, channels, schemas, chunk indexes, message indexes)
  where it answers for every message (:func:`ertools.io.mcap.scan.mcap_layout`); any other
  layout the specification allows (no summary, no statistics, no message indexes, channels
  only inside chunks, messages outside chunks) is read record by record, exactly
  (``index="scan"``, ``indexed=False``); only a file cut short is flagged in ``problems``.
- rosbag2: ``metadata.yaml`` (plus the MCAP summaries of its files for per-topic times).

Per-topic first/last times come from the chunk bounds (exact to the chunk) unless
``exact=True``, which reads the per-message index records (ROS1 index data, MCAP message
indexes, sqlite rows' time stamps) - still no message data. :func:`record_times` gives those
per-message record times, for rates.
"""

from __future__ import annotations

import logging
from collections import defaultdict
from pathlib import Path
from typing import Any

import numpy as np

from ertools.arrays import I64
from ertools.errors import BagError
from ertools.inputs import open_regular
from ertools.io.decode.fast import LayoutMismatchError, gather
from ertools.io.formats import detect_format
from ertools.io.model import BagSummary, TopicSummary, short_msgtype
from ertools.io.ros1.index import Ros1Bag
from ertools.io.ros1.layout import read_layout
from ertools.io.rosbag2.metadata import read_metadata, readable_files, storage_files

log = logging.getLogger("ertools.io.summary")


def _size(path: Path) -> int:
    if path.is_dir():
        return sum(f.stat().st_size for f in path.rglob("*") if f.is_file())
    return path.stat().st_size


def _build(
    path: Path,
    fmt: str,
    version: str,
    compression: str,
    indexed: bool,
    topics: dict[str, tuple[str, int, int | None, int | None, int]],
    problems: list[str],
    index: str = "",
) -> BagSummary:
    if not index:
        index = {"ros1": "index-records", "ros1-active": "index-records"}.get(fmt, "metadata.yaml")
        index = index if indexed else "scan"
    tops = tuple(
        TopicSummary(name, msgtype, count, first, last, nconn)
        for name, (msgtype, count, first, last, nconn) in sorted(topics.items())
    )
    firsts = [t.first_ns for t in tops if t.first_ns is not None and t.count]
    lasts = [t.last_ns for t in tops if t.last_ns is not None and t.count]
    start = min(firsts) if firsts else 0
    end = max(lasts) if lasts else 0
    return BagSummary(
        str(path),
        fmt,
        version,
        start,
        end,
        end - start,
        _size(path),
        compression,
        sum(t.count for t in tops),
        indexed,
        tops,
        tuple(problems),
        index,
    )


def _merge_topic(
    topics: dict[str, tuple[str, int, int | None, int | None, int]],
    name: str,
    msgtype: str,
    count: int,
    first: int | None,
    last: int | None,
) -> None:
    old = topics.get(name)
    if old is None:
        topics[name] = (msgtype, count, first, last, 1)
        return
    f = [x for x in (old[2], first) if x is not None]
    la = [x for x in (old[3], last) if x is not None]
    topics[name] = (
        old[0],
        old[1] + count,
        min(f) if f else None,
        max(la) if la else None,
        old[4] + 1,
    )


Times = dict[str, list[I64]]


def _ros1(path: Path, fmt: str, exact: bool, times: Times | None = None) -> BagSummary:
    layout = read_layout(path)
    compressions: set[str] = set()
    spans: dict[int, list[int]] = {}
    counts: dict[int, int] = defaultdict(int)
    topic_of = {c.id: c.topic for c in layout.conns}
    index_problems: list[str] = []
    if layout.chunks:
        # Ros1Bag refuses damaged closed bags for reading; the summary wants what is there.
        bag = Ros1Bag(path, layout, strict=False)
        try:
            chunks = layout.chunks if exact or not layout.indexed else layout.chunks[:1]
            for chunk in chunks:
                if not chunk.compression:
                    bag.chunk_record(chunk)
                compressions.add(chunk.compression)
            for chunk in layout.chunks:
                if exact or chunk.entries is not None:
                    entries = bag.chunk_entries(chunk)
                    index_problems.extend(_ros1_index_disagrees(chunk, entries))
                    for cid, (t, _off) in entries.items():
                        if times is not None:
                            times.setdefault(topic_of.get(cid, f"conn {cid}"), []).append(t)
                        if len(t):
                            s = spans.setdefault(cid, [int(t.min()), int(t.max())])
                            s[0], s[1] = min(s[0], int(t.min())), max(s[1], int(t.max()))
                else:
                    for cid in chunk.counts:
                        s = spans.setdefault(cid, [chunk.start_ns, chunk.end_ns])
                        s[0], s[1] = min(s[0], chunk.start_ns), max(s[1], chunk.end_ns)
                for cid, n in chunk.counts.items():
                    counts[cid] += n
            if exact and layout.indexed and not index_problems:
                index_problems.extend(_ros1_check_ends(bag, layout.chunks, spans))
        finally:
            bag.close()
    topics: dict[str, tuple[str, int, int | None, int | None, int]] = {}
    for c in layout.conns:
        span = spans.get(c.id)
        _merge_topic(topics, c.topic, c.msgtype, counts.get(c.id, 0), *(span or (None, None)))
    return _build(
        path,
        fmt,
        "2.0",
        "/".join(sorted(compressions)) or "none",
        layout.indexed,
        topics,
        [*layout.problems, *index_problems[:MAX_INDEX_PROBLEMS]],
    )


# A wholly wrong index says so in a few lines, not one per chunk.
MAX_INDEX_PROBLEMS = 5
# Ends each such line: ``info --check`` replaces them by its record-level lines.
INDEX_SELF_CHECK = "(damaged index; info --check reads the records)"
# Ends a line on a chunk that does not decompress (damaged, or over the budget): info --check
# says the same of every chunk.
CHUNK_SELF_CHECK = "(info --check reads every chunk)"


def _ros1_check_ends(bag: Any, chunks: list[Any], spans: dict[int, list[int]]) -> list[str]:
    """Each connection's first and last times, as its index data gives them, are its
    records': the index entries of the chunks that start no later than a connection's
    first time or end no earlier than its last (the chunks that could hold an earlier or
    later message: one or two) are checked against their records (conn and time). A damaged
    entry time elsewhere leaves counts and span as they were; one there would move the
    topic's span (found by fuzzing). Decompresses those few chunks only."""
    for chunk in chunks:
        bounding = [
            cid
            for cid in chunk.counts
            if cid in spans and (chunk.start_ns <= spans[cid][0] or chunk.end_ns >= spans[cid][1])
        ]
        if not bounding:
            continue
        where = f"in {bag.path} at byte {chunk.pos}"
        try:
            data = bag.chunk_bytes(chunk)
        except BagError as err:  # damaged data or over the budget, not a damaged index
            return [f"{err.message} {CHUNK_SELF_CHECK}"]
        try:
            buf = np.frombuffer(data, dtype=np.uint8)
            entries = bag.chunk_entries(chunk)
            found = [(cid, *entries[cid]) for cid in bounding if cid in entries]
            if found:
                # one check of every bounding connection's entries: a call per connection
                # cost 0.26 ms each (40,000 connections: 10 s)
                t = np.concatenate([f[1] for f in found])
                off = np.concatenate([f[2] for f in found])
                conn = np.repeat([f[0] for f in found], [len(f[1]) for f in found])
                bag.checked_spans(buf, off, t, conn.astype(np.int64), where)
        except BagError as err:
            return [f"chunk at byte {chunk.pos}: {err.message} {INDEX_SELF_CHECK}"]
    return []


def _ros1_index_disagrees(chunk: Any, entries: dict[int, tuple[I64, I64]]) -> list[str]:
    """Where a chunk's two index records contradict each other: the chunk-info record's
    per-connection counts and time span against the index-data records' entries. A summary
    read from either alone would report counts or times no record holds (found by fuzzing:
    one flipped count or time changed ``info`` with exit 0); ``info --check`` compares both
    with the records themselves."""
    out = []
    where = f"chunk at byte {chunk.pos}"
    for cid in sorted(set(entries) | set(chunk.counts)):
        t = entries.get(cid, (np.empty(0, np.int64), None))[0]
        said = chunk.counts.get(cid, 0)
        if len(t) != said:
            out.append(
                f"{where}: connection {cid}: the chunk info counts {said} messages, the index "
                f"data {len(t)} {INDEX_SELF_CHECK}"
            )
        elif len(t) and (int(t.min()) < chunk.start_ns or int(t.max()) > chunk.end_ns):
            out.append(
                f"{where}: connection {cid}: index-data times outside the chunk info's span "
                + INDEX_SELF_CHECK
            )
    return out


def _mcap_scanned(
    path: Path, why: str, times: Times | None = None
) -> tuple[dict[str, tuple[str, int, int | None, int | None, int]], set[str], list[str]]:
    """Topics of an MCAP file read record by record (chunks decompressed): the path for
    layouts the summary cannot answer for alone, exact for all of them."""

    from ertools.io.mcap.scan import scan_mcap  # lazy: 5 ms, MCAP files only

    log.info("%s: %s; reading the file record by record", path, why)
    found = scan_mcap(path)
    problems = [found.problem] if found.problem else []
    cids, t = found.channel_id, found.log_time
    orphans = sorted(set(np.unique(cids).tolist()) - set(found.channels))
    if orphans:
        n = int(np.isin(cids, orphans).sum())
        problems.append(f"{n} messages on channel ids without a channel record: {orphans}")
    topics: dict[str, tuple[str, int, int | None, int | None, int]] = {}
    for cid, ch in sorted(found.channels.items()):
        mine = t[cids == cid]
        schema = found.schemas.get(ch.schema_id)
        if times is not None and len(mine):
            times.setdefault(ch.topic, []).append(mine)
        _merge_topic(
            topics,
            ch.topic,
            short_msgtype(schema.name if schema else ""),
            len(mine),
            int(mine.min()) if len(mine) else None,
            int(mine.max()) if len(mine) else None,
        )
    return topics, set(found.compressions), problems


def _mcap_indexed(
    path: Path, layout: Any, exact: bool, times: Times | None = None
) -> tuple[dict[str, tuple[str, int, int | None, int | None, int]], set[str], list[str], str]:
    """Topics from the summary: counts from the statistics, or from the message indexes when
    ``exact`` or when the summary has no statistics (then every message is counted)."""

    from ertools.io.mcap.index import McapIndex  # lazy: 5 ms, MCAP files only

    summary = layout.summary
    spans: dict[int, list[int]] = {}
    compressions = set()
    recorded = stats = summary.statistics
    if (
        stats is not None
        and stats.channel_message_counts
        and sum(stats.channel_message_counts.values()) != stats.message_count
    ):
        # damaged statistics (a per-channel count that is no longer part of the total):
        # count from the message indexes instead, as for a file without statistics
        log.warning("%s: MCAP statistics do not add up; counting from the indexes", path)
        stats = None
    read_indexes = exact or stats is None
    counts: dict[int, int] = {} if read_indexes else dict(stats.channel_message_counts)
    # channel -> (chunk, message index offset) of every chunk holding it
    located: dict[int, list[tuple[Any, int]]] = {}
    with open_regular(path) as f:
        for chunk in summary.chunk_indexes:
            compressions.add(chunk.compression or "none")
            for cid, offset in chunk.message_index_offsets.items():
                if cid not in layout.channels:
                    raise BagError(
                        f"chunk index at byte {chunk.chunk_start_offset} names channel {cid}, "
                        "which the file does not declare",
                        path=path,
                    )
                if read_indexes:
                    t, _ = McapIndex._message_index(f, path, offset, cid, padded=False)
                    if times is not None:
                        times.setdefault(layout.channels[cid].topic, []).append(t)
                    counts[cid] = counts.get(cid, 0) + len(t)
                    if not len(t):
                        continue
                    lo, hi = int(t.min()), int(t.max())
                    located.setdefault(cid, []).append((chunk, offset))
                    if lo < chunk.message_start_time or hi > chunk.message_end_time:
                        # a damaged index entry: its time is outside its own chunk's span
                        raise BagError(
                            f"message index of channel {cid} at byte {offset} has times "
                            f"outside its chunk's (chunk at byte {chunk.chunk_start_offset})",
                            path=path,
                        )
                else:
                    lo, hi = int(chunk.message_start_time), int(chunk.message_end_time)
                s = spans.setdefault(cid, [lo, hi])
                s[0], s[1] = min(s[0], lo), max(s[1], hi)
    _check_ends(path, located, spans)
    problems = []
    if read_indexes and recorded is not None and recorded.message_count != sum(counts.values()):
        problems.append(
            f"the statistics record counts {recorded.message_count} messages, the message "
            f"indexes {sum(counts.values())}"
        )
    topics: dict[str, tuple[str, int, int | None, int | None, int]] = {}
    for cid, ch in sorted(layout.channels.items()):
        schema = layout.schemas.get(ch.schema_id)
        span = spans.get(cid)
        _merge_topic(
            topics,
            ch.topic,
            short_msgtype(schema.name if schema else ""),
            int(counts.get(cid, 0)),
            *(span or (None, None)),
        )
    index = "summary+message-indexes" if read_indexes and summary.chunk_indexes else "summary"
    return topics, compressions, problems, index


def _check_ends(
    path: Path, located: dict[int, list[tuple[Any, int]]], spans: dict[int, list[int]]
) -> None:
    """Each channel's first and last log times, as its message indexes give them, are its
    records': every index entry of the channel is checked against its record in each chunk
    that starts no later than the channel's first time or ends no earlier than its last
    (the chunks that could hold an earlier or later message: one or two per channel). A
    damaged entry elsewhere leaves counts and span as they were; one in those chunks would
    move the topic's reported span. Reads those few chunks (each checked against its CRC).

    Raises:
        BagError: an index entry and its record disagree.
    """
    from ertools.io.mcap.index import McapIndex  # lazy: 5 ms, MCAP files only

    chunks: dict[int, np.ndarray] = {}
    with open_regular(path) as f:
        for cid, where in located.items():
            lo, hi = spans[cid]
            for chunk, offset in where:
                if chunk.message_start_time > lo and chunk.message_end_time < hi:
                    continue
                key = int(chunk.chunk_start_offset)
                if key not in chunks:
                    raw = McapIndex.inflated_bytes(path, chunk)
                    chunks[key] = np.frombuffer(raw, dtype=np.uint8)
                buf = chunks[key]
                t, off = McapIndex._message_index(f, path, offset, cid)
                head = 1 + 8 + 2 + 4 + 8  # op, length, channel, sequence, log time
                ok = not len(off) or (int(off.min()) >= 0 and int(off.max()) + head <= len(buf))
                if ok and len(off):
                    rows = gather(buf, off, head)
                    n = len(off)
                    channel = np.ndarray((n,), "<u2", buffer=rows, offset=9, strides=(head,))
                    log_time = np.ndarray((n,), "<u8", buffer=rows, offset=15, strides=(head,))
                    ok = bool(
                        np.all(rows[:, 0] == 0x05)
                        and np.all(channel == cid)
                        and np.all(log_time.astype(np.int64) == t)
                    )
                if not ok:
                    raise BagError(
                        f"message index of channel {cid} (chunk at byte {key}) disagrees with "
                        "the records it points at: damaged index or chunk",
                        path=path,
                    )


def _mcap_file(
    path: Path, exact: bool, times: Times | None = None
) -> tuple[dict[str, tuple[str, int, int | None, int | None, int]], set[str], list[str], str]:
    """(topics, chunk compressions, problems, index used) of one MCAP file, through its
    indexes where they answer for every message, else record by record."""
    from ertools.io.mcap.scan import SCAN, mcap_layout  # lazy: 5 ms, MCAP files only

    layout = mcap_layout(path)
    if layout.index != SCAN:
        mine: Times | None = None if times is None else {}
        try:
            found = _mcap_indexed(path, layout, exact, mine)
        except LayoutMismatchError as err:
            why = str(err)  # a padded message index: counted record by record
        else:
            if times is not None and mine is not None:
                for topic, parts in mine.items():
                    times.setdefault(topic, []).extend(parts)
            return found
    else:
        why = layout.why
    topics, compressions, problems = _mcap_scanned(path, why, times)
    return topics, compressions, problems, SCAN


def _mcap_version(path: Path) -> str:
    from mcap.reader import make_reader  # lazy: mcap, 90 ms

    from ertools.io.mcap.summary import mcap_errors  # lazy: 5 ms, MCAP files only

    try:
        with open_regular(path) as f:
            header = make_reader(f).get_header()
    except mcap_errors():
        return ""
    return f"mcap0 profile {header.profile or 'none'} ({header.library})"


def _mcap(path: Path, exact: bool, times: Times | None = None) -> BagSummary:
    topics, compressions, problems, index = _mcap_file(path, exact, times)
    compression = "/".join(sorted(compressions)) or "none"
    indexed = index != "scan"
    return _build(path, "mcap", _mcap_version(path), compression, indexed, topics, problems, index)


def _rosbag2(path: Path, fmt: str, exact: bool, times: Times | None = None) -> BagSummary:
    info = read_metadata(path)
    problems = []
    files = storage_files(path, info)
    missing = [f.name for f in files if not f.exists()]
    if missing:
        problems.append(f"storage file(s) listed in metadata.yaml missing: {', '.join(missing)}")
    else:
        files = readable_files(path, info)
    topics: dict[str, tuple[str, int, int | None, int | None, int]] = {}
    inner: set[str] = set()
    used: set[str] = set()
    if fmt == "rosbag2-mcap" and not missing:
        for file in files:
            part, chunk_compressions, file_problems, file_index = _mcap_file(file, exact, times)
            used.add(file_index)
            problems.extend(f"{file.name}: {p}" for p in file_problems)
            inner |= chunk_compressions - {"none"}
            for name, (msgtype, count, first, last, _n) in part.items():
                _merge_topic(topics, name, msgtype, count, first, last)
        topics = {k: (v[0], v[1], v[2], v[3], 1) for k, v in topics.items()}
    else:
        start = int(info.get("starting_time", {}).get("nanoseconds_since_epoch", 0))
        duration = int(info.get("duration", {}).get("nanoseconds", 0))
        spans: dict[str, tuple[int, int]] = {}
        if exact and not missing:
            spans = _sqlite_spans(files)
        for entry in info.get("topics_with_message_count", []):
            meta = entry["topic_metadata"]
            count = int(entry.get("message_count", 0))
            default: tuple[int | None, int | None] = (
                (start, start + duration) if count else (None, None)
            )
            first, last = spans.get(meta["name"], default)
            topics[str(meta["name"])] = (short_msgtype(str(meta["type"])), count, first, last, 1)
    compression = str(info.get("compression_format") or "none")
    if info.get("compression_mode"):
        compression += f" ({str(info['compression_mode']).lower()})"
    if inner and compression == "none":
        compression = "/".join(sorted(inner)) + " (mcap chunks)"
    # the MCAP storage files' own indexes (or scans) gave the counts and times
    index = "+".join(["metadata.yaml", *sorted(used)])
    return _build(
        path, fmt, str(info.get("version", "")), compression, True, topics, problems, index
    )


def _sqlite_spans(files: list[Path]) -> dict[str, tuple[int, int]]:
    from ertools.io.rosbag2.sqlite_storage import query  # lazy: sqlite3 1.5 ms, .db3 only

    out: dict[str, tuple[int, int]] = {}
    for db in files:
        rows = query(
            db,
            "SELECT topics.name, MIN(timestamp), MAX(timestamp) FROM messages "
            "JOIN topics ON topics.id = messages.topic_id GROUP BY topics.name",
        )
        for name, lo, hi in rows:
            old = out.get(name)
            out[name] = (min(lo, old[0]), max(hi, old[1])) if old else (int(lo), int(hi))
    return out


def summary(path: str | Path, *, exact: bool = False) -> BagSummary:
    """Format, times, size, compression and per-topic counts of one bag, from its index.

    Args:
        path: a ``.bag``, ``.bag.active``, ``.mcap`` file or a rosbag2 directory.
        exact: also read the per-message index records so that every topic's first and last
            times are exact (otherwise they are those of the chunks holding the topic).

    Raises:
        BagError: missing path, empty file, not a bag, or a header too damaged to scan.
    """
    p = Path(path)
    fmt = detect_format(p)
    if fmt in ("ros1", "ros1-active"):
        return _ros1(p, fmt, exact)
    if fmt == "mcap":
        return _mcap(p, exact)
    return _rosbag2(p, fmt, exact)


def summary_and_times(path: str | Path) -> tuple[BagSummary, dict[str, I64]]:
    """The exact summary and every topic's sorted record times, from one pass over the index
    records (what ``ertools info`` shows)."""
    p = Path(path)
    fmt = detect_format(p)
    times: Times = {}
    if fmt in ("ros1", "ros1-active"):
        s = _ros1(p, fmt, True, times)
    elif fmt == "mcap":
        s = _mcap(p, True, times)
    elif fmt == "rosbag2-mcap":
        s = _rosbag2(p, fmt, True, times)
    else:
        return _rosbag2(p, fmt, True), record_times(p)
    return s, {k: np.sort(np.concatenate(v)) for k, v in times.items()}


def record_times(path: str | Path) -> dict[str, I64]:
    """topic -> sorted record times of its messages, from index records only (for rates);
    an MCAP file whose indexes do not cover every message is read record by record."""
    p = Path(path)
    fmt = detect_format(p)
    parts: dict[str, list[I64]] = defaultdict(list)
    if fmt in ("ros1", "ros1-active"):
        layout = read_layout(p)
        bag = Ros1Bag(p, layout, strict=False)
        topic_of = {c.id: c.topic for c in layout.conns}
        try:
            for chunk in layout.chunks:
                for cid, (t, _off) in bag.chunk_entries(chunk).items():
                    parts[topic_of.get(cid, f"conn {cid}")].append(t)
        finally:
            bag.close()
    elif fmt in ("mcap", "rosbag2-mcap"):
        # the same choice as the summary: message indexes where they cover every message,
        # else the records themselves
        for file in [p] if fmt == "mcap" else _mcap_files(p):
            _mcap_file(file, True, parts)
    else:
        from ertools.io.rosbag2.sqlite_storage import query  # lazy: sqlite3 1.5 ms, .db3 only

        for db in readable_files(p):
            rows = query(
                db,
                "SELECT topics.name, timestamp FROM messages "
                "JOIN topics ON topics.id = messages.topic_id",
            )
            by: dict[str, list[int]] = defaultdict(list)
            for name, t in rows:
                by[name].append(t)
            for name, ts in by.items():
                parts[name].append(np.array(ts, dtype=np.int64))
    return {k: np.sort(np.concatenate(v)) for k, v in parts.items()}


def _mcap_files(path: Path) -> list[Path]:
    """The MCAP storage files of a rosbag2 directory, readable (decompressed when the bag is
    compressed file by file)."""
    return [f for f in readable_files(path) if f.suffix == ".mcap"]
