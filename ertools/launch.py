"""Programs started from a shell: the ``ertools`` command (ertools/__main__.py) and the
``python -m ertools...`` modules, each a function run by :func:`run`.

A Ctrl-C lands wherever the program is, often in its first moments, while NumPy or a command's
modules are imported: Python's answer is a traceback of its import machinery, 30 to 70 lines.
Here it is one line, ``PROGRAM: interrupted``, and exit status 130 (128 + SIGINT, what a shell
shows for a program a Ctrl-C ended). The program's modules are imported by the function that
:func:`run` calls (a plain import inside it), so that an interrupt during the imports is caught
too; only Python's own start-up and this light module come before. A second Ctrl-C while the
first is being answered (workers closed, files removed) ends the process at once, without a
word.
"""

from __future__ import annotations

import _thread
import os
import signal
import sys
import threading
import time
from collections.abc import Callable
from types import FrameType
from typing import Any

INTERRUPTED = 130  # 128 + SIGINT

# Set by the first Ctrl-C: an extension module interrupted while it loads (NumPy's C core) may
# turn the KeyboardInterrupt into an ImportError of its own, with its advice on reinstalling.
_received = threading.Event()
# Set when a KeyboardInterrupt was swallowed (raised inside a callback Python cannot raise from)
# and is being delivered again.
_again = threading.Event()


def _on_interrupt(signum: int, frame: FrameType | None) -> None:
    if _again.is_set():
        if _delivering.locked():  # still inside the hook below: later
            _deliver_later()
            return
        _again.clear()
        raise KeyboardInterrupt
    if _received.is_set():
        # a second Ctrl-C while the first is answered: the operating system's default, at once
        signal.signal(signal.SIGINT, signal.SIG_DFL)
        os.kill(os.getpid(), signal.SIGINT)
        return
    _received.set()
    raise KeyboardInterrupt


# Held while the hook below runs (always in the main thread, where signal handlers run).
_delivering = threading.Lock()


def _deliver_later() -> None:
    def deliver() -> None:
        time.sleep(0.001)  # the main thread leaves the callback meanwhile, most often
        _thread.interrupt_main(signal.SIGINT)

    # a bare thread: threading.Thread.start() waits for it, and the handler would run there
    _thread.start_new_thread(deliver, ())


def _unraisable(hook: Callable[[Any], object]) -> Callable[[Any], object]:
    """``sys.unraisablehook`` that delivers again a Ctrl-C that landed where an exception
    cannot propagate (a weakref callback of the import machinery, a ``__del__``): Python would
    print "Exception ignored in" with a traceback and carry on as if no key had been pressed.
    One that lands in a callback again comes back here, until it reaches code that can raise.
    """

    def deliver_again(unraisable: Any) -> object:
        if not isinstance(unraisable.exc_value, KeyboardInterrupt):
            return hook(unraisable)
        with _delivering:
            _again.set()
            _deliver_later()
        return None

    return deliver_again


def _caused_by_interrupt(err: BaseException) -> bool:
    """Whether ``err`` came of a Ctrl-C: one was received, or one is in its chain."""
    if _received.is_set():
        return True
    seen: set[int] = set()
    cause: BaseException | None = err
    while cause is not None and id(cause) not in seen:
        if isinstance(cause, KeyboardInterrupt):
            return True
        seen.add(id(cause))
        cause = cause.__cause__ or cause.__context__
    return False


def interrupted(program: str) -> int:
    """Say that ``program`` was interrupted (one line on stderr); the exit status to give."""
    if threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGINT, signal.SIG_DFL)
    try:
        sys.stderr.write(f"{program}: interrupted\n")
        sys.stderr.flush()
    except (OSError, ValueError):  # stderr closed: the status says it
        pass
    return INTERRUPTED


def run(start: Callable[[], object], program: str) -> int:
    """Call ``start``, which imports the program's modules and runs it (it reads
    ``sys.argv``); its exit status, or :data:`INTERRUPTED` after one line when a Ctrl-C came at
    any moment, imports included."""
    hook = sys.unraisablehook
    try:
        if threading.current_thread() is threading.main_thread():
            signal.signal(signal.SIGINT, _on_interrupt)
            sys.unraisablehook = _unraisable(hook)
        code = start()
    except KeyboardInterrupt:
        return interrupted(program)
    except Exception as err:  # an ImportError of NumPy's, say, made of the interrupt
        if _caused_by_interrupt(err):
            return interrupted(program)
        raise
    finally:
        sys.unraisablehook = hook
    if threading.current_thread() is threading.main_thread():
        # done: a Ctrl-C while Python exits (its atexit work) ends it at once, no traceback
        signal.signal(signal.SIGINT, signal.SIG_DFL)
    return code if isinstance(code, int) else 0 if code is None else 1
