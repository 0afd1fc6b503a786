"""``summary(path)``: what a bag holds, from the file's own index, without message data.

- ROS1: the bag header record, then the connection and chunk-info records at the index
  position (plus the first chunk's record header for its compression). A bag with no index
  (``.bag.active``) or a damaged or truncated one is scanned record by record instead and
  flagged (``indexed=False``, ``problems``).
- MCAP: the summary section (statistics, channels, schemas, chunk indexes). A file without one
  (unfinished, truncated) is scanned and flagged.
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
import numpy.typing as npt

from ertools.errors import BagError
from ertools.io.formats import detect_format
from ertools.io.model import BagSummary, TopicSummary, short_msgtype

log = logging.getLogger("ertools.io.summary")

I64 = npt.NDArray[np.int64]


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
) -> BagSummary:
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
    from ertools.io.ros1_index import Ros1Bag, read_layout

    layout = read_layout(path)
    compressions: set[str] = set()
    spans: dict[int, list[int]] = {}
    counts: dict[int, int] = defaultdict(int)
    topic_of = {c.id: c.topic for c in layout.conns}
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
                    for cid, (t, _off) in bag.chunk_entries(chunk).items():
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
        list(layout.problems),
    )


def _mcap_scan(path: Path, why: str) -> BagSummary:
    """Walk an MCAP file without a summary, record by record, as far as it goes."""
    from mcap.records import Channel, Chunk, Message, Schema
    from mcap.stream_reader import CRCValidationError, StreamReader

    from ertools.io.files import mcap_errors

    log.info("%s: %s; scanning the whole file", path, why)
    problems = [why]
    schemas: dict[int, str] = {}
    channels: dict[int, tuple[str, int]] = {}
    stats: dict[int, list[int]] = {}
    compressions: set[str] = set()
    with path.open("rb") as f:
        try:
            # CRCs checked: lz4 and zstd chunks inflate damaged bytes without an error
            scan = StreamReader(f, skip_magic=False, emit_chunks=False, validate_crcs=True)
            for record in scan.records:
                if isinstance(record, Schema):
                    schemas[record.id] = record.name
                elif isinstance(record, Channel):
                    channels[record.id] = (record.topic, record.schema_id)
                elif isinstance(record, Chunk):
                    compressions.add(record.compression or "none")
                elif isinstance(record, Message):
                    s = stats.setdefault(record.channel_id, [0, record.log_time, record.log_time])
                    s[0] += 1
                    s[1] = min(s[1], record.log_time)
                    s[2] = max(s[2], record.log_time)
        except CRCValidationError as err:
            # a damaged chunk or data section, not the end of an unfinished recording
            raise BagError(
                f"MCAP data fails its CRC check before byte {f.tell()} (damaged file)", path=path
            ) from err
        except mcap_errors() as err:
            problems.append(
                f"truncated or damaged at byte {f.tell()} ({type(err).__name__}: {err})"
            )
    topics: dict[str, tuple[str, int, int | None, int | None, int]] = {}
    for cid, (topic, sid) in channels.items():
        st = stats.get(cid)
        _merge_topic(
            topics,
            topic,
            short_msgtype(schemas.get(sid, "")),
            st[0] if st else 0,
            st[1] if st else None,
            st[2] if st else None,
        )
    return _build(
        path, "mcap", "", "/".join(sorted(compressions)) or "none", False, topics, problems
    )


def _mcap_topics(
    path: Path, summary: Any, exact: bool, times: Times | None = None
) -> tuple[dict[str, tuple[str, int, int | None, int | None, int]], set[str]]:
    spans: dict[int, list[int]] = {}
    compressions = set()
    stats = summary.statistics
    if (
        stats is not None
        and stats.channel_message_counts
        and sum(stats.channel_message_counts.values()) != stats.message_count
    ):
        # damaged statistics (a per-channel count that is no longer part of the total):
        # count from the message indexes instead, as for a file without statistics
        log.warning("%s: MCAP statistics do not add up; counting from the indexes", path)
        stats = None
    counts: dict[int, int] = dict(stats.channel_message_counts) if stats else {}
    need_counts = stats is None
    with path.open("rb") as f:
        for chunk in summary.chunk_indexes:
            compressions.add(chunk.compression or "none")
            for cid, offset in chunk.message_index_offsets.items():
                if cid not in summary.channels:
                    raise BagError(
                        f"chunk index at byte {chunk.chunk_start_offset} names channel {cid}, "
                        "which the summary section does not declare",
                        path=path,
                    )
                if exact or need_counts:
                    from ertools.io.mcap_index import McapIndex

                    t, _ = McapIndex._message_index(f, path, offset, cid)
                    if times is not None:
                        times.setdefault(summary.channels[cid].topic, []).append(t)
                    if need_counts:
                        counts[cid] = counts.get(cid, 0) + len(t)
                    if not len(t):
                        continue
                    lo, hi = int(t.min()), int(t.max())
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
    topics: dict[str, tuple[str, int, int | None, int | None, int]] = {}
    for cid, ch in sorted(summary.channels.items()):
        schema = summary.schemas.get(ch.schema_id)
        span = spans.get(cid)
        _merge_topic(
            topics,
            ch.topic,
            short_msgtype(schema.name if schema else ""),
            int(counts.get(cid, 0)),
            *(span or (None, None)),
        )
    return topics, compressions


def _mcap(path: Path, exact: bool, times: Times | None = None) -> BagSummary:
    from ertools.io.mcap_index import read_summary

    with path.open("rb") as f:
        try:
            summary = read_summary(f, path)
        except BagError as err:
            return _mcap_scan(path, f"no readable summary section ({err.message})")
        from mcap.reader import make_reader

        from ertools.io.files import mcap_errors

        f.seek(0)
        try:
            header = make_reader(f).get_header()
        except mcap_errors() as err:
            # Only the version text comes from the header record; the summary is still right.
            header = None
            problems = [f"unreadable header record ({type(err).__name__}: {err})"]
    if summary is None:
        return _mcap_scan(path, "no summary section (recording not finished?)")
    if not summary.chunk_indexes and summary.statistics and summary.statistics.message_count:
        return _mcap_scan(path, "no chunk indexes")
    topics, compressions = _mcap_topics(path, summary, exact, times)
    if header is None:
        version = "mcap0"
    else:
        version = f"mcap0 profile {header.profile or 'none'} ({header.library})"
        problems = []
    return _build(
        path, "mcap", version, "/".join(sorted(compressions)) or "none", True, topics, problems
    )


def _rosbag2(path: Path, fmt: str, exact: bool, times: Times | None = None) -> BagSummary:
    from ertools.io.rosbag2 import read_metadata, storage_files

    info = read_metadata(path)
    problems = []
    files = storage_files(path, info)
    missing = [f.name for f in files if not f.exists()]
    if missing:
        problems.append(f"storage file(s) listed in metadata.yaml missing: {', '.join(missing)}")
    topics: dict[str, tuple[str, int, int | None, int | None, int]] = {}
    inner: set[str] = set()
    if fmt == "rosbag2-mcap" and not missing:
        from ertools.io.mcap_index import read_summary

        for file in files:
            with file.open("rb") as f:
                summary = read_summary(f, file)
            if summary is None:
                problems.append(f"{file.name}: no MCAP summary section")
                continue
            part, chunk_compressions = _mcap_topics(file, summary, exact, times)
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
    return _build(path, fmt, str(info.get("version", "")), compression, True, topics, problems)


def _sqlite_spans(files: list[Path]) -> dict[str, tuple[int, int]]:
    from ertools.io.rosbag2 import query

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
    """topic -> sorted record times of its messages, from index records only (for rates)."""
    p = Path(path)
    fmt = detect_format(p)
    parts: dict[str, list[I64]] = defaultdict(list)
    if fmt in ("ros1", "ros1-active"):
        from ertools.io.ros1_index import Ros1Bag, read_layout

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
        from ertools.io.mcap_index import McapIndex, read_summary

        files = [p] if fmt == "mcap" else sorted(p.glob("*.mcap"))
        for file in files:
            with file.open("rb") as f:
                summ = read_summary(f, file)
                if summ is None:
                    continue
                for chunk in summ.chunk_indexes:
                    for cid, offset in chunk.message_index_offsets.items():
                        t, _ = McapIndex._message_index(f, file, offset, cid)
                        if cid not in summ.channels:
                            raise BagError(
                                f"chunk index names channel {cid}, which the summary section "
                                "does not declare",
                                path=file,
                            )
                        parts[summ.channels[cid].topic].append(t)
    else:
        from ertools.io.rosbag2 import query, read_metadata, storage_files

        for db in storage_files(p, read_metadata(p)):
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
