"""Scoring processes: each forked from one single-threaded process, the fork server.

A process forked from a multi-threaded one holds every lock another thread held at that
instant, for ever (docs/rescore.md: a scorer forked from the threads of a LocalCluster hung
on such a lock). The fork server has one thread when it forks. It is forked from
``rescore`` before any thread starts (:func:`forks_ready`); in a process that already has
threads (a Dask worker, a notebook) it is a fresh interpreter instead
(``python -m ertools.competition.children``). It keeps what a job loads on first use imported
(the benchmark's modules, what they import lazily, the SVG figure writer, the report
template), so each child starts warm in milliseconds.

A child scores the jobs it is sent, one at a time, over a socket of its own, until that
socket closes; one that dies costs its job only. Every process here ends with its parent,
however that ends (:func:`end_with_parent`).
"""

from __future__ import annotations

import atexit
import contextlib
import ctypes
import os
import pickle
import signal
import socket
import struct
import subprocess
import sys
import threading
import time
from collections.abc import Iterator
from typing import BinaryIO

from ertools.benchmarks import registry
from ertools.competition.jobs import Job, Outcome, run_job
from ertools.report import html
from ertools.report.figures import preload

# prctl(2): PR_SET_PDEATHSIG, the signal the kernel sends a process when its parent ends
_PR_SET_PDEATHSIG = 1
_LENGTH = struct.Struct("!I")  # a request's length, before its pickle
_NUMBER = struct.Struct("!q")  # a reply: a child's pid, or its exit code


class ForkServerError(RuntimeError):
    """The fork server ended (killed by hand or for memory), or could not fork: not a
    ``BrokenPipeError``, which the command line reads as its own output closed."""


class ForkFailedError(ForkServerError):
    """The fork server runs, but could not fork a scorer (out of processes or memory)."""


def end_with_parent(parent: int) -> None:
    """End this process when its parent ``parent`` ends, however that ends (``kill -9``
    included): a worker left behind holds its memory and its job for ever, blocked on a pipe
    whose other end its siblings keep open (inherited by fork).

    Linux: the kernel sends SIGKILL (``PR_SET_PDEATHSIG``: when the parent's thread that forked
    this one ends). Elsewhere a thread watches the parent's pid. Either way, a parent that died
    before this was set up is caught at once.
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


# What scoring imports only where it is used (each a `# lazy:` import, so that the command line
# starts fast): imported by the server as it starts, or each scorer imports them on its first
# job (hundreds of modules, docs/performance.md: --jobs 2 paid them twice where --jobs 1 paid
# them once). tests/rescore/test_rescore_children.py checks
# that every lazy scipy import of ertools is here.
SCORING_IMPORTS = ("scipy.spatial.transform", "scipy.interpolate", "scipy.special")

_warmed: set[str] = set()


def preload_scoring() -> None:
    """Import :data:`SCORING_IMPORTS` (in the server: while its owner scans the logs)."""
    with contextlib.suppress(Exception):  # only a head start: a scorer imports what failed
        # (imported for what they leave in sys.modules: the scorers forked later inherit them)
        import scipy.interpolate  # lazy: scipy, 300 ms
        import scipy.spatial.transform  # lazy: scipy, 300 ms
        import scipy.special  # noqa: F401  # lazy: scipy, 300 ms


def ertools_own(target: str) -> bool:
    """Whether the registry entry ``target`` is one of ertools' benchmarks (whose lazy imports
    :data:`SCORING_IMPORTS` lists), not another's (a test's toy)."""
    return target.startswith("ertools.")


def warm(job: Job) -> None:
    """Import what scoring ``job`` and drawing its report load on first use (its benchmark's
    modules, the SVG figure writer, the compiled template), once per process: the children
    forked after it inherit them (issue 29: re-importing them per task cost the Dask path
    +72 % over local workers)."""
    if job.target in _warmed:
        return
    _warmed.add(job.target)
    if ertools_own(job.target):
        preload_scoring()
    with contextlib.suppress(Exception):  # only a head start: the child imports what failed
        registry.warm(job.target, report=job.report_dir is not None)
        if job.report_dir is not None:
            preload()
            html.environment().get_template("report.html.j2")


class Child:
    """A scoring process of the fork server: :meth:`run` sends it a job and waits for the
    outcome; :meth:`close` ends it and says how it ended."""

    def __init__(self, server: ForkServer, pid: int, channel: socket.socket) -> None:
        self.owner = os.getpid()
        self.pid = pid
        self._server = server
        self._channel = channel
        self._jobs = channel.makefile("wb")
        self._out = channel.makefile("rb")
        self._closed = False
        self._busy = False

    def run(self, job: Job) -> Outcome | None:
        """The child's outcome of ``job``; None when it died before sending one."""
        return self.receive() if self.send(job) else None

    def send(self, job: Job) -> bool:
        """Hand the child ``job``; False when it is dead."""
        try:
            pickle.dump(job, self._jobs)
            self._jobs.flush()
        except (OSError, ValueError):  # ValueError: closed meanwhile, as in receive
            return False
        self._busy = True
        return True

    def receive(self) -> Outcome | None:
        """The outcome of the job sent last (waiting for it); None when the child died."""
        try:
            outcome: Outcome = pickle.load(self._out)  # from our own child: trusted
        except (EOFError, OSError, ValueError, pickle.UnpicklingError):
            return None  # ValueError: closed meanwhile (the process's server closed)
        self._busy = False
        return outcome

    def fileno(self) -> int:
        """The channel's descriptor: readable when an outcome arrived, or the child died."""
        return self._channel.fileno()

    def close(self) -> int | None:
        """Close the child's input (an idle child leaves at once; one still scoring is killed:
        the run was interrupted) and wait for it; its exit code (None when the server ended
        first: it took its children along)."""
        if self._closed:
            return 0
        self._closed = True
        if self._busy:
            with contextlib.suppress(OSError):
                os.kill(self.pid, signal.SIGKILL)
        for fh in (self._jobs, self._out, self._channel):
            with contextlib.suppress(OSError):
                fh.close()
        return self._server.wait(self.pid)


