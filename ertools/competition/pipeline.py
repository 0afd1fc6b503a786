"""The rescore pipeline: executions -> jobs -> outcomes (cached or scored) -> results document.

:func:`rescore` is the one library function behind ``ertools rescore``: it plans one job per
execution (values from the manifest, through the registry only), takes what the cache holds,
scores the rest (:mod:`ertools.competition.parallel`), and returns the ``results.json`` document
(schema in docs/rescore.md) that :func:`write_results` writes with ``results.csv``.
"""

from __future__ import annotations

import csv
import io
import json
import logging
import re
from collections.abc import Callable, Mapping, Sequence
from dataclasses import field, replace
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

from ertools._version import __version__
from ertools.atomic import write_text
from ertools.benchmarks import registry
from ertools.benchmarks.base import Benchmark
from ertools.competition.boards import leaderboards
from ertools.competition.cache import (
    Cache,
    FileHashes,
    Fingerprints,
    changed_files,
    fingerprints,
    job_key,
    records,
)
from ertools.competition.jobs import Job, Outcome
from ertools.competition.manifest import Manifest
from ertools.competition.parallel import DaskClient, run_jobs
from ertools.competition.site import write_site
from ertools.competition.site_text import TEAM_UNKNOWN
from ertools.csvsafe import spreadsheet_safe
from ertools.errors import ErtoolsError
from ertools.frozen_dataclass import frozen_dataclass
from ertools.io.summary import summary
from ertools.progress import Reporter
from ertools.timeutil import NS_PER_S, iso_utc

log = logging.getLogger(__name__)

SCHEMA_VERSION = 1
CSV_COLUMNS = (
    "id",
    "benchmark",
    "team",
    "start",
    "end",
    "status",
    "reason",
    "rank_value",
    # the team's place on its benchmark's leaderboard, when this is its ranked execution
    # (docs/uncertainty.md, "Rank stability"): empty otherwise
    "rank",
    "rank_group",
    "interval_low",
    "interval_high",
    "p_swap_next",
    "tied_with",
    "report",
)
_UNSAFE = re.compile(r"[^A-Za-z0-9_.-]+")


@frozen_dataclass
class Scoring:
    """One score to compute, wherever it was found (listed in the manifest, discovered in the
    logs): a benchmark execution, or a robot's own log compared with the GT (``of``: the id of
    the execution it belongs to).

    ``bags`` are what the benchmark reads; ``blockers`` (one line each) make it unscoreable
    before any scoring (no team to take the inputs of); ``notes`` are discovery's remarks
    about it (partial GT coverage...), kept with its warnings.
    """

    benchmark: str
    team: str | None
    bags: tuple[Path, ...]
    start_ns: int | None = None
    end_ns: int | None = None
    team_source: str | None = None
    values: Mapping[str, Any] = field(default_factory=dict)
    blockers: tuple[str, ...] = ()
    notes: tuple[str, ...] = ()
    of: str | None = None


@frozen_dataclass
class Planned:
    """An execution, its job and its row's fixed part."""

    execution: Scoring
    job: Job
    title: str
    missing: tuple[str, ...]
    of: str | None = None  # a robot-log comparison: its execution's id


def listed_executions(manifest: Manifest) -> list[Scoring]:
    """The executions the manifest lists by hand."""
    return [
        Scoring(
            benchmark=e.benchmark,
            team=e.team,
            bags=e.bags,
            start_ns=e.start_ns,
            end_ns=e.end_ns,
            team_source="manifest" if e.team is not None else None,
            values=e.values,
        )
        for e in manifest.executions
    ]


def _bags_span(bags: Sequence[Path]) -> tuple[int | None, int | None]:
    """The first and last message time of the bags (None when unreadable: the scorer says why)."""

    starts: list[int] = []
    ends: list[int] = []
    for bag in bags:
        try:
            s = summary(bag)
        except (ErtoolsError, OSError, ValueError):
            continue
        # a bag with no message (an unreadable RSBB run bag) has no time, not 1970's
        if s.message_count and s.start_ns is not None and s.end_ns is not None:
            starts.append(int(s.start_ns))
            ends.append(int(s.end_ns))
    return (min(starts) if starts else None, max(ends) if ends else None)


