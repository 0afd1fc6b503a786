"""Every benchmark execution in a timeline, with its team, GT files and robot log.

Pure: it reads the :class:`~ertools.timelines.model.Timeline` that
:func:`ertools.timelines.scan.scan` built (and, optionally, the teams the IO edge read from the
state payloads), never a file.

- An **execution** is a benchmark log (a bag with state topics, ``kind == "benchmark"``) and
  one benchmark namespace of its topics (``/fbm2h/bmbox_state`` -> ``fbm2h``); its span is the
  log's (first to last message). A copy of a benchmark log is the same execution, not another.
- Its **GT files** are the timeline's pairing of that log: the GT logger files of its
  benchmark overlapping its span, with their coverage.
- Its **robot log** is the robot log (``kind == "robot"``, not a copy) of the same benchmark
  whose span overlaps the execution's the most. Each robot log belongs to at most one
  execution: the one it overlaps the most (a team's logger runs from before the benchmark
  starts to after it ends, so the next team's run overlaps it less, if at all).
- Its **team**, by :func:`ertools.benchmarks.common.teams.resolve_team`: a team the state
  payloads name (``payload_teams``, read by
  :func:`ertools.benchmarks.common.teams.read_payload_team`), else the robot log's rockin_logger
  name (``FBM2H_<date>_<team>.bag``), else none (a ``no-team`` problem; the execution is
  scored all the same, and ranked once the manifest names it).
- A **GT-only recording** (the GT logger's split files in one folder, none of which overlaps
  a benchmark log: the 2015 test logs) is an execution with ``gt_only`` set, its first file as
  ``bmbox_log``; the IO edge asks its benchmark whether and how it is scored alone
  (:meth:`~ertools.benchmarks.base.Discovered.gt_only`). A recording naming no benchmark, a
  noise recording, and the uncovered split files of a recording that covers a benchmark log
  are ``gt-only`` problems.

Problems (:class:`Problem`, one per file and kind): files nobody could read, truncated or
unindexed files, copies, clock offsets, gaps between GT split files (from the timeline's
per-file checks), robot logs no execution explains, executions without a team or without full
GT coverage, and unreadable files whose name says they were a benchmark log (an execution
that cannot be found).
"""

from __future__ import annotations

import datetime as dt
import re
from collections.abc import Mapping
from typing import Literal

from ertools.benchmarks.common.teams import Team, TeamSource, resolve_team
from ertools.frozen_dataclass import frozen_dataclass
from ertools.timelines.build import bag_stem, rsbb_run, split_name
from ertools.timelines.model import BagEntry, Pairing, Timeline
from ertools.timeutil import NS_PER_S

# Spelled as the ``problems[].kind`` of results.json (the rescore contract).
ProblemKind = Literal[
    "unreadable",
    "truncated",
    "active",
    "duplicate",
    "clock-offset",
    "gap",
    "duplicate-name",
    "unpaired",
    "no-team",
    "no-gt",
    "partial-gt",
    "ambiguous",
    "file",
    "gt-only",
]

# The 2015 benchmark manager named its logs log_<namespace>[_mocap]_<YYYY-mm-dd-HH-MM-SS>_<n>.
_BENCHMARK_LOG_RE = re.compile(
    r"^log_(?P<ns>[ft]bm\d[hw])(?:_mocap)?_(?P<date>\d{4}-\d{2}-\d{2}-\d{2}-\d{2}-\d{2})_\d+$",
    re.IGNORECASE,
)
# Words of a GT recording's name that say the marker set lay still (a noise measurement).
_STILL_WORDS = frozenset({"noise", "static", "stationary", "still"})
# What the timeline's per-file problem lines say, by kind (ertools.timelines.build writes them).
_FILE_PROBLEMS: tuple[tuple[str, ProblemKind], ...] = (
    ("truncated", "truncated"),
    ("same recording as", "duplicate"),
    ("record times differ from header stamps", "clock-offset"),
    ("cannot read the first messages", "clock-offset"),
    ("not indexed", "active"),
    ("unindexed", "active"),
    ("gap of", "gap"),
    ("missing before this one", "gap"),
    ("duplicated file name", "duplicate-name"),
    ("no messages", "unreadable"),
)


