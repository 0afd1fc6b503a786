"""Scoring jobs in parallel: local worker processes (``--jobs N``) or a Dask cluster
(``--scheduler ADDRESS|local``); the scoring processes are children of the fork server
(:mod:`ertools.competition.children`).

Each local worker is a process of its own holding one job at a time, so that when one dies
(killed for memory, a crash in a native library) the job it held is known: that job's row
says so and a new worker takes the rest. ``concurrent.futures`` cannot do that: a dead worker
breaks its whole pool and every job still in it. Results come back in completion order through
``on_done``; the caller orders them.
"""

from __future__ import annotations

import contextlib
import logging
import multiprocessing.connection
import os
import sys
import threading
from collections.abc import Callable, Iterable, Iterator, Sequence
from typing import Any

from ertools.competition.children import (
    Child,
    ForkServerError,
    close_idle_server,
    died,
    forks_ready,
    new_child,
    run_job_forked,
)
from ertools.competition.jobs import Job, Outcome, run_job
from ertools.competition.schedule import Schedule
from ertools.cores import workers
from ertools.errors import ConfigError

OnDone = Callable[[Outcome], None]
log = logging.getLogger(__name__)


def default_jobs() -> int:
    """Local worker processes without ``--jobs``: the cores this process may run on (under
    ``taskset`` or a container's cpuset, not the machine's: more would only compete)."""
    return workers()


def run_jobs(
    jobs: Sequence[Job],
    *,
    workers: int,
    scheduler: str | None,
    on_done: OnDone,
    known: Iterable[tuple[str, float]] = (),
    dask: DaskClient | None = None,
) -> None:
    """Score every job (by ``workers`` local processes, or the Dask ``scheduler``); with
    several workers, the longest expected first (:mod:`ertools.competition.schedule`; ``known``:
    (benchmark, seconds) of executions already timed). ``dask``: the scheduler's client,
    already being started (:func:`early_dask`); closed in the background once the jobs are
    done."""
    if not jobs:
        return
    if scheduler is not None:
        run_dask(jobs, scheduler, workers=workers, on_done=on_done, known=known, dask=dask)
    elif workers <= 1:
        for job in jobs:  # in this process: the simplest path, and the reference for the others
            on_done(run_job(job))
    else:
        run_local(jobs, workers=workers, on_done=on_done, known=known)


def run_local(
    jobs: Sequence[Job],
    *,
    workers: int,
    on_done: OnDone,
    known: Iterable[tuple[str, float]] = (),
) -> None:
    """Score ``jobs`` with ``workers`` local processes (children of the fork server), the
    longest expected first; a worker that dies costs its job, and a new one takes the rest.
    Where there is no fork, one by one in this process."""
    if not hasattr(os, "fork"):
        for job in jobs:
            on_done(run_job(job))
        return
    pending = Schedule(jobs, known)
    with forks_ready():
        busy: dict[int, tuple[Child, Job]] = {}  # by the descriptor its outcome comes on
        for _ in range(min(workers, len(jobs))):
            _hand(busy, None, pending, on_done)
        while busy:
            for fd in multiprocessing.connection.wait(list(busy)):
                assert isinstance(fd, int)
                child, job = busy.pop(fd)
                outcome = child.receive()
                alive = outcome is not None
                if outcome is None:
                    outcome = died(child, job, "worker")
                pending.done(outcome)
                # the next job first: the worker waits for none
                _hand(busy, child if alive else None, pending, on_done)
                on_done(outcome)


def _hand(
    busy: dict[int, tuple[Child, Job]], child: Child | None, pending: Schedule, on_done: OnDone
) -> None:
    """Give the next job to ``child`` (idle), or to a new worker when ``child`` is None or has
    died since; with no job left, ``child`` ends. A job no process can be started for costs
    its own row (the fork server could not fork: out of processes or memory)."""
    while (job := pending.next()) is not None:
        if child is not None and child.send(job):
            busy[child.fileno()] = (child, job)
            return
        if child is not None:
            child.close()  # died since its outcome: of no job
        try:
            child = new_child(job)
        except ForkServerError as err:
            child = None
            outcome = Outcome(job.id, "failed", reason=f"no process could score it: {err}")
            pending.done(outcome)
            on_done(outcome)
            continue
        child.send(job)  # one that died at once says so when read
        busy[child.fileno()] = (child, job)
        return
    if child is not None:
        child.close()