def execution_id(benchmark: str, team: str | None, start_ns: int | None, n: int) -> str:
    """``fbm3w-robotto-20151120T123105``: benchmark, team, start (UTC); without a start, the
    execution's place in the list."""
    when = (
        datetime.fromtimestamp(start_ns / NS_PER_S, tz=UTC).strftime("%Y%m%dT%H%M%S")
        if start_ns is not None
        else f"{n + 1}"
    )
    return f"{benchmark}-{_UNSAFE.sub('_', team or 'unknown')}-{when}"


def score_argv(
    benchmark: Benchmark[Any, Any, Any, Any],
    bags: Sequence[Path],
    values: Mapping[str, Any],
    team: str | None,
) -> list[str]:
    """The ``ertools score`` command line that scores the same execution (for the report)."""
    argv = ["ertools", "score", benchmark.name, *(str(b) for b in bags)]
    for declared in benchmark.inputs:
        value = values.get(declared.name)
        if value is None or value is False:
            continue
        if declared.kind == "flag":
            argv.append(declared.option)
            continue
        items = value if isinstance(value, tuple | list) else (value,)
        if (declared.kind == "paths" and not declared.repeat) or declared.with_file:
            argv += [declared.option, *(str(v) for v in items)]
        else:
            for item in items:
                argv += [declared.option, str(item)]
    if team and all(declared.option != "--team" for declared in benchmark.inputs):
        argv += ["--team", team]  # the score commands' own --team (else a declared input)
    return argv


def plan(
    executions: Sequence[Scoring], manifest: Manifest, out: Path, *, reports: bool = True
) -> list[Planned]:
    """One job per execution, in time order, with unique ids and the manifest's values."""
    ordered = sorted(
        enumerate(executions),
        key=lambda ie: (ie[1].start_ns is None, ie[1].start_ns or 0, ie[0]),
    )
    planned: list[Planned] = []
    seen: dict[str, int] = {}
    ids_by_log: dict[str, str] = {}  # a benchmark log -> its execution's id (for ``of``)
    for n, (_, execution) in enumerate(ordered):
        benchmark = registry.get(execution.benchmark)
        start_ns, end_ns = execution.start_ns, execution.end_ns
        if start_ns is None or end_ns is None:
            found_start, found_end = _bags_span(execution.bags[:1])  # its benchmark log
            start_ns = start_ns if start_ns is not None else found_start
            end_ns = end_ns if end_ns is not None else found_end
            execution = Scoring(**{**execution.__dict__, "start_ns": start_ns, "end_ns": end_ns})
        ident = execution_id(execution.benchmark, execution.team, start_ns, n)
        seen[ident] = seen.get(ident, 0) + 1
        if seen[ident] > 1:
            ident = f"{ident}-{seen[ident]}"
        if execution.of is None and execution.bags:
            ids_by_log.setdefault(str(execution.bags[0].resolve()), ident)
        values, missing = manifest.values_for(execution.benchmark, execution.team, execution.values)
        values = {k: v for k, v in values.items() if v is not None}
        job = Job(
            id=ident,
            benchmark=benchmark.name,
            target=registry.target(benchmark.name),
            team=execution.team,
            bags=tuple(str(b) for b in execution.bags),
            values=values,
            report_dir=str(out / "executions" / ident) if reports else None,
            argv=tuple(score_argv(benchmark, execution.bags, values, execution.team)),
        )
        planned.append(Planned(execution, job, benchmark.title, (*execution.blockers, *missing)))
    return [
        replace(p, of=ids_by_log.get(p.execution.of)) if p.execution.of is not None else p
        for p in planned
    ]


