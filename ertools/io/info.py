"""``ertools info``'s library function: a bag's summary with per-topic rates, and checks.

Rates are medians of the intervals between consecutive record times of each topic, read from
the index records (ROS1 index data, MCAP message indexes, rosbag2 time stamps), never from the
message data. A rate is stated only for a topic with at least :data:`MIN_RATE_MESSAGES`
messages over at least :data:`MIN_RATE_SPAN_NS` (see :func:`median_rate`); other topics are
described by their count and time span. ``check=True`` additionally reads every chunk,
decompresses it and checks that every indexed message record is where the index says (the
only way to find a corrupted chunk).
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from ertools.errors import BagError
from ertools.frozen_dataclass import frozen_dataclass
from ertools.io.formats import detect_format
from ertools.io.mcap.index import verify_mcap
from ertools.io.model import BagSummary
from ertools.io.ros1.check import check_ros1
from ertools.io.ros1.index import Ros1Bag
from ertools.io.rosbag2.metadata import readable_files
from ertools.io.rosbag2.sqlite_storage import query
from ertools.io.summary import CHUNK_SELF_CHECK, INDEX_SELF_CHECK, summary_and_times
from ertools.timeutil import iso_utc, ns_to_s

if TYPE_CHECKING:
    from ertools.progress import Reporter

# A median rate is stated only with at least 10 messages (9 intervals: the median is then not
# decided by one or two intervals) over at least 1 s (a topic seen for less than a second, or
# a burst such as four /rosout lines written 0.2 s apart, has no publishing rate to state: its
# intervals say how fast a node wrote a burst). A 1 Hz topic needs 10 s to get a rate; below
# that "n messages in s s" says everything the index knows.
MIN_RATE_MESSAGES = 10
MIN_RATE_SPAN_NS = 1_000_000_000


@frozen_dataclass
class BagInfo:
    """A summary plus the median message rate of every topic (None: too few messages or too
    short a span to state one, see :func:`median_rate`)."""

    summary: BagSummary
    median_rate_hz: dict[str, float | None]
    checked: bool = False
    # What --check found (index against records, damaged chunks), one line each.
    check_problems: tuple[str, ...] = ()

    @property
    def fatal_problem(self) -> str | None:
        """What makes the bag unusable (truncated, damaged, an index that contradicts
        itself), one line; None for a sound bag or a mere ``.active`` still recording."""
        bad = [p for p in self.summary.problems if not p.startswith("not indexed")]
        return "; ".join(bad) if bad else None

    def to_dict(self) -> dict[str, Any]:
        s = self.summary
        empty = s.message_count == 0
        return {
            "path": s.path,
            "format": s.format,
            "version": s.version,
            "start": None if empty else ns_to_s(s.start_ns),
            "start_iso": None if empty else iso_utc(s.start_ns),
            "end": None if empty else ns_to_s(s.end_ns),
            "end_iso": None if empty else iso_utc(s.end_ns),
            "duration": ns_to_s(s.duration_ns),
            "size_bytes": s.size_bytes,
            "compression": s.compression,
            "messages": s.message_count,
            "indexed": s.indexed,
            "index": s.index,
            "checked": self.checked,
            "problems": [*s.problems, *self.check_problems],
            "topics": [
                {
                    "name": t.name,
                    "type": t.msgtype,
                    "count": t.count,
                    "connections": t.connections,
                    "first": None if t.first_ns is None else ns_to_s(t.first_ns),
                    "last": None if t.last_ns is None else ns_to_s(t.last_ns),
                    "span_s": span_s(t.first_ns, t.last_ns),
                    "median_rate_hz": self.median_rate_hz.get(t.name),
                }
                for t in s.topics
            ],
        }


def span_s(first_ns: int | None, last_ns: int | None) -> float | None:
    """Seconds from a topic's first to its last message (difference taken in int64 ns)."""
    if first_ns is None or last_ns is None:
        return None
    return ns_to_s(last_ns - first_ns)


def median_rate(t_ns: np.ndarray[Any, np.dtype[np.int64]]) -> float | None:
    """1 / median interval of sorted record times, in Hz.

    None with fewer than :data:`MIN_RATE_MESSAGES` messages, a span (last - first) under
    :data:`MIN_RATE_SPAN_NS`, or a zero median interval: no rate can honestly be stated.
    """
    if len(t_ns) < MIN_RATE_MESSAGES or int(t_ns[-1]) - int(t_ns[0]) < MIN_RATE_SPAN_NS:
        return None
    dt = float(np.median(np.diff(t_ns)))
    return 1e9 / dt if dt > 0 else None


def describe(path: str | Path, *, check: bool = False, progress: Reporter | None = None) -> BagInfo:
    """Summary (exact per-topic times), median rates, and with ``check`` a full chunk check
    (whose bytes are reported to ``progress``).

    Raises:
        BagError: unreadable bag, or (with ``check``) a damaged chunk.
    """

    s, times = summary_and_times(path)
    rates = {name: median_rate(t) for name, t in times.items()}
    found = verify(Path(path), progress) if check else []
    if check:
        # the record-level check says each index disagreement exactly: not twice
        kept = [p for p in s.problems if not p.endswith((INDEX_SELF_CHECK, CHUNK_SELF_CHECK))]
        s = replace(s, problems=type(s.problems)(kept))
    return BagInfo(s, rates, check, tuple(found))


def verify(path: Path, progress: Reporter | None = None) -> list[str]:
    """Read every chunk and check every indexed message record, reporting the bytes read to
    ``progress`` chunk by chunk (ROS1 and indexed MCAP).

    Returns:
        For ROS1 bags, every disagreement between the index and the records, one line each
        (:mod:`ertools.io.ros1.check`); other formats raise at the first damage.

    Raises:
        BagError: naming the file and the byte offset of the first damaged chunk.
    """

    fmt = detect_format(path)
    if fmt == "ros1":
        return check_ros1(path, progress)
    if fmt == "ros1-active":
        bag = Ros1Bag(path)
        try:
            bag.verify(progress)
        finally:
            bag.close()
    elif fmt in ("mcap", "rosbag2-mcap"):
        for file in [path] if fmt == "mcap" else readable_files(path):
            verify_mcap(file, progress)
    else:
        for db in readable_files(path):
            result = query(db, "PRAGMA quick_check")[0][0]
            if result != "ok":
                raise BagError(f"sqlite3 storage fails its integrity check ({result})", path=db)
    return []