class ForkServer:
    """The fork server of this process (see the module's text); :meth:`child` is safe from
    any thread."""

    def __init__(self, *, preload: bool = False) -> None:
        self.owner = os.getpid()
        self._lock = threading.Lock()
        ours, theirs = socket.socketpair()
        self._popen: subprocess.Popen[bytes] | None = None
        self._reaped = False  # its pid may belong to another process since
        if threading.active_count() == 1:  # no other thread: nothing locked to inherit
            pid = os.fork()
            if pid == 0:
                ours.close()
                code = 0
                try:
                    end_with_parent(self.owner)
                    _serve(theirs, preload=preload)
                except BaseException:
                    code = 1
                os._exit(code)  # none of the parent's cleanup
            self._pid = pid
        else:
            # with this process's import path: a notebook's sys.path.insert included
            path = os.pathsep.join(p for p in sys.path if p)
            self._popen = subprocess.Popen(
                [sys.executable, "-m", __name__, str(theirs.fileno()), str(self.owner)]
                + (["preload"] if preload else []),
                pass_fds=[theirs.fileno()],
                stdin=subprocess.DEVNULL,
                # a Ctrl-C at the terminal is its owner's to act on (it closes the server);
                # in the terminal's process group, the server would print its own traceback
                start_new_session=True,
                env={**os.environ, "PYTHONPATH": path},
            )
            self._pid = self._popen.pid
        theirs.close()
        self._control = ours

    def child(self, job: Job) -> Child:
        """A new scoring child, forked once the server has loaded what ``job`` needs.

        Raises:
            ForkServerError: the server ended, or could not fork.
        """
        with self._lock:
            _send(self._control, ("child", job))
            pid, fds = _reply(self._control, fds=1)
        if pid < 0:  # it could not fork (out of processes or memory)
            raise ForkFailedError(
                f"the fork server could not start a scoring process: {os.strerror(-pid)}"
            )
        child = Child(self, pid, socket.socket(fileno=fds[0]))
        with _server_lock:
            _children.append(child)  # closed with the server, whoever forgets it
        return child

    def wait(self, pid: int) -> int | None:
        """The exit code of the server's child ``pid``, once it ended (None: server gone)."""
        with self._lock:
            try:
                _send(self._control, ("wait", pid))
                code, _ = _reply(self._control, fds=0)
            except ForkServerError:
                return None
        return code

    def alive(self) -> bool:
        """Whether the server still runs (killed by hand, or for memory, it is not)."""
        if self._popen is not None:
            return self._popen.poll() is None
        if not self._reaped:
            try:
                self._reaped = os.waitpid(self._pid, os.WNOHANG) != (0, 0)
            except ChildProcessError:
                self._reaped = True
        return not self._reaped

    def close(self) -> None:
        """End the server (its children end with it) and reap it: killed, not waited for
        through what it may still be importing (a rerun that scored nothing)."""
        with contextlib.suppress(OSError):
            self._control.close()
        if self._popen is not None:
            self._popen.kill()  # nothing once reaped
            self._popen.wait()
        elif not self._reaped:
            self._reaped = True
            with contextlib.suppress(ProcessLookupError):
                os.kill(self._pid, signal.SIGKILL)
            with contextlib.suppress(ChildProcessError):
                os.waitpid(self._pid, 0)