def rescore(
    executions: Sequence[Scoring],
    manifest: Manifest,
    out: Path,
    *,
    workers: int = 1,
    scheduler: str | None = None,
    use_cache: bool = True,
    reports: bool = True,
    command: Sequence[str] = (),
    problems: Sequence[Mapping[str, Any]] = (),
    timeline: Mapping[str, Any] | None = None,
    progress: Reporter | None = None,
    on_outcome: Callable[[Outcome], None] | None = None,
    dask: DaskClient | None = None,
) -> dict[str, Any]:
    """Score every execution (cache first) and return the ``results.json`` document.

    Args:
        executions: what to score (the manifest's list, the logs' discoveries).
        manifest: the validated manifest (values per benchmark and team).
        out: the results folder (``cache/`` and ``executions/<id>/`` go in it).
        workers: local worker processes (1: in this process); with ``scheduler``, the
            LocalCluster's workers.
        scheduler: a Dask scheduler address, ``local``, or None.
        use_cache: False: score everything again (the cache is still refreshed).
        reports: write each execution's report folder.
        command: the command line, for provenance.
        problems: problems found before scoring (the logs' discovery, the timeline).
        timeline: the ``timeline`` entry of the document (figure, sessions).
        progress: told of every execution done.
        on_outcome: called with each outcome as it arrives (the CLI's stderr lines), but a
            robot log's with no topic to compare (no row: its execution's warning says so).
        dask: the ``scheduler``'s client, started earlier (the caller closes it).
    """
    out.mkdir(parents=True, exist_ok=True)
    cache_dir = out / "cache"
    hashes = FileHashes(cache_dir / "hashes.json")
    cache = Cache(cache_dir, hashes)
    planned = plan(executions, manifest, out, reports=reports)
    outcomes: dict[str, Outcome] = {}
    cached: set[str] = set()
    keys: dict[str, str] = {}
    # each job's files as keyed: what its row records, and what is checked once it is scored
    keyed: dict[str, Fingerprints] = {}
    inputs: dict[str, list[dict[str, Any]]] = {}
    to_run: list[Job] = []
    scorer: dict[str, str] = {}  # a key -> the id of the job that scores it
    sharing: dict[str, list[str]] = {}  # that id -> the ids of the same key, given its outcome
    for p in planned:
        if p.missing:
            outcomes[p.job.id] = Outcome(p.job.id, "unscoreable", reason="; ".join(p.missing))
            continue
        try:
            keys[p.job.id] = job_key(p.job, hashes)
            inputs[p.job.id] = records(p.job.values, hashes)
        except OSError as err:  # a bag gone between discovery and now: the moment's verdict
            outcomes[p.job.id] = Outcome(
                p.job.id,
                "unscoreable",
                reason=f"cannot read {err.filename}: {err.strerror}",
                machine=True,
            )
            continue
        keyed[p.job.id] = fingerprints(p.job, hashes)
        hit = cache.get(keys[p.job.id], p.job) if use_cache else None
        if hit is not None:
            outcomes[p.job.id] = hit
            cached.add(p.job.id)
        elif keys[p.job.id] in scorer:  # the same bytes, team and inputs: scored once
            sharing.setdefault(scorer[keys[p.job.id]], []).append(p.job.id)
        else:
            scorer[keys[p.job.id]] = p.job.id
            to_run.append(p.job)
    hashes.save()
    if cache.invalid:
        path, why = cache.invalid[0]
        more = f" and {len(cache.invalid) - 1} more" if len(cache.invalid) > 1 else ""
        log.warning(
            "%d cache entr%s not used, scored again (%s: %s%s); the cache is not signed: "
            "docs/rescore.md",
            len(cache.invalid),
            "y" if len(cache.invalid) == 1 else "ies",
            path.name,
            why,
            more,
        )

    total = len(planned)
    state = {"done": len(outcomes), "bad": sum(o.status != "scored" for o in outcomes.values())}

    def tell() -> None:
        if progress is not None:
            label = "rescoring" + (f" ({state['bad']} not scored)" if state["bad"] else "")
            progress.task(label, total, "executions")
            progress.advance(state["done"])

    # a robot log with no topic to compare is no row (its execution's warning says so): not
    # told; every other execution not scored is, a missing topic's too
    robot_jobs = {p.job.id for p in planned if p.of is not None}

    def told(outcome: Outcome) -> None:
        if on_outcome is not None and not (outcome.id in robot_jobs and _no_topics(outcome)):
            on_outcome(outcome)

    for outcome in outcomes.values():
        told(outcome)
    tell()

    def done(scored: Outcome) -> None:
        copies = [
            replace(scored, id=other, warnings=(*scored.warnings, same_as(scored.id)))
            for other in sharing.get(scored.id, [])
        ]
        for outcome in (scored, *copies):
            changed = changed_files(keyed[outcome.id], hashes)
            # scored from bytes that are not those keyed and recorded: no score (a row that
            # says why it has none, of the moment, says it better: a file it could not find)
            if changed and (outcome.status == "scored" or not outcome.machine):
                outcome = input_changed(outcome, changed)
            outcomes[outcome.id] = outcome
            cache.put(keys[outcome.id], outcome)
            state["done"] += 1
            state["bad"] += outcome.status != "scored"
            told(outcome)
        tell()

    # what the cache hits took tells the schedule which benchmarks cost most
    known = [(p.job.benchmark, outcomes[p.job.id].seconds) for p in planned if p.job.id in cached]
    run_jobs(to_run, workers=workers, scheduler=scheduler, on_done=done, known=known, dask=dask)
    return document(
        planned,
        outcomes,
        cached,
        manifest,
        out,
        hashes,
        command=command,
        options={"jobs": workers, "scheduler": scheduler},
        problems=problems,
        timeline=timeline,
        inputs=inputs,
        keyed=keyed,
    )


