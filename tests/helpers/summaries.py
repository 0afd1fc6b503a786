"""Hand-made bag summaries for the pure timeline (what ``ertools.io.model.BagSummary`` offers)."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Topic:
    name: str
    msgtype: str
    count: int = 10


@dataclass(frozen=True)
class Summary:
    path: str
    start_ns: int
    end_ns: int
    topics: tuple[Topic, ...]
    format: str = "ros1"
    indexed: bool = True
    problems: tuple[str, ...] = ()
    message_count: int = 10


# The keys of each bag object in `ertools timeline --format json` (docs/timeline.md): scripts
# depend on them, so the layout is written down here, not derived from the code.
BAG_KEYS = [
    "path",
    "format",
    "start",
    "end",
    "duration",
    "kind",
    "benchmarks",
    "overlaps",
    "problems",
    "copy_of",
    "copies",
]