def _send(control: socket.socket, request: tuple[str, object]) -> None:
    data = pickle.dumps(request)
    try:
        control.sendall(_LENGTH.pack(len(data)) + data)
    except OSError as err:
        raise ForkServerError(f"the fork server ended ({err})") from err


def _reply(control: socket.socket, *, fds: int) -> tuple[int, list[int]]:
    try:
        data, got, _, _ = socket.recv_fds(control, _NUMBER.size, fds)
        while data and len(data) < _NUMBER.size:  # a stream: the rest may come apart
            data += control.recv(_NUMBER.size - len(data))
    except OSError as err:
        raise ForkServerError(f"the fork server ended ({err})") from err
    number: int = _NUMBER.unpack(data)[0] if len(data) == _NUMBER.size else 0
    if len(data) < _NUMBER.size or (number >= 0 and len(got) < fds):
        raise ForkServerError("the fork server ended")
    return number, list(got)


def _read(stream: BinaryIO, size: int) -> bytes | None:
    data = stream.read(size)
    return data if data is not None and len(data) == size else None


def _serve(control: socket.socket, *, preload: bool) -> None:
    """The server's loop: a child per ``child`` request, an exit code per ``wait``; ends when
    its owner closes the control socket (or dies). ``preload``: :func:`preload_scoring` first
    (while the owner scans the logs)."""
    me = os.getpid()
    if preload:
        preload_scoring()
    requests = control.makefile("rb")
    while (head := _read(requests, _LENGTH.size)) is not None:
        body = _read(requests, _LENGTH.unpack(head)[0])
        if body is None:
            break
        kind, arg = pickle.loads(body)  # from the process that started this one: trusted
        if kind == "child":
            warm(arg)
            mine, theirs = socket.socketpair()
            try:
                pid = os.fork()
            except OSError as err:  # said to the asker, who fails that job: the server goes on
                mine.close()
                theirs.close()
                control.sendall(_NUMBER.pack(-(err.errno or 1)))
                continue
            if pid == 0:
                requests.close()
                control.close()
                mine.close()
                os._exit(_score(theirs, me))
            theirs.close()
            socket.send_fds(control, [_NUMBER.pack(pid)], [mine.fileno()])
            mine.close()
        else:
            try:
                _, status = os.waitpid(arg, 0)
                code = os.waitstatus_to_exitcode(status)
            except ChildProcessError:
                code = 0
            control.sendall(_NUMBER.pack(code))


def _score(channel: socket.socket, server: int) -> int:
    """A child's life: score the jobs that come until the channel closes."""
    try:
        end_with_parent(server)  # the server ended (its owner died): so do its children
        with channel.makefile("rb") as jobs, channel.makefile("wb") as out:
            while True:
                try:
                    job = pickle.load(jobs)  # from our own server's owner: trusted
                except EOFError:
                    return 0
                pickle.dump(run_job(job), out)
                out.flush()
    except BaseException:
        return 1


_servers: dict[int, ForkServer] = {}  # by the pid that started it: a forked copy is not ours
# the calls inside forks_ready, by pid: two rescorings at once (two threads of a notebook)
# share the server, and the last to end closes it, never one the other still uses
_users: dict[int, int] = {}
_server_lock = threading.Lock()
_local = threading.local()  # a thread's child, kept for its next job (a Dask worker's thread)
_children: list[Child] = []  # every child of this process: closed with the server


