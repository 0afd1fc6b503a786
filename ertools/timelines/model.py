"""The data of a timeline (:class:`Timeline`: bags, sessions, pairings, problems) and the
thresholds it is built with (:class:`TimelineConfig`), with its JSON layout and CSV rows.

:mod:`ertools.timelines.build` builds it from bag summaries; :mod:`ertools.timelines.scan` reads
the summaries; the report draws it.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import field
from pathlib import Path
from typing import Any, Literal, Protocol

from ertools.frozen_dataclass import frozen_dataclass
from ertools.timeutil import NS_PER_S, ns_to_s

Kind = Literal["gt", "benchmark", "robot", "other", "unreadable"]

KIND_LABELS: dict[str, str] = {
    "gt": "GT logger",
    "benchmark": "benchmark log",
    "robot": "robot log",
    "other": "other",
    "unreadable": "unreadable",
}


class TopicLike(Protocol):
    """What the timeline needs of a topic summary (``ertools.io.model.TopicSummary``)."""

    @property
    def name(self) -> str: ...

    @property
    def msgtype(self) -> str: ...

    @property
    def count(self) -> int: ...


class SummaryLike(Protocol):
    """What the timeline needs of a bag summary (``ertools.io.model.BagSummary``)."""

    @property
    def path(self) -> str | Path: ...

    @property
    def format(self) -> str: ...

    @property
    def start_ns(self) -> int | None: ...

    @property
    def end_ns(self) -> int | None: ...

    @property
    def message_count(self) -> int: ...

    @property
    def indexed(self) -> bool: ...

    @property
    def topics(self) -> Sequence[TopicLike]: ...

    @property
    def problems(self) -> Sequence[str]: ...


@frozen_dataclass
class BagEntry:
    """One bag in the timeline (``start_ns`` is None when it could not be read)."""

    path: str
    format: str | None
    start_ns: int | None
    end_ns: int | None
    kind: Kind
    logger: str
    overlaps: tuple[str, ...] = ()
    problems: tuple[str, ...] = ()
    session: int | None = None
    benchmarks: tuple[str, ...] = ()  # namespaces of its topics / name (``fbm2h``)
    copy_of: str | None = None  # the recording this file is a copy of
    copies: tuple[str, ...] = ()  # the files that are copies of this one

    @property
    def duration_ns(self) -> int | None:
        if self.start_ns is None or self.end_ns is None:
            return None
        return self.end_ns - self.start_ns

    @property
    def readable(self) -> bool:
        return self.start_ns is not None


@frozen_dataclass
class Pairing:
    """A benchmark or robot log and the GT files that cover it.

    Attributes:
        path: the benchmark or robot log.
        kind: its kind.
        gt: the GT files of its benchmark overlapping it, by start time.
        coverage: percent of the log's span covered by the union of the GT files' spans.
        uncovered: the spans of the log no GT file covers, (start_ns, end_ns).
        basis: ``content`` when the log and every paired GT file name the same benchmark;
            ``time`` when one of them names none, so overlap in time was all there was to go on.
        other_benchmark: GT files overlapping it in time that record another benchmark.
    """

    path: str
    kind: Kind
    gt: tuple[str, ...]
    coverage: float
    uncovered: tuple[tuple[int, int], ...]
    basis: Literal["content", "time"] = "content"
    other_benchmark: tuple[str, ...] = ()


@frozen_dataclass
class Session:
    """A chain of overlapping bags (each overlaps at least one other of the chain)."""

    index: int
    start_ns: int
    end_ns: int
    paths: tuple[str, ...]
    pairings: tuple[Pairing, ...] = ()

    @property
    def duration_ns(self) -> int:
        return self.end_ns - self.start_ns


@frozen_dataclass
class Problem:
    path: str
    problem: str


@frozen_dataclass
class TimelineConfig:
    """Thresholds of the checks.

    Attributes:
        clock_tolerance_ns: largest |record time - header stamp| accepted before a bag is
            flagged as recorded across unsynchronised clocks. Default 0.5 s: a mocap logger
            records its own messages a few ms late, a robot over Wi-Fi some tens of ms.
        gap_tolerance_ns: largest pause between consecutive split files of one logger.
            Default 1 s: rosbag opens the next split file at once, so anything longer means
            the logger stopped. Bags at most this far apart also chain into one session, so that a
            logger's hourly split files (which touch but do not overlap) stay one session.
        coverage_join_ns: GT files at most this far apart cover the time between them (default
            0.1 s, the trajectory scorer's max gap): consecutive split files leave one frame
            period (8 ms at 120 Hz) between them, which is no hole in the GT.
    """

    clock_tolerance_ns: int = NS_PER_S // 2
    gap_tolerance_ns: int = NS_PER_S
    coverage_join_ns: int = NS_PER_S // 10


@frozen_dataclass
class RsbbRunFiles:
    """One run of an RSBB season folder and its files (docs/rsbb.md, "What an RSBB run
    writes"): the bag and result file paired by code, team, run and time, the side files
    its script read. A missing file is None."""

    code: str
    team: str
    run: int
    bag: str | None
    result: str | None
    config: str | None = None
    transform: str | None = None
    items: str | None = None

    def to_dict(self) -> dict[str, Any]:
        return {
            "code": self.code,
            "team": self.team,
            "run": self.run,
            "bag": self.bag,
            "result": self.result,
            "config": self.config,
            "transform": self.transform,
            "items": self.items,
        }


@frozen_dataclass
class RsbbFolder:
    """What the RSBB layout makes of the files under the paths: its runs, every file it
    recognised (kind, path) and what a referee should look at."""

    runs: tuple[RsbbRunFiles, ...]
    files: tuple[tuple[str, str], ...]
    problems: tuple[str, ...]


@frozen_dataclass
class Timeline:
    """The result of :func:`build_timeline` (bags ordered by start; unreadable ones last);
    ``rsbb``: the RSBB season layout found under the paths, if any."""

    bags: tuple[BagEntry, ...]
    sessions: tuple[Session, ...]
    problems: tuple[Problem, ...]
    config: TimelineConfig = field(default_factory=TimelineConfig)
    rsbb: RsbbFolder | None = None

    @property
    def readable_count(self) -> int:
        return sum(1 for b in self.bags if b.readable)

    @property
    def pairings(self) -> tuple[Pairing, ...]:
        return tuple(p for s in self.sessions for p in s.pairings)

    def to_dict(self) -> dict[str, Any]:
        """The JSON layout of issue 2 section 5 (times in epoch seconds, float)."""
        return {
            "bags": [
                {
                    "path": b.path,
                    "format": b.format,
                    "start": _s(b.start_ns),
                    "end": _s(b.end_ns),
                    "duration": _s(b.duration_ns),
                    "kind": b.kind,
                    "benchmarks": list(b.benchmarks),
                    "overlaps": list(b.overlaps),
                    "problems": list(b.problems),
                    "copy_of": b.copy_of,
                    "copies": list(b.copies),
                }
                for b in self.bags
            ],
            "sessions": [
                {
                    "index": s.index,
                    "start": ns_to_s(s.start_ns),
                    "end": ns_to_s(s.end_ns),
                    "duration": ns_to_s(s.duration_ns),
                    "bags": list(s.paths),
                    "pairings": [
                        {
                            "path": p.path,
                            "kind": p.kind,
                            "gt": list(p.gt),
                            "coverage": p.coverage,
                            "uncovered": [[ns_to_s(a), ns_to_s(b)] for a, b in p.uncovered],
                            "basis": p.basis,
                            "other_benchmark": list(p.other_benchmark),
                        }
                        for p in s.pairings
                    ],
                }
                for s in self.sessions
            ],
            "problems": [{"path": p.path, "problem": p.problem} for p in self.problems],
            **(
                {
                    "rsbb": {
                        "runs": [r.to_dict() for r in self.rsbb.runs],
                        "files": [{"kind": k, "path": p} for k, p in self.rsbb.files],
                        "problems": list(self.rsbb.problems),
                    }
                }
                if self.rsbb is not None
                else {}
            ),
        }

    def rows(self) -> list[dict[str, Any]]:
        """One flat row per bag, for CSV and tables."""
        return [
            {
                "start": _s(b.start_ns),
                "end": _s(b.end_ns),
                "duration": _s(b.duration_ns),
                "kind": b.kind,
                "format": b.format or "",
                "session": "" if b.session is None else b.session,
                "logger": b.logger,
                "path": b.path,
                "copy_of": b.copy_of or "",
                "overlaps": ";".join(b.overlaps),
                "problems": "; ".join(b.problems),
            }
            for b in self.bags
        ]


def _s(ns: int | None) -> float | None:
    return None if ns is None else ns_to_s(ns)
