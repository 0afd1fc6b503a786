"""One execution to score, as a worker receives it, and the scoring itself.

A :class:`Job` is small and picklable: the benchmark's registry entry (``module:ATTR``), the
paths of its bags and input files and its input values. Workers (local processes or Dask
workers) read the logs by path from a shared file system; no bag bytes travel with the job.
:func:`run_job` never raises for a problem of the execution itself: it returns an
:class:`Outcome` saying ``scored``, ``unscoreable`` (an :class:`ErtoolsError`: the data or the
inputs cannot be scored) or ``failed`` (anything else: a bug, one line), so one bad execution
costs one row.
"""

from __future__ import annotations

import contextlib
import logging
import threading
import time
import traceback
from collections.abc import Iterator, Mapping
from dataclasses import field
from pathlib import Path
from typing import Any, Literal

from ertools.auditing.compare import attach
from ertools.benchmarks import registry
from ertools.benchmarks.base import Discovered, Reported
from ertools.benchmarks.common.teams import with_team
from ertools.benchmarks.document import all_failed, score_json
from ertools.benchmarks.scoring import score_execution
from ertools.errors import ErtoolsError, transient_error, watching
from ertools.frozen_dataclass import frozen_dataclass
from ertools.progress import reporting
from ertools.report.folder import _audit_inputs, write_report
from ertools.rsbb.score import ScoreComparison
from ertools.serialize import jsonable

Status = Literal["scored", "unscoreable", "failed"]


@frozen_dataclass
class Job:
    """One execution to score.

    Attributes:
        id: the execution's stable id (``fbm3w-robotto-20151120T123105``).
        benchmark: its registry name.
        target: the registry entry (``module:ATTR``), imported by the worker: a worker needs
            nothing but this job and the file system.
        team: the team, when known (kept in the result as ``--team`` would).
        bags: the logs, absolute paths.
        values: the benchmark's input values by :attr:`Input.name` (paths absolute).
        report_dir: where its report folder goes (None: no report).
        argv: the equivalent ``ertools score`` command line, shown in the report.
    """

    id: str
    benchmark: str
    target: str
    team: str | None
    bags: tuple[str, ...]
    values: Mapping[str, Any] = field(default_factory=dict)
    report_dir: str | None = None
    argv: tuple[str, ...] = ()


@frozen_dataclass
class Outcome:
    """What scoring one job gave (everything JSON-able, for the cache and the row)."""

    id: str
    status: Status
    reason: str | None = None
    score: dict[str, Any] | None = None
    rank_value: float | None = None
    warnings: tuple[str, ...] = ()
    deviations: tuple[str, ...] = ()
    live_score: Any = None
    live_differences: tuple[str, ...] = ()
    report: str | None = None
    seconds: float = 0.0
    error: str | None = None  # the error's class (``TopicError``) when not scored
    # not the data's fault but the machine's (a folder not writable, a disk full): not cached
    machine: bool = False

    def to_dict(self) -> dict[str, Any]:
        return {
            "id": self.id,
            "status": self.status,
            "reason": self.reason,
            "score": self.score,
            "rank_value": self.rank_value,
            "warnings": list(self.warnings),
            "deviations": list(self.deviations),
            "live_score": self.live_score,
            "live_differences": list(self.live_differences),
            "report": self.report,
            "seconds": self.seconds,
            "error": self.error,
            "machine": self.machine,
        }

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> Outcome:
        return cls(
            id=str(data["id"]),
            status=data["status"],
            reason=data.get("reason"),
            score=data.get("score"),
            rank_value=data.get("rank_value"),
            warnings=tuple(data.get("warnings", ())),
            deviations=tuple(data.get("deviations", ())),
            live_score=data.get("live_score"),
            live_differences=tuple(data.get("live_differences", ())),
            report=data.get("report"),
            seconds=float(data.get("seconds", 0.0)),
            error=data.get("error"),
            machine=bool(data.get("machine", False)),
        )


def one_line(text: str) -> str:
    return " ".join(text.split())


def run_job(job: Job) -> Outcome:
    """Score one job; every problem becomes the outcome's status and reason, never a raise."""
    start = time.perf_counter()
    # what the readers log (a file not indexed...) belongs to this execution's row, not to
    # stderr interleaved from several workers
    with _capturing() as captured:
        outcome, met = _outcome(job)
    seconds = round(time.perf_counter() - start, 3)
    logged = tuple(dict.fromkeys(captured))
    extra: tuple[str, ...] = ()
    if met and not outcome.machine:
        # met and handled by the scorer (a GT file skipped for a moment): what it computed may
        # not be what the same bytes give next time
        extra = (transient_note(met[0]),)
    return Outcome(
        **{
            **outcome.__dict__,
            "seconds": seconds,
            "warnings": (*logged, *outcome.warnings, *extra),
            "machine": outcome.machine or bool(met),
        }
    )


def _outcome(job: Job) -> tuple[Outcome, list[BaseException]]:
    """The job's outcome, and the transient errors met while it was scored."""
    met: list[BaseException] = []
    try:
        # a worker forked from the command holds its progress bar: the bar is the parent's, and
        # counts executions; the reads inside one report nothing
        with reporting(None), watching() as met:
            return _score(job), met
    except ErtoolsError as err:
        return Outcome(
            job.id,
            "unscoreable",
            reason=one_line(str(err)),
            error=type(err).__name__,
            machine=transient_error(err),
        ), met
    except Exception as err:  # a bug in a scorer: this execution's row only
        where = traceback.extract_tb(err.__traceback__)[-1] if err.__traceback__ else None
        at = f" at {Path(where.filename).name}:{where.lineno}" if where else ""
        return Outcome(
            job.id,
            "failed",
            reason=one_line(f"unexpected {type(err).__name__}: {err}{at}"),
            error=type(err).__name__,
        ), met