def server(*, preload: bool = False) -> ForkServer:
    """This process's fork server, started now if it has none (``preload``: see
    :func:`forks_ready`)."""
    with _server_lock:
        current = _servers.get(os.getpid())
        if current is None or not current.alive():  # none yet, or it was killed: a new one
            if current is not None:
                current.close()
            _servers[os.getpid()] = ForkServer(preload=preload)
        return _servers[os.getpid()]


def close_server() -> None:
    """Close this process's scoring children and its fork server, if it has them (at exit,
    whoever still uses them: see :func:`close_idle_server`)."""
    with _server_lock:
        _close_locked()


def _close_locked() -> None:
    mine = [c for c in _children if c.owner == os.getpid()]
    _children[:] = [c for c in _children if c.owner != os.getpid()]
    for child in mine:
        child.close()
    if (ours := _servers.pop(os.getpid(), None)) is not None:
        ours.close()


atexit.register(close_server)  # no orphan; the children's CPU time counts as this process's


def close_idle_server() -> None:
    """:func:`close_server`, unless a :func:`forks_ready` block of this process still runs
    (another thread's rescoring): its last block closes it."""
    with _server_lock:
        if not _users.get(os.getpid(), 0):
            _close_locked()


@contextlib.contextmanager
def forks_ready(*, preload: bool = False) -> Iterator[None]:
    """This process's fork server, started now if it has none (in a command: before any
    thread), and then closed with its children when the last block of this process using it
    ends (blocks of several threads overlap: each its own rescoring). ``preload``: the server
    imports what ertools' benchmarks import lazily as it starts (:data:`SCORING_IMPORTS`)."""
    pid = os.getpid()
    with _server_lock:
        _users[pid] = _users.get(pid, 0) + 1
    try:
        server(preload=preload)
        yield
    finally:
        with _server_lock:
            _users[pid] -= 1
            if not _users[pid]:
                del _users[pid]
                _close_locked()


def new_child(job: Job) -> Child:
    """A new scoring child of this process's server, for ``job``; a server found dead is
    replaced once.

    Raises:
        ForkServerError: the new server ended too (ForkFailedError: a server could not fork).
    """
    try:
        return server().child(job)
    except ForkFailedError:
        raise
    except ForkServerError:  # it ended: its scorers went with it
        with _server_lock:
            dead = _servers.pop(os.getpid(), None)
        if dead is not None:
            dead.close()
        return server().child(job)


def run_job_forked(job: Job) -> Outcome:
    """:func:`run_job` in a child of this process's fork server: a scorer that crashes or is
    killed (for memory) costs this job's row, never the Dask worker running it nor the other
    tasks that worker holds (the scheduler would count those as suspects of its death).
    Where there is no fork, in this process.

    The child stays for this thread's next job (as a local worker does): what a job loads on
    first use is loaded once per worker thread, not once per job (issue 29). A child that died
    is replaced by the next job."""
    if not hasattr(os, "fork"):
        return run_job(job)
    child: Child | None = getattr(_local, "child", None)
    if child is None or child.owner != os.getpid():  # none yet, or one of a parent's
        child = _local.child = new_child(job)
    outcome = child.run(job)
    if outcome is not None:
        return outcome
    _local.child = None
    return died(child, job, "process")


def died(child: Child, job: Job, scorer: str) -> Outcome:
    """The row of ``job``, whose ``child`` died scoring it: how it ended (``exit code -9``, or
    its server ended), ``scorer`` naming the child as the user knows it (a worker, a process)."""
    code = child.close()
    how = "its fork server ended" if code is None else f"exit code {code}"
    return Outcome(
        job.id,
        "failed",
        reason=f"the {scorer} scoring it died ({how}); the other executions were scored",
    )


if __name__ == "__main__":  # a fork server as a fresh interpreter: ForkServer, with threads
    _fd, _owner = (int(arg) for arg in sys.argv[1:3])
    _preload = sys.argv[3:] == ["preload"]
    # It ends when its owner ends, however: the owner's end of the control socket closes and
    # the loop reads its end. Not by PR_SET_PDEATHSIG, which fires when the owner's *thread*
    # that started it ends: a notebook's thread that ran one rescoring, while another thread's
    # rescoring still uses the server (issue 36).
    _serve(socket.socket(fileno=_fd), preload=_preload)
