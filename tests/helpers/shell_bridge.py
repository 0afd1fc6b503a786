"""A bash session whose ``ertools`` commands run in this process (tests/helpers/inprocess.py).

The documentation's commands are pasted into bash as printed: bash does the quoting, globs,
variables, redirections, pipes and ``|| echo`` exactly as for a reader. Only ``ertools`` is a
shell function here: it hands its arguments and folder to this process over a FIFO, which runs
``ertools.cli.main.main`` with stdout and stderr opened on the function's own (the terminal, a
file it was redirected to, the pipe into ``head``) and replies with the exit status. What the
page shows is the commands' output, the same as from a process; each command saves the start-up
of a new interpreter (0.4 s idle, seconds on a loaded machine).

Limits, which the pages keep to: one ``ertools`` at a time (none in the background, none piped
into another), and an output file written by the command alone (not a ``{ ...; } > f`` group).
A page that needs a real process (a recording and its monitor side by side) runs without it.
"""

from __future__ import annotations

import contextlib
import io
import os
import select
import subprocess
import tempfile
import time
import traceback
from collections.abc import Iterator, Mapping
from pathlib import Path

from tests.helpers.inprocess import run

# A request is the arguments, NUL-separated: the function's process (for its file descriptors),
# its folder, the number of arguments, then each; it is whole when the function closes the
# request FIFO, and by then the function's stdout is its own again. The reply (the exit status,
# one line) comes on a FIFO the shell holds open for reading and writing from the start, so a
# reply written and closed never reads as the end of the next one.
FUNCTION = r"""
exec {ertools_reply}<>"$ERTOOLS_REPLY"
ertools() {
    { printf '%s\0' "$BASHPID" "$PWD" "$#"; [ "$#" -eq 0 ] || printf '%s\0' "$@"; } \
        > "$ERTOOLS_REQUEST"
    local code
    read -r code <&"$ertools_reply"
    return "$code"
}
"""


def parse_request(data: bytes) -> tuple[int, str, list[str]]:
    """(process, folder, arguments) of one whole request."""
    pid, cwd, count, *rest = data.split(b"\0")
    argv = [a.decode() for a in rest[: int(count)]]
    assert len(rest) == int(count) + 1 and rest[-1] == b"", data  # each field NUL-ended
    return int(pid), cwd.decode(), argv


def _flags(pid: int, fd: int) -> int:
    for line in Path(f"/proc/{pid}/fdinfo/{fd}").read_text().splitlines():
        if line.startswith("flags:"):
            return int(line.split()[1], 8)
    return 0


@contextlib.contextmanager
def _streams(pid: int) -> Iterator[tuple[io.TextIOWrapper, io.TextIOWrapper]]:
    """Text streams on the function's stdout and stderr, unbuffered (a terminal shows stdout
    and stderr interleaved as written); one stream where both are the same regular file."""
    opened: list[io.TextIOWrapper] = []

    def stream(fd: int) -> io.TextIOWrapper:
        path = f"/proc/{pid}/fd/{fd}"
        append = os.O_APPEND if _flags(pid, fd) & os.O_APPEND else 0
        raw = os.open(path, os.O_WRONLY | append)
        text = io.TextIOWrapper(
            io.FileIO(raw, "w"), encoding="utf-8", errors="strict", write_through=True
        )
        opened.append(text)
        return text

    out = stream(1)
    same = os.stat(f"/proc/{pid}/fd/1"), os.stat(f"/proc/{pid}/fd/2")
    regular = (same[0].st_mode & 0o170000) == 0o100000
    err = out if regular and same[0][1:3] == same[1][1:3] else stream(2)
    try:
        yield out, err
    finally:
        for text in opened:
            with contextlib.suppress(OSError):  # a reader gone (`| head`): as a process would
                text.close()


def _serve(pid: int, cwd: str, argv: list[str]) -> int:
    with _streams(pid) as (out, err):
        try:
            return run(argv, cwd=cwd, stdout=out, stderr=err).code
        except Exception:  # a bug in ertools: its traceback where the process would print it
            with contextlib.suppress(OSError):
                err.write(traceback.format_exc())
            return 1


def run_bash(
    script: str, *, cwd: Path, env: Mapping[str, str], timeout: float, merge: bool = True
) -> tuple[int, str, str]:
    """``bash -c script`` with ``ertools`` run in this process: (exit status, stdout, stderr);
    with ``merge``, stderr is in stdout as a terminal shows both, and the third is ``""``."""
    with tempfile.TemporaryDirectory(prefix="ertools-bridge-") as folder:
        request, reply = Path(folder) / "request", Path(folder) / "reply"
        os.mkfifo(request)
        os.mkfifo(reply)
        # Files opened for appending, not pipes: the commands run here write to them beside
        # bash (never over each other), and nothing blocks on a full pipe meanwhile.
        terminal = Path(folder) / "stdout", Path(folder) / "stderr"
        fds = [os.open(t, os.O_WRONLY | os.O_CREAT | os.O_APPEND, 0o600) for t in terminal]
        proc = subprocess.Popen(
            ["bash", "-c", FUNCTION + script],
            cwd=cwd,
            env={**env, "ERTOOLS_REQUEST": str(request), "ERTOOLS_REPLY": str(reply)},
            stdout=fds[0],
            stderr=fds[0] if merge else fds[1],
        )
        for fd in fds:
            os.close(fd)
        deadline = time.monotonic() + timeout
        try:
            while proc.poll() is None:
                data = _next_request(request, proc, deadline)
                if data is None:
                    continue
                code = _serve(*parse_request(data))
                answer = os.open(reply, os.O_WRONLY | os.O_NONBLOCK)  # bash holds it open
                try:
                    os.write(answer, f"{code}\n".encode())
                finally:
                    os.close(answer)
        finally:
            if proc.poll() is None:
                proc.kill()
                proc.wait()
        out, err = (t.read_bytes().decode("utf-8", errors="replace") for t in terminal)
    return proc.returncode, out, err


def _next_request(path: Path, proc: subprocess.Popen[bytes], deadline: float) -> bytes | None:
    """The next request, read until the function closes the FIFO; None if bash ended first.
    (A FIFO opened for reading with no writer yet does not read as ended: it waits for one.)"""
    fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK)
    data = b""
    try:
        while True:
            if time.monotonic() > deadline:
                raise TimeoutError("bash did not finish in time")
            ready, _, _ = select.select([fd], [], [], 0.05)
            if not ready:
                if proc.poll() is not None:
                    return None
                continue
            chunk = os.read(fd, 65536)
            if not chunk:
                return data
            data += chunk
    finally:
        os.close(fd)
