"""The error hierarchy.

Every error a user can cause (a bad file, a bad config, a run that cannot be found, a score
that cannot be computed) is an :class:`ErtoolsError`. Its message is one line that says what is
wrong, where (file, topic, time) and, where possible, what to do. The CLI prints it on stderr
and exits with status 1; anything else escaping the library is a bug.

An error is *transient* when it says something about the machine or the moment, not about the
bytes read: a file missing for a moment (a USB key re-plugged), a permission, an I/O error, a
disk full, memory, a worker that died. The same input read again may succeed, so such a verdict
is never kept in a cache (:func:`transient_error`, :func:`watching`; docs/rescore.md).
"""

from __future__ import annotations

import contextlib
import sys
from collections.abc import Iterator
from contextvars import ContextVar
from pathlib import Path

# The transient errors made while a :func:`watching` block runs (None: none is watched)
_WATCHED: ContextVar[list[BaseException] | None] = ContextVar("ertools_transient", default=None)
# The longest path a message shows whole: a folder deeper than the system's path limit (4096
# bytes on Linux) would make a line thousands of characters long. A path has no spaces to
# wrap at: this one leaves room in the 200 characters of an error's first line.
MAX_SHOWN = 160


def shown(path: str | Path) -> str:
    """``path`` for a message: whole up to :data:`MAX_SHOWN` characters, else its start and
    end around "..." with its length said (about 120 characters)."""
    text = str(path)
    if len(text) <= MAX_SHOWN:
        return text
    return f"{text[:40]}...{text[-60:]} ({len(text)} characters)"


class ErtoolsError(Exception):
    """Root of every error ertools raises on purpose.

    ``transient``: the error is of the machine or the moment, not of the data (see the
    module's text); by default it is when it is made while an environmental error
    (:func:`environmental`) is being handled, as every ``except OSError`` that says it in
    ertools' own words does.
    """

    exit_code = 1

    def __init__(
        self, message: str, *, path: str | Path | None = None, transient: bool | None = None
    ) -> None:
        self.path = str(path) if path is not None else None
        self.message = message
        handled = sys.exc_info()[1]
        self.transient = transient if transient is not None else transient_error(handled)
        if self.transient:
            _note(self)
        super().__init__(f"{shown(self.path)}: {message}" if self.path else message)


class BagError(ErtoolsError):
    """A bag or MCAP file that is missing, unreadable, truncated or lacks what was asked."""


class TopicError(BagError):
    """A topic or tf frame that is not in the file, or has the wrong type."""


class ConfigError(ErtoolsError):
    """A YAML config or command-line value that is malformed or inconsistent."""


class SegmentationError(ErtoolsError):
    """Runs, segments or windows that cannot be found in the logs."""


class ScoringError(ErtoolsError):
    """A score that cannot be computed from the data found (too few samples, NaN poses...)."""


class ClockError(ErtoolsError):
    """Clocks that disagree more than allowed, or logs that do not overlap in time."""


class UsageError(ErtoolsError):
    """A command line that cannot be acted on; the CLI exits with status 2."""

    exit_code = 2


def environmental(err: BaseException) -> bool:
    """Whether ``err`` itself is of the machine or the moment: an operating system error
    (it carries an ``errno``: missing, permission, I/O, disk full, interrupted; or a time-out,
    a lost connection), memory, an interrupt, or sqlite's failures to open or read a file.
    An ``OSError`` without an ``errno`` is a library's verdict on bytes (``bz2``'s "Invalid
    data stream", gzip's bad header), not transient."""
    if isinstance(err, OSError):
        return err.errno is not None or isinstance(err, TimeoutError | ConnectionError)
    if isinstance(err, MemoryError | KeyboardInterrupt):
        return True
    kind = type(err)
    return kind.__module__ == "sqlite3" and kind.__name__ == "OperationalError"


def transient_error(err: BaseException | None) -> bool:
    """Whether ``err``, or an error it was raised from or while handling, is transient: an
    :class:`ErtoolsError` says so itself, any other error by :func:`environmental`."""
    seen: set[int] = set()
    while err is not None and id(err) not in seen:
        seen.add(id(err))
        if isinstance(err, ErtoolsError):
            if err.transient:
                return True
        elif environmental(err):
            return True
        err = err.__cause__ or err.__context__
    return False


def _note(err: BaseException) -> None:
    watched = _WATCHED.get()
    if watched is not None:
        watched.append(err)


def note_transient(err: BaseException) -> None:
    """Tell the :func:`watching` block that a transient error was met and handled (a file
    skipped for a moment's ``OSError``): what it computes depends on the moment."""
    if transient_error(err):
        _note(err)


@contextlib.contextmanager
def watching() -> Iterator[list[BaseException]]:
    """The transient errors made (or noted, :func:`note_transient`) in this thread while the
    block runs, raised or not: a result computed while one was met, even one handled quietly
    (a run skipped, a file left out), depends on the moment and is not to be cached."""
    watched: list[BaseException] = []
    token = _WATCHED.set(watched)
    try:
        yield watched
    finally:
        _WATCHED.reset(token)
