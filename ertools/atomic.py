"""Files written whole or not at all, and folders written by one process at a time.

A laptop closed, a process killed or a disk filled while a page or ``results.json`` is written
must leave the previous file, never a half-written one: every output goes to a temporary of a
unique name in the same folder (the rename must not cross file systems), is flushed to disk and
then renamed over the target, which POSIX makes atomic. Two processes writing the same file
each have their own temporary; the last rename wins with a whole file.
"""

from __future__ import annotations

import contextlib
import os
import shutil
import sys
import tempfile
from collections.abc import Callable, Iterator
from functools import cache
from pathlib import Path

if sys.platform != "win32":
    import fcntl


_FOLDER_TRIES = 10  # replace_folder: runs racing for one folder, at most


@cache
def _umask() -> int:
    # the mode a plain open() would give: mkstemp makes 0600 files, fine for secrets, not pages
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def _fsync_folder(folder: Path) -> None:
    # the rename itself is durable only once the folder is (POSIX); not possible everywhere
    with contextlib.suppress(OSError, AttributeError):
        fd = os.open(folder, os.O_RDONLY)
        try:
            os.fsync(fd)
        finally:
            os.close(fd)


def _named(err: OSError, path: Path) -> OSError:
    """``err`` naming ``path`` where it names no file (a full disk: ``write`` says none) or
    the temporary (a read-only folder: ``mkstemp`` names it): the user asked for ``path``."""
    name = None if err.filename is None else Path(os.fsdecode(err.filename)).name
    if name is not None and not name.startswith(f".{path.name}."):
        return err  # another file, named already
    try:
        return type(err)(err.errno, err.strerror or str(err), str(path))
    except TypeError:  # a subclass with its own arguments
        return OSError(err.errno, err.strerror or str(err), str(path))


@contextlib.contextmanager
def replacing(path: Path) -> Iterator[Path]:
    """A temporary path beside ``path`` (same suffix, for writers that read it) to write in;
    renamed over ``path`` once the block ends without an error, removed otherwise. An error
    of the temporary's is raised naming ``path``."""
    path = Path(path)
    try:
        fd, name = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=path.suffix)
    except OSError as err:
        raise _named(err, path) from err
    os.close(fd)
    tmp = Path(name)
    try:
        yield tmp
        with open(tmp, "rb+") as fh:
            os.fsync(fh.fileno())
        os.chmod(tmp, 0o666 & ~_umask())
        os.replace(tmp, path)
    except BaseException as err:
        with contextlib.suppress(OSError):
            tmp.unlink()
        if isinstance(err, OSError):
            raise _named(err, path) from err
        raise
    _fsync_folder(path.parent)


def write_bytes(path: Path, data: bytes) -> Path:
    """``data`` into ``path``, whole or not at all (a pipe or a device, ``-o /dev/stdout``,
    is written as it is: it cannot be replaced)."""
    path = Path(path)
    if path.exists() and not path.is_file():
        try:
            with open(path, "wb") as fh:
                fh.write(data)
        except OSError as err:  # a full device: the write names no file
            raise _named(err, path) from err
        return path
    with replacing(path) as tmp:
        tmp.write_bytes(data)
    return path


def write_text(path: Path, text: str) -> Path:
    """``text`` (UTF-8) into ``path``, whole or not at all."""
    return write_bytes(path, text.encode("utf-8"))


def replace_folder(new: Path, path: Path) -> None:
    """The folder ``new`` (built whole beside ``path``, by ``tempfile.mkdtemp``) put at
    ``path``: what was there is renamed away first, under a unique name, and removed after.
    Two runs doing it at once each end with a whole folder there (the last one's)."""
    for _ in range(_FOLDER_TRIES):
        old: Path | None = None
        if path.is_symlink():
            path.unlink()
        elif path.exists():
            old = Path(tempfile.mkdtemp(dir=path.parent, prefix=f".{path.name}.", suffix=".old"))
            # over an empty folder (POSIX allows it); gone already: another run moved it
            with contextlib.suppress(FileNotFoundError):
                os.replace(path, old)
        try:
            os.replace(new, path)
        except OSError:  # another run put its folder there meanwhile: move it away too
            continue
        finally:
            if old is not None:
                shutil.rmtree(old, ignore_errors=True)
        return
    raise FileExistsError(f"{path}: replaced by other runs {_FOLDER_TRIES} times; not written")


@contextlib.contextmanager
def folder_lock(folder: Path, *, on_wait: Callable[[str], None] | None = None) -> Iterator[None]:
    """Hold ``folder/.ertools.lock`` (an advisory ``flock``) for the block.

    When another process holds it, ``on_wait`` is told who (the holder's pid, as it wrote it)
    and the call waits for it to end. The lock goes with its
    holder's process, however that ends: a killed run leaves no stale lock. Where there is no
    ``flock`` (Windows) the block runs unlocked.
    """
    if sys.platform == "win32":  # pragma: no cover - not on the platforms tested
        yield
        return
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / ".ertools.lock"
    fd = os.open(path, os.O_RDWR | os.O_CREAT, 0o666 & ~_umask())
    try:
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            holder = os.pread(fd, 64, 0).decode("ascii", "replace").strip() or "unknown"
            if on_wait is not None:
                on_wait(holder)
            fcntl.flock(fd, fcntl.LOCK_EX)
        os.ftruncate(fd, 0)
        os.pwrite(fd, f"{os.getpid()}\n".encode("ascii"), 0)
        yield
    finally:
        os.close(fd)  # releases the lock


def hold(fd: int) -> bool:
    """Take the advisory lock (``flock``) of the open file ``fd`` for as long as it stays open,
    without waiting: False when another open of it holds it (a recording being written). Where
    there is no ``flock`` (Windows), True."""
    if sys.platform == "win32":  # pragma: no cover - not on the platforms tested
        return True
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except BlockingIOError:
        return False
    return True
