"""What the logs hold: the timeline of the given folders, the executions
:mod:`ertools.competition.discover` finds in it, and each one as a :class:`Scoring` (the IO edge
of discovery: it reads the state payloads for team names and writes the timeline page).

Every execution is scored from its benchmark log and the GT files covering it
(``ertools score NAME BMBOX_LOG GT...``). Its robot's own log, when there is one, is compared
with the same GT files by every registered benchmark whose bags are a robot log then GT paths
(:attr:`Benchmark.bags_metavar` ``("ROBOT_BAG", ...)``): the declaration says which, not a name.
A GT-only recording is scored with the values its benchmark's ``gt_only`` proposes (FBM2H: the
timing file beside it), or is a ``gt-only`` problem saying why not. Every file under the
folders is listed too, for the ledger (:mod:`ertools.competition.ledger`).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import field
from functools import partial
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ertools.benchmarks import registry
from ertools.benchmarks.base import Described, Discovered
from ertools.benchmarks.common.teams import read_payload_team
from ertools.competition.discover import Discovery, Execution, discover
from ertools.competition.jobs import one_line
from ertools.competition.memo import (
    CLOCK,
    TEAM,
    FileMemo,
    clock_from_json,
    clock_json_valid,
    clock_to_json,
    team_json_valid,
)
from ertools.competition.pipeline import Scoring
from ertools.frozen_dataclass import frozen_dataclass
from ertools.io.clock import clock_check
from ertools.io.formats import regular_files
from ertools.progress import Reporter
from ertools.report.timeline_page import write_timeline_page
from ertools.rsbb.layout import FileKind, SeasonFile, layout_root
from ertools.rsbb.layout import classify as rsbb_classify
from ertools.rsbb.results import parse_result_time
from ertools.rsbb_states import BENCHMARKS
from ertools.timelines.build import rsbb_run
from ertools.timelines.model import RsbbFolder, RsbbRunFiles, Timeline
from ertools.timelines.scan import scan
from ertools.timeutil import NS_PER_S

if TYPE_CHECKING:
    from ertools.io.clock import ClockCheck
    from ertools.io.model import BagSummary

ROBOT_BAG = "ROBOT_BAG"
TIMELINE_PAGE = "timeline.html"


@frozen_dataclass
class Found:
    """The logs' scorings, problems (results.json's ``problems``) and timeline.

    ``executions`` are discovery's executions that are scored (a GT-only recording its
    benchmark cannot score alone is a problem instead), ``values`` their own input values by
    benchmark log (a GT-only FBM2H log's timing file...), ``files`` every file under the
    folders scanned (absolute) and ``folders`` those folders (a file given: its folder).
    """

    scorings: tuple[Scoring, ...]
    problems: tuple[dict[str, Any], ...]
    timeline: Timeline
    discovery: Discovery
    executions: tuple[Execution, ...] = ()
    values: Mapping[str, Mapping[str, Any]] = field(default_factory=dict)
    files: tuple[str, ...] = ()
    folders: tuple[str, ...] = ()


def list_files(paths: Sequence[Path]) -> tuple[tuple[str, ...], tuple[str, ...]]:
    """Every file under ``paths`` (absolute, sorted) and the folders scanned."""
    files: set[str] = set()
    folders: list[str] = []
    for path in paths:
        path = path.resolve()
        if path.is_dir():
            folders.append(str(path))
        elif path.is_file():
            folders.append(str(path.parent))
        else:
            continue
        # a folder that cannot be listed is one of the timeline scan's problems already
        found, _problems = regular_files([path])
        files |= {str(p) for p in found}
    return tuple(sorted(files)), tuple(dict.fromkeys(folders))


def robot_benchmarks() -> tuple[str, ...]:
    """The registered benchmarks that score a robot's own log against GT files."""
    out = []
    for name in registry.names():
        bench = registry.get(name)
        if not isinstance(bench, Described | Discovered):
            continue
        metavar = bench.bags_metavar if isinstance(bench, Described) else Described.bags_metavar
        if not isinstance(metavar, str) and metavar[0] == ROBOT_BAG:
            out.append(name)
    return tuple(out)


def payload_teams(timeline: Timeline, memo: FileMemo | None = None) -> dict[str, str]:
    """Benchmark log -> the team its state payloads name (where one does); remembered in
    ``memo`` by the log's stamp."""
    memo = memo or FileMemo(None)
    teams: dict[str, str] = {}
    for entry in timeline.bags:
        if entry.kind != "benchmark" or not entry.readable or entry.copy_of is not None:
            continue
        if rsbb_run(entry.path) is not None:  # its folder names the team
            continue
        for namespace in entry.benchmarks:
            ns = namespace.lower()
            team = memo.get(
                entry.path, TEAM + ns, partial(read_payload_team, [entry.path], ns), team_json_valid
            )
            if team:
                teams[entry.path] = team
                break
    return teams


def find(
    paths: Sequence[Path], *, progress: Reporter | None = None, memo: FileMemo | None = None
) -> Found:
    """Scan ``paths`` and turn every execution found into its scorings; what each log says
    (its clock check, its payloads' team) is taken from ``memo`` while the log is unchanged
    (:mod:`ertools.competition.memo`)."""
    memo = memo or FileMemo(None)

    def clock(s: BagSummary) -> ClockCheck | None:
        value = memo.get(s.path, CLOCK, lambda: clock_to_json(clock_check(s)), clock_json_valid)
        return clock_from_json(str(s.path), value)

    # absolute, so that every path of the results can be shown relative to the folder
    timeline = scan([Path(p).resolve() for p in paths], progress=progress, clock=clock)
    discovery = discover(timeline, payload_teams(timeline, memo))
    known = set(registry.names())
    robots = robot_benchmarks()
    problems = [{"kind": p.kind, "path": p.path, "message": p.message} for p in discovery.problems]
    scorings: list[Scoring] = []
    kept: list[Execution] = []
    own: dict[str, Mapping[str, Any]] = {}
    pairings = {p.path: p for p in timeline.pairings}
    results, rsbb_problems = rsbb_results(timeline.rsbb)
    problems += rsbb_problems + unsure_side_files(timeline.rsbb)
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
        gt = tuple(Path(g).resolve() for g in e.gt_files)
        bags = (Path(e.bmbox_log).resolve(), *gt)
        values: Mapping[str, Any] = {}
        result = results.get(str(Path(e.bmbox_log).resolve()))
        if result is not None and _declares(e.benchmark, "result"):
            values = own[e.bmbox_log] = {"result": Path(result)}
        if e.gt_only:
            proposed = _gt_only_values(e.benchmark, bags)
            if isinstance(proposed, str):
                problems += [
                    {"kind": "gt-only", "path": str(b), "message": proposed} for b in bags[:1]
                ] + [
                    {"kind": "gt-only", "path": str(b), "message": f"split file of {bags[0]}"}
                    for b in bags[1:]
                ]
                continue
            values = proposed
            own[e.bmbox_log] = values
        kept.append(e)
        scorings.append(
            Scoring(
                benchmark=e.benchmark,
                team=e.team,
                bags=bags,
                start_ns=e.start_ns,
                end_ns=e.end_ns,
                team_source=e.team_source,
                values=values,
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
                    of=str(Path(e.bmbox_log).resolve()),
                )
            )
    scorings += _unreadable_runs(timeline, known, results)
    files, folders = list_files(paths)
    return Found(
        tuple(scorings), tuple(problems), timeline, discovery, tuple(kept), own, files, folders
    )


def _unreadable_runs(
    timeline: Timeline, known: set[str], results: Mapping[str, str]
) -> list[Scoring]:
    """An RSBB run bag that cannot be read, as an execution its place names (benchmark, team)
    that is unscoreable, saying why: the referee sees the run rather than losing it."""
    out: list[Scoring] = []
    for entry in timeline.bags:
        place = rsbb_run(entry.path)
        if entry.readable or place is None or place[0].lower() not in known:
            continue
        path = Path(entry.path).resolve()
        # the first problem only: the others are warnings of their own (one line each)
        why = one_line(entry.problems[0] if entry.problems else "no message could be read")
        result = results.get(str(path))
        # its time: the result file's name (the BmBox's setup, zone included), within 60 s of
        # the bag's start; the bag's own name has its local time without the zone
        named = None if result is None else rsbb_classify(result)
        when = None if named is None or named.stamp is None else parse_result_time(named.stamp)
        start_ns = None if when is None else int(when.timestamp()) * NS_PER_S
        out.append(
            Scoring(
                benchmark=place[0].lower(),
                team=place[1],
                bags=(path,),
                start_ns=start_ns,
                end_ns=start_ns,
                team_source="RSBB layout",
                values={"result": Path(result)} if result is not None else {},
                blockers=(f"its run bag cannot be read ({why})",),
            )
        )
    return out


def rsbb_results(
    folder: RsbbFolder | None,
) -> tuple[dict[str, str], list[dict[str, Any]]]:
    """Each RSBB run bag's result file (by the bag's absolute path), and a problem for each
    result file without its bag and each scripted run's bag without its result file."""
    if folder is None:
        return {}, []
    results: dict[str, str] = {}
    problems: list[dict[str, Any]] = []
    for r in folder.runs:
        what = f"{r.code} run {r.run} of team {r.team}"
        if r.bag is not None and r.result is not None:
            results[str(Path(r.bag).resolve())] = str(Path(r.result).resolve())
        elif r.result is not None:
            problems.append(
                {
                    "kind": "unpaired",
                    "path": str(Path(r.result).resolve()),
                    "message": f"the result file of {what}: no run bag of it (rsbb_logs/"
                    f"{r.code}/{r.team}/run_{r.run}_<date>.bag, started within 60 s)",
                }
            )
        elif r.bag is not None and BENCHMARKS[r.code].scripted:
            problems.append(
                {
                    "kind": "unpaired",
                    "path": str(Path(r.bag).resolve()),
                    "message": f"the run bag of {what}: no result file of it (results/{r.code}/"
                    f"{r.team}/result_run_{r.run}_<date>.yaml): scored without the script's "
                    "score to compare",
                }
            )
    return results, problems


# A run's side-file inputs and the kind of file each is in the RSBB layout.
SIDE_KINDS = {
    "config": FileKind.BENCHMARK_CONFIG,
    "items": FileKind.ITEMS,
    "transform": FileKind.TRANSFORM,
    "description": FileKind.DESCRIPTION,
}


def run_root(run: RsbbRunFiles) -> Path | None:
    """The folder holding ``run``'s layout (its ``rsbb_logs/`` or ``results/``)."""
    path = run.bag if run.bag is not None else run.result
    kind = FileKind.RUN_BAG if run.bag is not None else FileKind.RESULT
    if path is None:
        return None
    return layout_root(SeasonFile(Path(path).resolve(), kind, run.code, run.team))


def run_side_file(
    folder: RsbbFolder, run: RsbbRunFiles, name: str
) -> Path | tuple[Path, ...] | None:
    """``run``'s side file for the input ``name``: its own layout's, else the only one
    elsewhere; the candidates when there are several elsewhere (nothing tells which is the
    run's); None when there is none (or the run takes none: items of another benchmark)."""
    kind = SIDE_KINDS.get(name)
    if kind is None or (name != "description" and getattr(run, name) is None):
        return None
    candidates = []
    for k, p in folder.files:
        if k != kind.value:
            continue
        f = rsbb_classify(p)
        if kind is FileKind.TRANSFORM and (f is None or f.team != run.team):
            continue
        if kind is FileKind.BENCHMARK_CONFIG and (f is None or f.code != run.code):
            continue
        candidates.append(Path(p).resolve())
    root = run_root(run)
    own = sorted(c for c in candidates if root is not None and root in c.parents)
    if own or len(candidates) == 1:
        return (own or candidates)[0]
    return tuple(sorted(candidates)) or None


def unsure_side_files(folder: RsbbFolder | None) -> list[dict[str, Any]]:
    """An ``ambiguous`` problem for each run whose layout has no side file it takes while
    several other folders have one (the run is scored only once the manifest names one)."""
    out: list[dict[str, Any]] = []
    if folder is None:
        return out
    for run in folder.runs:
        if run.bag is None:
            continue
        for name in SIDE_KINDS:
            side = run_side_file(folder, run, name)
            if not isinstance(side, tuple) or not _declares(run.code.lower(), name):
                continue
            out.append(
                {
                    "kind": "ambiguous",
                    "path": str(Path(run.bag).resolve()),
                    "message": f"{run.code} run {run.run} of team {run.team}: no {name} in its "
                    f"RSBB layout and {len(side)} elsewhere ({', '.join(map(str, side))}): "
                    f"name the run's in the manifest (executions[].inputs.{name})",
                }
            )
    return out


def _declares(benchmark: str, name: str) -> bool:
    """Whether a registered ``benchmark`` takes the input ``name``."""
    if benchmark not in registry.names():
        return False
    return any(i.name == name for i in registry.get(benchmark).inputs)


def _gt_only_values(benchmark: str, bags: Sequence[Path]) -> Mapping[str, Any] | str:
    """The values scoring a GT-only recording of ``benchmark``, or why it is no execution."""
    bench = registry.get(benchmark)
    values = bench.gt_only(bags) if isinstance(bench, Discovered) else None
    if values is None:
        return (
            f"the GT logger's {bench.title} log alone (no state topics): {bench.name} is "
            "scored from its benchmark log, which is not here"
        )
    return values


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
