"""Opening what a user gives: regular files only, and paths short enough to print.

A named pipe where a bag or config should be blocks ``open()`` until a writer comes (for
ever), and a device or socket is no input either: every input file ertools opens goes through
:func:`open_regular`, which checks the file's type before opening it and again on the open
file (opened without blocking, so a pipe swapped in between cannot hang it). The refusal is an
``OSError`` (:class:`NotRegularFileError`): callers turn it into their one-line error as they do a
missing or unreadable file.

(Paths in messages are shortened by :func:`ertools.errors.shown`.)
"""

from __future__ import annotations

import errno
import os
import stat
from io import BufferedReader

StrPath = str | os.PathLike[str]

_KINDS = (
    (stat.S_ISFIFO, "a FIFO"),
    (stat.S_ISSOCK, "a socket"),
    (stat.S_ISCHR, "a character device"),
    (stat.S_ISBLK, "a block device"),
    (stat.S_ISDIR, "a folder"),
)


class NotRegularFileError(OSError):
    """An input path that exists but is no regular file (a pipe, socket, device, folder)."""

    def __init__(self, path: StrPath, kind: str) -> None:
        super().__init__(errno.EINVAL, f"not a regular file ({kind})", os.fspath(path))
        self.kind = kind


def kind_of(mode: int) -> str:
    """What a file of ``mode`` is, in words ("a FIFO"); "" for a regular file."""
    if stat.S_ISREG(mode):
        return ""
    return next((name for test, name in _KINDS if test(mode)), "a special file")


def check_regular(path: StrPath) -> os.stat_result:
    """The ``stat`` of ``path`` (symbolic links followed) when it is a regular file.

    Raises:
        NotRegularFileError: it exists and is something else.
        OSError: it cannot be looked at (missing, no permission, path too long...).
    """
    st = os.stat(path)
    kind = kind_of(st.st_mode)
    if kind:
        raise NotRegularFileError(path, kind)
    return st


_FLAGS = (
    os.O_RDONLY
    | getattr(os, "O_NONBLOCK", 0)
    | getattr(os, "O_NOCTTY", 0)
    | getattr(os, "O_CLOEXEC", 0)
    | getattr(os, "O_BINARY", 0)
)


def open_regular(path: StrPath) -> BufferedReader:
    """``path`` opened for reading in binary, when it is a regular file.

    Checked before the open (opening a device can do things) and on the open file (a pipe
    swapped in between is opened without blocking and refused). Reads of a regular file are
    unaffected by the non-blocking flag.

    Raises:
        NotRegularFileError: not a regular file.
        OSError: it cannot be opened.
    """
    check_regular(path)
    fd = os.open(path, _FLAGS)
    try:
        kind = kind_of(os.fstat(fd).st_mode)
        if kind:
            raise NotRegularFileError(path, kind)
        return os.fdopen(fd, "rb")
    except BaseException:
        os.close(fd)
        raise


def read_regular(path: StrPath, limit: int | None = None) -> bytes:
    """The bytes of a regular file (at most ``limit`` + 1 of them: a caller with a limit sees
    that the file is longer without reading it all).

    Raises:
        NotRegularFileError, OSError: as :func:`open_regular`.
    """
    with open_regular(path) as f:
        return f.read() if limit is None else f.read(limit + 1)


def read_regular_text(path: StrPath, encoding: str = "utf-8") -> str:
    """The text of a regular file (universal newlines, as ``Path.read_text``).

    Raises:
        NotRegularFileError, OSError: as :func:`open_regular`; UnicodeDecodeError.
    """
    text = read_regular(path).decode(encoding)
    return text.replace("\r\n", "\n").replace("\r", "\n")


def why_not(err: OSError) -> str:
    """An ``OSError`` on an input as a few words ("permission denied")."""
    if isinstance(err, NotRegularFileError):
        return str(err.strerror)
    if err.errno == errno.ENAMETOOLONG:
        return "path longer than the system allows"
    if err.errno == errno.ENOENT:
        return "no such file or directory"
    return (err.strerror or type(err).__name__).lower()