@frozen_dataclass
class Problem:
    """One thing wrong, about one file (``path``) or one execution (its benchmark log)."""

    path: str
    kind: ProblemKind
    message: str


@frozen_dataclass
class Execution:
    """One benchmark execution and the logs that belong to it.

    Attributes:
        benchmark: the benchmark (``fbm1h``, ``fbm2h``, ``fbm3w``...): its namespace, lower case.
        namespace: the topics' namespace as logged (``fbm2h`` in ``/fbm2h/bmbox_state``).
        start_ns, end_ns: the benchmark log's first and last message (record times).
        bmbox_log: the benchmark manager's log (state topics).
        gt_files: the GT logger files of this benchmark overlapping it, by start time.
        robot_log: the team's own log, or None.
        team: the team, or None when nothing names it.
        team_source: where the team came from (``payload``, ``log name``), or None.
        problems: one line per problem of this execution or of one of its files.
        gt_only: a recording of the GT logger alone (no benchmark log): ``bmbox_log`` is its
            first file, ``gt_files`` the others; the benchmark's
            :meth:`~ertools.benchmarks.base.Discovered.gt_only` says how it is scored, if at all.
    """

    benchmark: str
    namespace: str
    start_ns: int
    end_ns: int
    bmbox_log: str
    gt_files: tuple[str, ...]
    robot_log: str | None
    team: str | None
    team_source: TeamSource | None
    problems: tuple[str, ...]
    gt_only: bool = False

    @property
    def id(self) -> str:
        """``<benchmark>-<team or unknown>-<start, UTC, %Y%m%dT%H%M%S>``, as results.json's."""
        stamp = dt.datetime.fromtimestamp(self.start_ns // NS_PER_S, tz=dt.UTC)
        return f"{self.benchmark}-{self.team or 'unknown'}-{stamp:%Y%m%dT%H%M%S}"


@frozen_dataclass
class Discovery:
    """What :func:`discover` found: executions by start time, and every problem."""

    executions: tuple[Execution, ...]
    problems: tuple[Problem, ...]


def _file_problems(entry: BagEntry) -> list[Problem]:
    out = []
    for text in entry.problems:
        kind: ProblemKind = next((k for key, k in _FILE_PROBLEMS if key in text), "file")
        if entry.kind == "unreadable" and kind == "file":
            kind = "unreadable"
        out.append(Problem(entry.path, kind, text))
    return out


def _overlap(a: BagEntry, start_ns: int, end_ns: int) -> int:
    """Nanoseconds the closed spans share; -1 when they do not meet."""
    assert a.start_ns is not None and a.end_ns is not None
    return (
        min(a.end_ns, end_ns) - max(a.start_ns, start_ns)
        if a.start_ns <= end_ns and start_ns <= a.end_ns
        else -1
    )


def _utc(ns: int) -> str:
    return dt.datetime.fromtimestamp(ns / NS_PER_S, tz=dt.UTC).strftime("%Y-%m-%d %H:%M:%S UTC")


def discover(timeline: Timeline, payload_teams: Mapping[str, str] | None = None) -> Discovery:
    """The benchmark executions of ``timeline`` and what is wrong (see the module docstring).

    Args:
        timeline: from :func:`ertools.timelines.scan.scan` (or
            :func:`ertools.timelines.build.build_timeline`).
        payload_teams: benchmark log path -> the team its state payloads name, for the logs
            where the IO edge found one (:func:`ertools.benchmarks.common.teams.read_payload_team`).
    """
    payload_teams = payload_teams or {}
    problems: list[Problem] = []
    for entry in timeline.bags:
        problems += _file_problems(entry)
        if entry.kind == "unreadable":
            lost = _lost_benchmark_log(entry)
            if lost is not None:
                problems.append(lost)
    by_path = {b.path: b for b in timeline.bags}
    pairings: dict[str, Pairing] = {p.path: p for p in timeline.pairings}
    originals = [b for b in timeline.bags if b.readable and b.copy_of is None]
    bench_logs = [b for b in originals if b.kind == "benchmark"]
    robots = [b for b in originals if b.kind == "robot"]

    # Each (log, namespace) is an execution; a log naming no benchmark is a problem.
    slots: list[tuple[BagEntry, str]] = []
    # A GT recording no benchmark log covers: the 2015 GT logger's log of a run scored
    # without state topics (the test logs), an execution when its benchmark can score it so.
    lone, lone_problems = _gt_only(originals, timeline.pairings)
    problems += lone_problems
    rest: dict[str, tuple[str, ...]] = {}
    for files in lone:
        slots += [(files[0], ns) for ns in files[0].benchmarks]
        rest[files[0].path] = tuple(f.path for f in files[1:])
    for log in bench_logs:
        if not log.benchmarks:
            problems.append(
                Problem(log.path, "ambiguous", "a benchmark log whose topics name no benchmark")
            )
        if len(log.benchmarks) > 1:
            problems.append(
                Problem(
                    log.path,
                    "ambiguous",
                    f"one benchmark log holds {len(log.benchmarks)} benchmarks "
                    f"({', '.join(log.benchmarks)}): one execution each",
                )
            )
        slots += [(log, ns) for ns in log.benchmarks]

    # Robot log -> the execution of its benchmark it overlaps the most.
    owner: dict[str, int] = {}
    for robot in robots:
        best = max(
            (
                (_overlap(robot, log.start_ns or 0, log.end_ns or 0), i)
                for i, (log, ns) in enumerate(slots)
                if ns.lower() in robot.benchmarks
            ),
            default=(-1, -1),
        )
        if best[0] >= 0:
            owner[robot.path] = best[1]
        else:
            assert robot.start_ns is not None and robot.end_ns is not None
            problems.append(
                Problem(
                    robot.path,
                    "unpaired",
                    f"robot log ({', '.join(robot.benchmarks) or 'no benchmark'}, "
                    f"{_utc(robot.start_ns)} to {_utc(robot.end_ns)}) overlaps no benchmark "
                    "execution of its benchmark",
                )
            )

    executions: list[Execution] = []
    for i, (log, ns) in enumerate(slots):
        assert log.start_ns is not None and log.end_ns is not None
        mine = sorted(
            (r for r in robots if owner.get(r.path) == i),
            key=lambda r: (-_overlap(r, log.start_ns or 0, log.end_ns or 0), r.path),
        )
        paired = mine[0] if mine else None
        notes: list[str] = []
        if len(mine) > 1:
            others = ", ".join(r.path for r in mine[1:])
            text = f"several robot logs overlap it; took {mine[0].path}, not {others}"
            notes.append(text)
            problems.append(Problem(log.path, "ambiguous", text))
        rsbb = rsbb_run(log.path)
        team = (
            Team(rsbb[1], "RSBB layout")
            if rsbb is not None
            else resolve_team(
                inputs=[paired.path] if paired is not None else [],
                payload_team=payload_teams.get(log.path),
            )
        )
        if team is None:  # scored all the same; its row says the team is unknown
            text = "no team: no state payload or robot log names one (give it in the manifest)"
            problems.append(Problem(log.path, "no-team", text))
        pairing = pairings.get(log.path)
        gt = pairing.gt if pairing is not None else ()
        if log.path in rest:  # a GT-only recording: its own files are its GT
            gt, pairing = rest[log.path], None
        elif rsbb is not None:  # an RSBB run bag records its own mocap (/tf)
            gt, pairing = (), None
        elif not gt:
            text = "no GT file of its benchmark overlaps it"
            notes.append(text)
            problems.append(Problem(log.path, "no-gt", text))
        elif pairing is not None and pairing.coverage < 100.0:
            holes = ", ".join(f"{_utc(a)} to {_utc(b)}" for a, b in pairing.uncovered)
            text = f"GT covers {pairing.coverage:.1f} % of it (not: {holes})"
            notes.append(text)
            problems.append(Problem(log.path, "partial-gt", text))
        for path in (log.path, *gt, *([paired.path] if paired is not None else [])):
            notes += [f"{path}: {p}" for p in by_path[path].problems]
        executions.append(
            Execution(
                benchmark=ns.lower(),
                namespace=ns,
                start_ns=log.start_ns,
                end_ns=max([log.end_ns, *(by_path[g].end_ns or 0 for g in rest.get(log.path, ()))]),
                bmbox_log=log.path,
                gt_files=tuple(gt),
                robot_log=paired.path if paired is not None else None,
                team=team.name if team is not None else None,
                team_source=team.source if team is not None else None,
                problems=tuple(dict.fromkeys(notes)),
                gt_only=log.path in rest,
            )
        )
    executions.sort(key=lambda e: (e.start_ns, e.benchmark, e.bmbox_log))
    return Discovery(tuple(executions), tuple(dict.fromkeys(problems)))


def _gt_only(
    originals: list[BagEntry], pairings: tuple[Pairing, ...]
) -> tuple[list[list[BagEntry]], list[Problem]]:
    """The GT recordings no benchmark log covers, each as its files in split order (one
    recording: the split files of one logger in one folder), and the problems of those that
    cannot be an execution (no benchmark named; a noise recording)."""
    covered = {g for p in pairings if p.kind == "benchmark" for g in p.gt}
    groups: dict[tuple[str, str], list[tuple[int, BagEntry]]] = {}
    for entry in originals:
        if entry.kind != "gt":
            continue
        split = split_name(entry.path)
        folder = entry.path.rsplit("/", 1)[0] if "/" in entry.path else ""
        key = (folder, split[0]) if split is not None else (entry.path, "")
        groups.setdefault(key, []).append((split[1] if split is not None else 0, entry))
    recordings: list[list[BagEntry]] = []
    problems: list[Problem] = []
    for members in groups.values():
        files = [e for _, e in sorted(members, key=lambda m: (m[0], m[1].path))]
        used = [f for f in files if f.path in covered]
        if used:  # a recording that covers benchmark logs: the rest of it covers none
            problems += [
                Problem(
                    f.path,
                    "gt-only",
                    f"split file of the GT recording {bag_stem(used[0].path)} that overlaps "
                    "no benchmark log: not used",
                )
                for f in files
                if f.path not in covered
            ]
            continue
        first = files[0]
        if not first.benchmarks:
            problems.append(
                Problem(
                    first.path,
                    "gt-only",
                    "GT logger file naming no benchmark (no /fbm.../ topics) that no benchmark "
                    "log overlaps: not an execution",
                )
            )
        elif _STILL_WORDS & set(bag_stem(first.path).lower().split("_")):
            problems.append(
                Problem(
                    first.path,
                    "gt-only",
                    "a noise recording of a marker set lying still (its name says so): "
                    "`ertools noise` measures it; not a benchmark execution",
                )
            )
        else:
            recordings.append(files)
            continue
        problems += [
            Problem(f.path, "gt-only", f"split file of {first.path}: not an execution")
            for f in files[1:]
        ]
    return recordings, problems


def _lost_benchmark_log(entry: BagEntry) -> Problem | None:
    """An unreadable file named like a benchmark log: an execution nobody can find."""
    match = _BENCHMARK_LOG_RE.match(bag_stem(entry.path))
    if match is None:
        return None
    when = dt.datetime.strptime(match.group("date"), "%Y-%m-%d-%H-%M-%S")
    return Problem(
        entry.path,
        "unreadable",
        f"named like the benchmark log of a {match.group('ns').lower()} execution started "
        f"{when:%Y-%m-%d %H:%M:%S} (its recorder's clock), but unreadable: that execution is "
        "missing",
    )


__all__ = ["Discovery", "Execution", "Problem", "ProblemKind", "discover"]