def transient_note(err: BaseException) -> str:
    """The warning of an execution scored while a problem of the machine or the moment was met
    (:func:`ertools.errors.transient_error`): not cached, scored again by the next run."""
    return (
        f"a problem of the machine or the moment was met while it was scored "
        f"({one_line(str(err))}): not kept in the cache, a rerun scores it again"
    )


class _Dispatch(logging.Handler):
    """On the ``ertools`` logger while jobs are scored: a record logged by a thread scoring a
    job goes to that job's lines; any other thread's to the handlers the logger had. Two
    rescorings of one process score in two threads at once (jobs=1, or two calls of a
    notebook): each job's warnings are its own row's, and the logger is given back whole."""

    def __init__(self) -> None:
        super().__init__(logging.NOTSET)
        self.lines = threading.local()  # .lines: the current thread's job's lines
        self.guard = threading.Lock()
        self.users = 0
        self.saved: tuple[list[logging.Handler], bool] = ([], True)

    def emit(self, record: logging.LogRecord) -> None:
        lines: list[str] | None = getattr(self.lines, "lines", None)
        if lines is not None:
            if record.levelno >= logging.WARNING:
                lines.append(one_line(record.getMessage()))
            return
        handlers, propagate = self.saved
        for handler in handlers:
            if record.levelno >= handler.level:
                handler.handle(record)
        parent = logging.getLogger("ertools").parent
        if propagate and parent is not None:
            parent.callHandlers(record)

    @contextlib.contextmanager
    def capture(self) -> Iterator[list[str]]:
        """The warnings this thread logs while the block runs (not shown elsewhere)."""
        logger = logging.getLogger("ertools")
        with self.guard:
            if self.users == 0:
                self.saved = (logger.handlers[:], logger.propagate)
                logger.handlers[:] = [self]
                logger.propagate = False
            self.users += 1
        outer = getattr(self.lines, "lines", None)
        lines: list[str] = []
        self.lines.lines = lines
        try:
            yield lines
        finally:
            self.lines.lines = outer
            with self.guard:
                self.users -= 1
                if self.users == 0:
                    logger.handlers[:], logger.propagate = self.saved


_capturing = _Dispatch().capture


def _score(job: Job) -> Outcome:
    benchmark = registry.load(job.target)
    bags = [Path(p) for p in job.bags]
    # the manifest chose the benchmark of each execution: its logs are not second-guessed
    scored = score_execution(benchmark, bags, dict(job.values), check_logs=False)
    result = scored.result
    if all_failed(result):
        return Outcome(job.id, "unscoreable", reason=one_line("; ".join(result.failures)))
    files = list(bags)  # as the score command's report
    if isinstance(benchmark, Reported):
        files = benchmark.input_files(bags, scored.options, result)
    result = with_team(result, job.team, files)
    warnings = tuple(str(w) for w in result.warnings)
    warnings += tuple(f"error: {f}" for f in result.failures)  # runs that failed, others scored
    audit = _live_audit(result, bags)
    live_score, differences = _rsbb_live(result)
    if audit is not None:
        live_score = jsonable(audit.live_score)
        if audit.comparison is not None:
            # with what explains it (a rule of the benchmark, a deviation's key), for the page
            differences = tuple(
                f"{line.key}: live {line.live} vs recomputed {line.recomputed}"
                + (f"; why: {one_line(line.explanation)}" if line.explanation else "")
                for line in audit.comparison.differences
            )
    report = None
    if job.report_dir is not None:
        index = write_report(
            result,
            Path(job.report_dir),
            inputs=files,
            argv=list(job.argv),
            audit=audit,
            team=job.team,
        )
        report = str(index)
    rank = benchmark.ranking.key(result) if isinstance(benchmark, Discovered) else None
    # valid data too thin for a score (issue 28): a verdict on the execution, its report kept
    unscoreable = getattr(result, "unscoreable_reason", None)
    return Outcome(
        job.id,
        "unscoreable" if unscoreable else "scored",
        reason=one_line(unscoreable) if unscoreable else None,
        score=score_json(result),
        rank_value=None if rank is None else float(rank),
        warnings=warnings,
        deviations=tuple(str(d) for d in result.deviations),
        live_score=live_score,
        live_differences=differences,
        report=report,
    )


def _rsbb_live(result: Any) -> tuple[Any, tuple[str, ...]]:
    """An RSBB benchmark's live score (``/rsbb/current_benchmark_result``, flattened) and
    where the recomputed score differs from it, from the result's own comparison; (None, ())
    for a result without one."""
    comparison = getattr(result, "comparison", None)
    if not isinstance(comparison, ScoreComparison) or comparison.live_t_ns is None:
        return None, ()
    live = {k.key: k.live for k in comparison.keys if k.present[1]}
    differences = tuple(
        f"{k.key}: live {k.live!r} vs recomputed {k.recomputed!r}"
        for k in comparison.differing("live")
    )
    return jsonable(live), differences


def _live_audit(result: Any, bags: list[Path]) -> Any:
    """The audit of the bags' state topics with its live-vs-recomputed comparison, or None
    (a benchmark without state topics, or logs without them)."""

    audit = _audit_inputs(result.name, bags)
    return None if audit is None else attach(audit, result)
