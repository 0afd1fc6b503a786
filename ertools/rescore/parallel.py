"""Scoring jobs in parallel: local worker processes (``--jobs N``) or a Dask cluster
(``--scheduler ADDRESS|local``).

Each local worker is a process of its own holding one job at a time, so that when one dies
(killed for memory, a crash in a native library) the job it held is known: that job's row
says so and a new worker takes the rest. ``concurrent.futures`` cannot do that: a dead worker
breaks its whole pool and every job still in it. Results come back in completion order through
``on_done``; the caller orders them.
"""

from __future__ import annotations

import atexit
import contextlib
import ctypes
import logging
import multiprocessing
import multiprocessing.connection
import os
import pickle
import signal
import sys
import threading
import time
from collections.abc import Callable, Iterable, Iterator, Sequence
from importlib import import_module
from typing import Any

from ertools.benchmarks import registry
from ertools.errors import ConfigError
from ertools.report import html
from ertools.report.figures import preload
from ertools.rescore.jobs import Job, Outcome, load_benchmark, run_job
from ertools.rescore.schedule import Schedule

OnDone = Callable[[Outcome], None]
log = logging.getLogger(__name__)


def default_jobs() -> int:
    return os.cpu_count() or 1


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
    several workers, the longest expected first (:mod:`ertools.rescore.schedule`; ``known``:
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


# prctl(2): PR_SET_PDEATHSIG, the signal the kernel sends a process when its parent ends
_PR_SET_PDEATHSIG = 1


def end_with_parent(parent: int) -> None:
    """End this process when its parent ``parent`` ends, however that ends (``kill -9``
    included): a worker left behind holds its memory and its job for ever, blocked on a pipe
    whose other end its siblings keep open (inherited by fork).

    Linux: the kernel sends SIGKILL (``PR_SET_PDEATHSIG``). Elsewhere a thread watches the
    parent's pid. Either way, a parent that died before this was set up is caught at once.
    """
    if sys.platform.startswith("linux"):
        try:
            libc = ctypes.CDLL(None, use_errno=True)
            if libc.prctl(_PR_SET_PDEATHSIG, signal.SIGKILL, 0, 0, 0) == 0:
                if os.getppid() != parent:  # it died between the fork and the prctl
                    os._exit(1)
                return
        except (OSError, AttributeError):  # no prctl in this libc: watch instead
            pass
    threading.Thread(target=_watch_parent, args=(parent,), daemon=True).start()


def _watch_parent(parent: int) -> None:
    while os.getppid() == parent:
        time.sleep(1.0)
    os._exit(1)


def _worker(conn: multiprocessing.connection.Connection, parent: int) -> None:
    """A local worker: score the jobs it is sent until it is sent None."""
    end_with_parent(parent)
    while True:
        try:
            job = conn.recv()
        except EOFError:
            return
        if job is None:
            return
        conn.send(run_job(job))


_warmed: set[str] = set()


def _warm(job: Job) -> None:
    """Import, in the process that forks, what scoring ``job`` and drawing its report load on
    first use (its benchmark's modules, matplotlib and its font), once per process: a child
    forked per job inherits them. Without it every Dask task paid those imports again (issue
    29: Dask cost +72 % over local workers, which keep them between jobs)."""
    if job.target in _warmed:
        return
    _warmed.add(job.target)
    with contextlib.suppress(Exception):  # only a head start: the child imports what failed
        load_benchmark(job.target)
        if job.report_dir is not None:
            figures = registry.get(job.benchmark).figures
            if figures:
                import_module(figures.partition(":")[0])
            preload()
            html.environment().get_template("report.html.j2")  # compiled once, not per job


def run_job_forked(job: Job) -> Outcome:
    """:func:`run_job` in a child process forked from this one: a scorer that crashes or is
    killed (for memory) costs this job's row, never the Dask worker running it nor the other
    tasks that worker holds (the scheduler would count those as suspects of its death).
    ``os.fork``, not ``multiprocessing``: a Dask worker under a nanny is a daemonic process,
    which ``multiprocessing`` forbids to have children. Where there is no fork, in this process.

    The child stays for the next job of the same thread (as a local worker does), so that what
    a job loads on first use (matplotlib, fonts, compiled templates, the figures' canvases)
    is loaded once per worker, not once per job: forking a child per job cost the Dask path
    ~0.8 s of CPU per execution more than local workers (issue 29). A child that died is
    replaced by the next job."""
    if not hasattr(os, "fork"):
        return run_job(job)
    child: _Child | None = getattr(_children, "child", None)
    if child is None or child.owner != os.getpid():  # none yet, or one of a parent's
        _warm(job)
        child = _children.child = _Child()
        # reaped when the worker exits: no orphan, and its CPU time counts as the worker's
        atexit.register(child.close)
    outcome = child.run(job)
    if outcome is not None:
        return outcome
    code = child.close()
    _children.child = None
    return Outcome(
        job.id,
        "failed",
        reason=f"the process scoring it died (exit code {code}); the other executions were scored",
    )


_children = threading.local()  # one child per thread of a Dask worker that runs tasks


class _Child:
    """A process forked from this one that scores the jobs it is sent, one at a time, until
    its input closes (this process ended: it leaves with it) or it dies."""

    def __init__(self) -> None:
        self.owner = os.getpid()
        job_read, job_write = os.pipe()
        out_read, out_write = os.pipe()
        pid = os.fork()
        if pid == 0:  # the child: leaves without running any of the parent's cleanup
            os.close(job_write)
            os.close(out_read)
            code = 0
            try:
                end_with_parent(self.owner)  # a worker killed mid-job takes its child along
                with os.fdopen(job_read, "rb") as jobs, os.fdopen(out_write, "wb") as out:
                    while True:
                        try:
                            job = pickle.load(jobs)  # from our own parent: trusted
                        except EOFError:
                            break
                        pickle.dump(run_job(job), out)
                        out.flush()
            except BaseException:
                code = 1
            os._exit(code)
        os.close(job_read)
        os.close(out_write)
        self.pid = pid
        self._jobs = os.fdopen(job_write, "wb")
        self._out = os.fdopen(out_read, "rb")

    def run(self, job: Job) -> Outcome | None:
        """The child's outcome of ``job``; None when it died before sending one."""
        try:
            pickle.dump(job, self._jobs)
            self._jobs.flush()
            outcome: Outcome = pickle.load(self._out)  # from our own child: trusted
        except (EOFError, OSError, pickle.UnpicklingError):
            return None
        return outcome

    def close(self) -> int:
        """Close the child's input and wait for it; its exit code (0 when already waited)."""
        for fh in (self._jobs, self._out):
            with contextlib.suppress(OSError):
                fh.close()
        try:
            _, status = os.waitpid(self.pid, 0)
        except ChildProcessError:
            return 0
        return os.waitstatus_to_exitcode(status)


def _context() -> Any:
    # fork: a worker starts in milliseconds with ertools already imported; elsewhere spawn
    methods = multiprocessing.get_all_start_methods()
    return multiprocessing.get_context("fork" if "fork" in methods else "spawn")


class _Worker:
    def __init__(self, ctx: Any) -> None:
        self.conn, child = ctx.Pipe()
        self.process = ctx.Process(target=_worker, args=(child, os.getpid()), daemon=True)
        self.process.start()
        child.close()
        self.job: Job | None = None


def run_local(
    jobs: Sequence[Job],
    *,
    workers: int,
    on_done: OnDone,
    known: Iterable[tuple[str, float]] = (),
) -> None:
    """Score ``jobs`` with ``workers`` local processes, the longest expected first; a worker
    that dies costs its job."""
    ctx = _context()
    pending = Schedule(jobs, known)
    pool = [_Worker(ctx) for _ in range(min(workers, len(jobs)))]
    try:
        for worker in pool:
            _assign(worker, pending)
        while any(w.job is not None for w in pool):
            busy = [w for w in pool if w.job is not None]
            ready = multiprocessing.connection.wait(
                [w.conn for w in busy] + [w.process.sentinel for w in busy]
            )
            for i, worker in enumerate(pool):
                if worker.job is None:
                    continue
                if worker.conn in ready:
                    try:
                        outcome: Outcome = worker.conn.recv()
                    except (EOFError, OSError):
                        outcome = _died(worker)
                        pool[i] = worker = _replace(worker, ctx)
                    worker.job = None
                    pending.done(outcome)
                    _assign(worker, pending)  # the next job first: the worker waits for none
                    on_done(outcome)
                elif worker.process.sentinel in ready:
                    outcome = _died(worker)
                    pool[i] = worker = _replace(worker, ctx)
                    pending.done(outcome)
                    _assign(worker, pending)
                    on_done(outcome)
    finally:
        for worker in pool:
            with contextlib.suppress(OSError, ValueError):  # a worker already gone
                worker.conn.send(None)
        for worker in pool:
            worker.process.join(timeout=5)
            if worker.process.is_alive():
                worker.process.kill()
                worker.process.join()


def _assign(worker: _Worker, pending: Schedule) -> None:
    job = pending.next()
    if job is not None:
        worker.job = job
        worker.conn.send(job)


def _died(worker: _Worker) -> Outcome:
    worker.process.join(timeout=5)
    code = worker.process.exitcode
    assert worker.job is not None
    return Outcome(
        worker.job.id,
        "failed",
        reason=f"the worker scoring it died (exit code {code}); the other executions were scored",
    )


def _replace(worker: _Worker, ctx: Any) -> _Worker:
    worker.conn.close()
    return _Worker(ctx)


def run_dask(
    jobs: Sequence[Job],
    address: str,
    *,
    workers: int,
    on_done: OnDone,
    known: Iterable[tuple[str, float]] = (),
    dask: DaskClient | None = None,
) -> None:
    """Score ``jobs`` on a Dask cluster (``local``: a LocalCluster of ``workers`` processes).

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
    """A Dask client being connected (a LocalCluster being started: its scheduler, nannies
    and worker processes) in a thread of its own, so that a run can start it before scanning
    the logs, and close it while it writes the results: Dask's fixed costs (~3.4 s of CPU,
    mostly in the processes it starts, and seconds of waiting for them; docs/rescore.md)
    overlap the main process's own work instead of adding to it.

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

            # Without the workers' statistical profiler (a thread sampling every 10 ms, ~5 %
            # of a core per worker: measured in docs/performance.md), and without the
            # MALLOC_TRIM_THRESHOLD_=65536 the nannies put in their workers' environment: glibc
            # then hands every freed array back to the kernel, and the next execution faults
            # its pages in again (a local worker keeps them). The event loops' tick monitor
            # (every 20 ms), the system monitor (500 ms) and the memory monitor (100 ms) of
            # the scheduler, nannies and workers cost 7 % of a core while the cluster waits
            # (1.08 s of CPU in 15 s); at 1 s, 5 s and 1 s, 1.5 % (0.23 s). The nannies hand
            # this configuration to the worker processes they start.
            with dask.config.set(
                {
                    "distributed.worker.profile.enabled": False,
                    "distributed.nanny.pre-spawn-environ.MALLOC_TRIM_THRESHOLD_": None,
                    "distributed.admin.tick.interval": "1s",
                    "distributed.admin.system-monitor.interval": "5s",
                    "distributed.worker.memory.monitor-interval": "1s",
                }
            ):
                cluster = distributed.LocalCluster(
                    n_workers=max(workers, 1),
                    threads_per_worker=1,
                    processes=True,
                    dashboard_address=None,
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