def run_dask(
    jobs: Sequence[Job],
    address: str,
    *,
    workers: int,
    on_done: OnDone,
    known: Iterable[tuple[str, float]] = (),
    dask: DaskClient | None = None,
) -> None:
    """Score ``jobs`` on a Dask cluster (``local``: a LocalCluster of ``workers`` threads,
    each scoring in a child of the fork server, :mod:`ertools.competition.children`).

    Only the jobs (paths and values) go through the scheduler; workers read the logs from the
    shared file system. A job whose worker died as often as the scheduler allows
    (``distributed.scheduler.allowed-failures``) comes back as ``KilledWorker``: one row.
    ``dask``: a client started earlier (:func:`early_dask`): it is closed in the background
    (its owner waits for it), else the client is started here and closed before returning.
    """
    owned = dask is None
    handle = dask if dask is not None else DaskClient(address, workers)
    try:
        distributed, client = handle.get()
        _run_dask(distributed, client, jobs, workers=workers, on_done=on_done, known=known)
    finally:
        handle.close(wait=owned)


class DaskClient:
    """A Dask client being connected (a LocalCluster being started: its scheduler and worker
    threads) in a thread of its own, so that a run can start it before scanning the logs, and
    close it while it writes the results: Dask's fixed costs (importing ``distributed`` and
    starting the cluster; docs/rescore.md) overlap the main process's own work instead of
    adding to it.

    ``distributed``'s log records are held from the start to the close and said in one line
    (:func:`_dask_logs_as_one_line`).
    """

    def __init__(self, address: str, workers: int) -> None:
        self.address = address
        self._stack = contextlib.ExitStack()
        self._got: tuple[Any, Any] | None = None
        self._cluster: Any = None
        self._error: BaseException | None = None
        self._closing: threading.Thread | None = None
        self._thread = threading.Thread(target=self._start, args=(workers,), daemon=True)
        self._thread.start()

    def _start(self, workers: int) -> None:
        try:
            try:
                # optional extra `ertools[dask]`: imported only when a scheduler is asked for
                import distributed as _distributed  # lazy: the optional Dask extra
            except ImportError:
                raise ConfigError(
                    "--scheduler needs Dask distributed: pip install 'ertools[dask]'"
                ) from None
            distributed: Any = _distributed  # untyped calls: its API is checked by the Dask test
            self._stack.enter_context(_dask_logs_as_one_line(self.address))
            client, self._cluster = _connect(distributed, self.address, workers)
            self._got = (distributed, client)
        except BaseException as err:  # said by get(), in the thread that needs the client
            self._error = err

    def get(self) -> tuple[Any, Any]:
        """(the ``distributed`` module, the client), once started.

        Raises:
            ConfigError: Dask not installed, the scheduler not reachable.
        """
        self._thread.join()
        if self._error is not None:
            raise self._error
        assert self._got is not None
        return self._got

    def close(self, *, wait: bool = True) -> None:
        """Close the client (and the LocalCluster); ``wait`` False: in the background, see
        :meth:`join`."""
        if self._closing is None:
            self._closing = threading.Thread(target=self._close, daemon=True)
            self._closing.start()
        if wait:
            self.join()

    def join(self) -> None:
        """Wait for the start, and the close when one was asked (with :meth:`close`)."""
        self._thread.join()
        if self._closing is not None:
            self._closing.join()

    def _close(self) -> None:
        self._thread.join()
        try:
            if self._got is not None:
                with contextlib.suppress(Exception):  # a scheduler already gone
                    self._got[1].close()
            if self._cluster is not None:
                with contextlib.suppress(Exception):
                    self._cluster.close()
                # its workers were threads here: their scoring children too (unless another
                # rescoring of this process uses the server)
                close_idle_server()
        finally:
            self._stack.close()
            sys.stderr.flush()


def early_dask(scheduler: str | None, workers: int, cold: bool) -> DaskClient | None:
    """A Dask client started now, for a run that will need it: with a scheduler, on a
    ``cold`` run (nothing in the cache: every execution is to be scored). A rerun may find
    everything in the cache and need no cluster: its client is started only if needed."""
    if scheduler is None or not cold:
        return None
    return DaskClient(scheduler, workers)


class _Held(logging.Handler):
    def __init__(self) -> None:
        super().__init__(logging.ERROR)
        self.records: list[logging.LogRecord] = []

    def emit(self, record: logging.LogRecord) -> None:
        self.records.append(record)


