"""Per-process memories of what was read from files (MCAP summaries, scans and layouts), each
kept by the file's identity (device, inode, size, modification time) so that one command does
not parse a file twice.

A process that runs many commands (a notebook, a test suite running the CLI in-process) may
empty them all with :func:`clear`, to see each file as a new process would.
"""

from __future__ import annotations

from collections.abc import Callable

_CLEARERS: list[Callable[[], None]] = []


def register(clear: Callable[[], None]) -> None:
    """``clear`` empties one module's memory when :func:`clear` is called."""
    _CLEARERS.append(clear)


def clear() -> None:
    """Empty every memory registered (by the modules imported so far)."""
    for forget in _CLEARERS:
        forget()
