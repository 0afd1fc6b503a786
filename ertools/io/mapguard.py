"""A file cut short while it is mapped: one error line and exit status 1, not a crash.

Reading through a map is reading the page cache in place, but when the file is truncated
while mapped (``cp other.bag`` over it truncates first; a sync, a full disk's cleanup), the
kernel answers a read of a lost page with SIGBUS, which Python cannot raise as an exception:
the process dies ("Bus error"), or prints a traceback of every thread when ``faulthandler``
is on. While a map made by :func:`watch` is alive, a SIGBUS handler installed through the C
library (``ctypes``, which NumPy imports anyway) writes one ``ertools: error:`` line naming the
mapped files and ends the process with status 1. A SIGBUS with no watched map alive is handed
back to the handler there was before (restored, and the faulting read repeats into it).

Linux only (the one system whose ``struct sigaction`` layout is fixed here); elsewhere
:data:`ACTIVE` is False and the caller reads with copies instead of maps where it can.
"""

from __future__ import annotations

import ctypes
import os
import signal
import sys
import threading
from typing import Any

from ertools.errors import shown

# glibc and musl on x86_64 and aarch64: handler (8 bytes), mask (128), flags (4 + 4 padding),
# restorer (8): 152 bytes. A buffer of 256 holds it; zero mask and flags ask for a plain
# one-argument handler, run with SIGBUS blocked.
_SIGACTION_BYTES = 256
ACTIVE = sys.platform.startswith("linux") and ctypes.sizeof(ctypes.c_void_p) == 8

_LOCK = threading.Lock()
_LIVE: dict[int, str] = {}  # id of a watched map -> its file, as messages show it
_state: dict[str, Any] = {}  # the installed handler and the disposition it replaced


def _message() -> bytes:
    files = ", ".join(dict.fromkeys(_LIVE.values())) or "a mapped file"
    return (
        f"ertools: error: {files}: the file changed while it was read (cut short: copied "
        "over, truncated or still being written?); read it again once it is complete\n"
    ).encode("utf-8", "replace")


def _on_sigbus(_signum: int) -> None:
    if not _LIVE:
        # not one of ours: the handler there was before takes it, raised again (blocked
        # until this handler returns; a faulting read would also fault again)
        libc = _state["libc"]
        libc.sigaction(signal.SIGBUS, _state["old"], None)
        _state["installed"] = False
        getattr(libc, "raise")(signal.SIGBUS)
        return
    os.write(2, _message())
    os._exit(1)


def _install() -> None:
    """The handler, installed once per process (the first time a file is mapped)."""
    if _state.get("installed") or not ACTIVE:
        return
    if "handler" not in _state:
        libc = ctypes.CDLL(None, use_errno=True)
        libc.sigaction.argtypes = [ctypes.c_int, ctypes.c_void_p, ctypes.c_void_p]
        libc.sigaction.restype = ctypes.c_int
        # kept for the life of the process: the C library may call it at any time
        handler = ctypes.CFUNCTYPE(None, ctypes.c_int)(_on_sigbus)
        new = ctypes.create_string_buffer(_SIGACTION_BYTES)
        ctypes.c_void_p.from_buffer(new).value = ctypes.cast(handler, ctypes.c_void_p).value
        _state.update(libc=libc, handler=handler, new=new)
    old = ctypes.create_string_buffer(_SIGACTION_BYTES)
    if _state["libc"].sigaction(signal.SIGBUS, _state["new"], old) != 0:
        return  # no handler: a cut file crashes as it did before
    _state.update(old=old, installed=True)


def watch(mapping: object, path: object) -> None:
    """``mapping`` (a map of ``path``) is alive: a SIGBUS now is this file's."""
    with _LOCK:
        _install()
        _LIVE[id(mapping)] = shown(str(path))


def unwatch(mapping: object) -> None:
    """``mapping`` is closed (no read through it can fault any more)."""
    with _LOCK:
        _LIVE.pop(id(mapping), None)


def watched() -> list[str]:
    """The files of the maps alive now (for tests)."""
    with _LOCK:
        return list(_LIVE.values())
