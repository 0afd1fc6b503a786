"""``ertools ARGS`` run inside the test process: what a command prints and its exit status,
without a new interpreter's start-up (Python, NumPy and the command's modules: 0.4 s a command
on an idle machine, seconds on a loaded one).

For tests about a command's output. Tests about the process itself (the console script's exit
status, a closed pipe, a kill, locks between two commands, a child's death signal) start a real
one. Each call is as a fresh process would see it: its own working folder and environment,
stdin, stdout and stderr (not terminals: no progress bar), the ``ertools`` logger and the
warning filters of a new interpreter, and the per-process caches of file reads emptied
(:func:`ertools.caches.clear`); all of it is put back afterwards, so nothing leaks from one
call into the next or into the test.
"""

from __future__ import annotations

import contextlib
import io
import logging
import os
import sys
import warnings
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TextIO

from ertools.caches import clear as clear_caches
from ertools.cli.main import main


@dataclass(frozen=True)
class Ran:
    """A command's exit status and output (``stderr`` is ``""`` when merged into stdout)."""

    code: int
    stdout: str
    stderr: str


@contextlib.contextmanager
def _environment(env: Mapping[str, str] | None) -> Iterator[None]:
    if env is None:
        yield
        return
    saved = dict(os.environ)
    os.environ.clear()
    os.environ.update(env)
    try:
        yield
    finally:
        os.environ.clear()
        os.environ.update(saved)


@contextlib.contextmanager
def _folder(cwd: Path | str | None) -> Iterator[None]:
    before = os.getcwd()
    if cwd is not None:
        os.chdir(cwd)
    try:
        yield
    finally:
        os.chdir(before)


@contextlib.contextmanager
def _logger() -> Iterator[None]:
    """The ``ertools`` logger as it was: the command installs its own handler (on the stream
    it was given) and level."""
    logger = logging.getLogger("ertools")
    handlers, level, propagate = logger.handlers[:], logger.level, logger.propagate
    try:
        yield
    finally:
        logger.handlers[:] = handlers
        logger.setLevel(level)
        logger.propagate = propagate


def _show(
    message: Warning | str,
    category: type[Warning],
    filename: str,
    lineno: int,
    file: object = None,
    line: str | None = None,
) -> None:
    sys.stderr.write(warnings.formatwarning(message, category, filename, lineno, line))


@contextlib.contextmanager
def _fresh_warnings() -> Iterator[None]:
    """A new interpreter's warning filters, printed on the command's stderr (pytest's own
    capture of warnings would otherwise swallow them); the "once per place" memory is
    forgotten, as a new process has none."""
    with warnings.catch_warnings():
        warnings.resetwarnings()  # also forgets which warnings were shown already
        warnings.simplefilter("default")
        for category in (DeprecationWarning, PendingDeprecationWarning, ImportWarning):
            warnings.filterwarnings("ignore", category=category)
        warnings.filterwarnings("default", category=DeprecationWarning, module="__main__")
        warnings.showwarning = _show
        yield


def run(
    argv: Sequence[str | os.PathLike[str]],
    *,
    cwd: Path | str | None = None,
    env: Mapping[str, str] | None = None,
    stdin: str = "",
    merge: bool = False,
    stdout: TextIO | None = None,
    stderr: TextIO | None = None,
) -> Ran:
    """``ertools *argv`` in this process. ``env`` replaces the environment for the call (None:
    this one's); ``merge`` interleaves stderr into stdout as a terminal shows both; ``stdout``
    and ``stderr``, when given, are written to instead of being captured (``Ran`` then holds
    ``""`` for them)."""
    out = stdout if stdout is not None else io.StringIO()
    err = out if merge else stderr if stderr is not None else io.StringIO()
    with contextlib.ExitStack() as stack:
        stack.enter_context(_environment(env))
        stack.enter_context(_folder(cwd))
        stack.enter_context(_logger())
        stack.enter_context(_fresh_warnings())
        stack.enter_context(contextlib.redirect_stdout(out))
        stack.enter_context(contextlib.redirect_stderr(err))
        saved_stdin = sys.stdin
        sys.stdin = io.StringIO(stdin)
        stack.callback(setattr, sys, "stdin", saved_stdin)
        clear_caches()
        stack.callback(clear_caches)
        try:
            code = main([os.fspath(a) for a in argv])
        except SystemExit as stop:  # as the process would end
            code = stop.code if isinstance(stop.code, int) else 0 if stop.code is None else 1
    return Ran(code, _text(out, stdout), "" if merge else _text(err, stderr))


def _text(stream: TextIO, given: TextIO | None) -> str:
    return stream.getvalue() if given is None and isinstance(stream, io.StringIO) else ""