def same_as(ident: str) -> str:
    """The warning of an execution whose bytes, team and inputs are another's (its cache key):
    a log copied under two names, listed twice."""
    return (
        f"the same logs (byte for byte), team, time and inputs as {ident}: scored once, as {ident}"
    )


def input_changed(outcome: Outcome, changed: Sequence[str]) -> Outcome:
    """The row of an execution one of whose files changed (or went) while it was scored: its
    score came from bytes no longer there, or from a mix of old and new; not cached."""
    more = f" and {len(changed) - 1} more" if len(changed) > 1 else ""
    return Outcome(
        outcome.id,
        "failed",
        reason=(
            f"its input changed or went while it was scored ({changed[0]}{more}): no score "
            "kept; "
            "run rescore again to score the files as they are now"
        ),
        warnings=outcome.warnings,
        seconds=outcome.seconds,
        error="InputChanged",
        machine=True,
    )


def _rel(path: str | None, out: Path) -> str | None:
    if path is None:
        return None
    try:
        return Path(path).relative_to(out.resolve()).as_posix()
    except ValueError:
        try:
            return Path(path).relative_to(out).as_posix()
        except ValueError:
            return path


def document(
    planned: Sequence[Planned],
    outcomes: Mapping[str, Outcome],
    cached: set[str],
    manifest: Manifest,
    out: Path,
    hashes: FileHashes,
    *,
    command: Sequence[str],
    options: Mapping[str, Any],
    problems: Sequence[Mapping[str, Any]],
    timeline: Mapping[str, Any] | None,
    inputs: Mapping[str, list[dict[str, Any]]] | None = None,
    keyed: Mapping[str, Fingerprints] | None = None,
) -> dict[str, Any]:
    """The ``results.json`` document (docs/rescore.md). ``inputs`` (a row's input records) and
    ``keyed`` (its files' SHA-256), by execution id, as they were when the executions were
    keyed: the hashes of the bytes scored, not of what lies there now."""
    inputs = inputs or {}
    scored = {
        name: (digest, _size(state))
        for prints in (keyed or {}).values()
        for name, (state, digest) in prints.items()
        if digest and state is not None
    }
    rows: list[dict[str, Any]] = []
    all_problems = [dict(p) for p in problems]
    files: dict[str, Path] = {}
    # A robot log without the topics its comparison needs (most robots log no pose in an
    # object perception benchmark) is no row: a line in its execution's warnings says so.
    skipped: dict[str, list[str]] = {}
    for p in planned:
        o = outcomes[p.job.id]
        if p.of is not None and _no_topics(o):
            skipped.setdefault(p.of, []).append(
                f"robot log {p.execution.bags[0]}: not compared with the GT by "
                f"{p.job.benchmark} ({o.reason})"
            )
    for p in planned:
        e, job = p.execution, p.job
        o = outcomes[job.id]
        if p.of is not None and _no_topics(o):
            continue
        row_inputs = inputs[job.id] if job.id in inputs else records(job.values, hashes)
        for bag in e.bags:
            files[str(bag)] = bag
        for value in job.values.values():
            for item in value if isinstance(value, tuple | list) else (value,):
                if isinstance(item, Path):
                    files[str(item)] = item
        for line in p.missing:
            all_problems.append(
                {"kind": "missing-input", "path": None, "message": f"{job.id}: {line}"}
            )
        rows.append(
            {
                "id": job.id,
                "benchmark": job.benchmark,
                "title": p.title,
                "team": e.team,
                "team_source": e.team_source,
                "start_ns": e.start_ns,
                "end_ns": e.end_ns,
                "start": iso_utc(e.start_ns) if e.start_ns is not None else None,
                "end": iso_utc(e.end_ns) if e.end_ns is not None else None,
                "bags": [str(b) for b in e.bags],
                "inputs": row_inputs,
                "status": o.status,
                "reason": o.reason,
                "score": o.score,
                "rank_value": o.rank_value,
                "warnings": [
                    *([TEAM_UNKNOWN] if e.team is None and p.of is None else []),
                    *o.warnings,
                    *e.notes,
                    *skipped.get(job.id, []),
                ],
                "deviations": list(o.deviations),
                "live_score": o.live_score,
                "live_differences": list(o.live_differences),
                "report": _rel(o.report, out),
                "of": p.of,
                "cached": job.id in cached,
                "seconds": o.seconds,
            }
        )
    deviations = sorted({d for row in rows for d in row["deviations"]})
    provenance = []
    for name, path in sorted(files.items()):
        try:
            digest, size = scored.get(name) or (hashes.sha256(path), hashes.size(path))
            provenance.append({"path": name, "sha256": digest, "size": size})
        except OSError:
            provenance.append({"path": name, "sha256": None, "size": None})
    hashes.save()
    return {
        "schema_version": SCHEMA_VERSION,
        "ertools_version": __version__,
        "generated": datetime.now(UTC).isoformat(timespec="seconds"),
        "command": list(command),
        "manifest": {
            "path": str(manifest.path),
            "sha256": manifest.sha256,
            "title": manifest.title,
        },
        "options": dict(options),
        "timeline": dict(timeline) if timeline is not None else None,
        "executions": rows,
        "leaderboards": leaderboards(rows),
        "problems": all_problems,
        "deviations_in_force": deviations,
        "inputs": provenance,
    }


