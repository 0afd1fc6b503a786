"""What the logs hold: the timeline of the given folders, the executions
:mod:`ertools.rescore.discover` finds in it, and each one as a :class:`Scoring` (the IO edge
of discovery: it reads the state payloads for team names and writes the timeline page).

Every execution is scored from its benchmark log and the GT files covering it
(``ertools score NAME BMBOX_LOG GT...``). Its robot's own log, when there is one, is compared
with the same GT files by every registered benchmark whose bags are a robot log then GT paths
(:attr:`Benchmark.bags_metavar` ``("ROBOT_BAG", ...)``): the declaration says which, not a name.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ertools.benchmarks import registry
from ertools.benchmarks.common.teams import read_payload_team
from ertools.progress import Reporter
from ertools.report.timeline_page import write_timeline_page
from ertools.rescore.discover import Discovery, discover
from ertools.rescore.pipeline import Scoring
from ertools.timeline.model import Timeline
from ertools.timeline.scan import scan

ROBOT_BAG = "ROBOT_BAG"
TIMELINE_PAGE = "timeline.html"


@dataclass(frozen=True)
class Found:
    """The logs' scorings, problems (results.json's ``problems``) and timeline."""

    scorings: tuple[Scoring, ...]
    problems: tuple[dict[str, Any], ...]
    timeline: Timeline
    discovery: Discovery


def robot_benchmarks() -> tuple[str, ...]:
    """The registered benchmarks that score a robot's own log against GT files."""
    out = []
    for name in registry.names():
        metavar = registry.get(name).bags_metavar
        if not isinstance(metavar, str) and metavar[0] == ROBOT_BAG:
            out.append(name)
    return tuple(out)


def payload_teams(timeline: Timeline) -> dict[str, str]:
    """Benchmark log -> the team its state payloads name (where one does)."""
    teams: dict[str, str] = {}
    for entry in timeline.bags:
        if entry.kind != "benchmark" or not entry.readable or entry.copy_of is not None:
            continue
        for namespace in entry.benchmarks:
            team = read_payload_team([entry.path], namespace.lower())
            if team:
                teams[entry.path] = team
                break
    return teams


def find(paths: Sequence[Path], *, progress: Reporter | None = None) -> Found:
    """Scan ``paths`` and turn every execution found into its scorings."""
    timeline = scan(paths, progress=progress)
    discovery = discover(timeline, payload_teams(timeline))
    known = set(registry.names())
    robots = robot_benchmarks()
    problems = [{"kind": p.kind, "path": p.path, "message": p.message} for p in discovery.problems]
    scorings: list[Scoring] = []
    pairings = {p.path: p for p in timeline.pairings}
    for e in discovery.executions:
        if e.benchmark not in known:
            problems.append(
                {
                    "kind": "no-scorer",
                    "path": e.bmbox_log,
                    "message": f"a {e.benchmark} execution: no registered benchmark scores it",
                }
            )
            continue
        blockers: tuple[str, ...] = ()
        if e.team is None:
            blockers = (
                f"no team: nothing in the logs names it; list it in the manifest "
                f"(executions: benchmark {e.benchmark}, bags [{e.bmbox_log}, ...], team)",
            )
        gt = tuple(Path(g).resolve() for g in e.gt_files)
        scorings.append(
            Scoring(
                benchmark=e.benchmark,
                team=e.team,
                bags=(Path(e.bmbox_log).resolve(), *gt),
                start_ns=e.start_ns,
                end_ns=e.end_ns,
                team_source=e.team_source,
                blockers=blockers,
                notes=e.problems,
            )
        )
        if e.robot_log is None:
            continue
        # the GT files covering the robot log itself (its logger ran before and after)
        pairing = pairings.get(e.robot_log)
        robot_gt = tuple(Path(g).resolve() for g in pairing.gt) if pairing is not None else gt
        if not robot_gt:
            continue
        for name in robots:
            scorings.append(
                Scoring(
                    benchmark=name,
                    team=e.team,
                    bags=(Path(e.robot_log).resolve(), *robot_gt),
                    start_ns=e.start_ns,
                    end_ns=e.end_ns,
                    team_source=e.team_source,
                    blockers=blockers,
                    of=str(Path(e.bmbox_log).resolve()),
                )
            )
    return Found(tuple(scorings), tuple(problems), timeline, discovery)


def write_timeline(found: Found, out: Path, title: str) -> dict[str, Any]:
    """``DIR/timeline.html`` (the day's timeline figure) and results.json's ``timeline``."""

    write_timeline_page(found.timeline, out / TIMELINE_PAGE, title=title or None)
    return {"figure": TIMELINE_PAGE, "sessions": len(found.timeline.sessions)}


def merge(found: Sequence[Scoring], listed: Sequence[Scoring]) -> list[Scoring]:
    """The logs' scorings and the manifest's: an execution the manifest lists (its first bag
    is a benchmark log the logs also gave) is the manifest's, with the robot-log comparisons
    that belong to it."""
    listed_logs = {s.bags[0].resolve() for s in listed if s.bags}
    kept = [s for s in found if s.of is not None or s.bags[0].resolve() not in listed_logs]
    return [*kept, *listed]