@contextlib.contextmanager
def _dask_logs_as_one_line(address: str) -> Iterator[None]:
    """``distributed`` logs a lost scheduler as several ERROR records with tracebacks, on
    stderr by its own handlers: held here, and said in one line (each execution's row already
    says what became of it)."""
    # distributed gives several of its loggers a handler of their own (distributed.client...)
    names = ["distributed", "tornado"] + [
        name
        for name in logging.root.manager.loggerDict
        if name.startswith(("distributed.", "tornado."))
    ]
    loggers = [logging.getLogger(name) for name in names]
    saved = [(lg.handlers[:], lg.propagate) for lg in loggers]
    held = _Held()
    for lg in loggers:
        lg.handlers[:] = [held]
        lg.propagate = False
    try:
        yield
    finally:
        for lg, (handlers, propagate) in zip(loggers, saved, strict=True):
            lg.handlers[:] = handlers
            lg.propagate = propagate
        messages = [m for r in held.records if (m := r.getMessage().strip())]
        if held.records:
            first = " ".join((messages[0] if messages else "an error").split())
            more = f" ({len(held.records) - 1} more not shown)" if len(held.records) > 1 else ""
            log.warning("Dask (%s): %s%s", address, first, more)


def _connect(distributed: Any, address: str, workers: int) -> tuple[Any, Any]:
    """(the client, the LocalCluster or None) for ``address``."""
    cluster = None
    try:
        if address == "local":
            import dask.config  # lazy: the optional Dask extra (ertools[dask]), as distributed

            # The workers are threads of this process (processes=False), each scoring in a
            # child of the fork server as a --jobs worker does: no nanny and worker process
            # spawned per worker, each importing distributed and ertools (~3.4 s of CPU for
            # two, which put a 15-20 s day up to +20 % over --jobs 2). Without the workers'
            # statistical profiler (a thread sampling every 10 ms, ~5 % of a core per worker:
            # measured in docs/performance.md). The event loops' tick monitor (every 20 ms),
            # the system monitor (500 ms) and the memory monitor (100 ms) cost 7 % of a core
            # while the cluster waits (1.08 s of CPU in 15 s); at 1 s, 5 s and 1 s, 1.5 %.
            with dask.config.set(
                {
                    "distributed.worker.profile.enabled": False,
                    "distributed.admin.tick.interval": "1s",
                    "distributed.admin.system-monitor.interval": "5s",
                    "distributed.worker.memory.monitor-interval": "1s",
                }
            ):
                cluster = distributed.LocalCluster(
                    n_workers=max(workers, 1),
                    threads_per_worker=1,
                    processes=False,
                    dashboard_address=None,
                    # its scheduler's HTTP routes (health, metrics) on a free port of this
                    # machine only: at the default 8787 a second run, or anything else there,
                    # drew "Port 8787 is already in use" on the referee's terminal
                    scheduler_kwargs={"dashboard": False, "dashboard_address": "127.0.0.1:0"},
                )
            return distributed.Client(cluster), cluster
        return distributed.Client(address, timeout="10s"), None
    except (OSError, TimeoutError) as err:
        if cluster is not None:
            with contextlib.suppress(Exception):
                cluster.close()
        raise ConfigError(f"--scheduler {address}: cannot connect ({err})") from err


def _run_dask(
    distributed: Any,
    client: Any,
    jobs: Sequence[Job],
    *,
    workers: int,
    on_done: OnDone,
    known: Iterable[tuple[str, float]] = (),
) -> None:
    # Handed out as on local workers, the longest expected first: a few tasks per worker
    # thread in flight (none waits for the scheduler), the next chosen as each ends.
    pending = Schedule(jobs, known)
    slots = sum(client.nthreads().values()) or max(workers, 1)
    futures: dict[Any, Job] = {}
    running = distributed.as_completed()

    def submit() -> None:
        job = pending.next()
        if job is not None:
            key = f"rescore-{job.id}-{os.getpid()}"
            future = client.submit(run_job_forked, job, key=key, pure=False)
            futures[future] = job
            running.add(future)

    for _ in range(2 * slots):
        submit()
    for future in running:
        job = futures.pop(future)
        try:
            outcome = future.result()
        except distributed.KilledWorker:
            outcome = Outcome(
                job.id,
                "failed",
                reason="the Dask worker scoring it died; the others were scored",
            )
        except Exception as err:  # lost connection, a worker without ertools...
            text = " ".join(f"{type(err).__name__}: {err}".split())
            outcome = Outcome(job.id, "failed", reason=f"Dask: {text}")
        pending.done(outcome)
        submit()
        on_done(outcome)
        future.release()