def _size(state: tuple[Any, ...]) -> int:
    """The size in a :func:`~ertools.competition.cache.file_state` (a folder's: its files')."""
    if state and isinstance(state[0], tuple):
        return sum(int(f[1]) for f in state)
    return int(state[0]) if state else 0


def _no_topics(outcome: Outcome) -> bool:
    return outcome.status == "unscoreable" and outcome.error == "TopicError"


def _placings(doc: Mapping[str, Any]) -> dict[str, dict[str, Any]]:
    """Execution id -> its leaderboard row's rank stability, as results.csv columns."""
    out: dict[str, dict[str, Any]] = {}
    for board in doc.get("leaderboards") or []:
        for row in board.get("rows") or []:
            interval = row.get("interval") or (None, None)
            out[str(row.get("execution"))] = {
                "rank": row.get("rank"),
                "rank_group": row.get("rank_group"),
                "interval_low": interval[0],
                "interval_high": interval[1],
                "p_swap_next": row.get("p_swap_next"),
                "tied_with": "; ".join(row.get("tied_with") or []),
            }
    return out


def csv_text(doc: Mapping[str, Any]) -> str:
    buffer = io.StringIO()
    writer = csv.DictWriter(
        buffer, fieldnames=CSV_COLUMNS, extrasaction="ignore", lineterminator="\n"
    )
    writer.writeheader()
    placings = _placings(doc)
    for row in doc["executions"]:
        row = {**row, **placings.get(str(row["id"]), {})}
        writer.writerow(
            {k: "" if row.get(k) is None else spreadsheet_safe(row[k]) for k in CSV_COLUMNS}
        )
    return buffer.getvalue()


def write_results(doc: Mapping[str, Any], out: Path) -> list[Path]:
    """``results.json``, ``results.csv`` and the results page ``index.html``."""
    out.mkdir(parents=True, exist_ok=True)
    written = []
    for name, text in (
        ("results.json", json.dumps(doc, indent=2, allow_nan=False) + "\n"),
        ("results.csv", csv_text(doc)),
    ):
        written.append(write_text(out / name, text))
    # the results page, rebuilt from the document alone (ertools.competition.site)
    written.append(write_site(dict(doc), out))
    return written
