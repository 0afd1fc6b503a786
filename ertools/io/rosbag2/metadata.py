"""rosbag2 directories: ``metadata.yaml`` (the summary), their storage files as readable files
(:func:`readable_files`, the one place that decides it for every command) and bulk row access
to sqlite3 storage (:mod:`ertools.io.rosbag2.sqlite_storage`, imported only for it)."""

from __future__ import annotations

import atexit
from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import Any

from ertools.arrays import I64, U8
from ertools.errors import BagError
from ertools.inputs import open_regular, why_not
from ertools.io.formats import load_metadata, metadata_errors, metadata_problem
from ertools.io.inflate import inflate_file
from ertools.io.model import Conn


def read_metadata(path: Path) -> dict[str, Any]:
    """``rosbag2_bagfile_information`` of a rosbag2 directory."""

    try:
        data = load_metadata(path)
        info = data["rosbag2_bagfile_information"]
    except OSError as err:
        raise BagError(f"unreadable metadata.yaml ({why_not(err)})", path=path) from err
    except metadata_errors() as err:
        raise BagError(f"unreadable metadata.yaml ({metadata_problem(err)})", path=path) from err
    if not isinstance(info, dict):
        raise BagError("metadata.yaml has no rosbag2_bagfile_information", path=path)
    return info


def storage_files(path: Path, info: dict[str, Any]) -> list[Path]:
    """The storage files the metadata lists (relative to the directory)."""
    rel = info.get("relative_file_paths") or [f["path"] for f in info.get("files", [])]
    return [path / str(r) for r in rel]


# Decompressed copies of file-compressed storage, per process: (file, size, mtime) -> copy.
_DECOMPRESSED: dict[tuple[str, int, int], Path] = {}
_SCRATCH: list[Path] = []


def _scratch() -> Path:
    if not _SCRATCH:
        import shutil  # lazy: shutil pulls bz2, lzma (2 ms), only for a file-compressed bag
        import tempfile  # lazy: tempfile pulls random (1.5 ms), only for this

        folder = Path(tempfile.mkdtemp(prefix="ertools-rosbag2-"))
        atexit.register(shutil.rmtree, folder, True)
        _SCRATCH.append(folder)
    return _SCRATCH[0]


def file_compression(info: dict[str, Any]) -> str | None:
    """The compression of the storage files as whole files (``compression_mode: file``, as
    ``ros2 bag record --compression-mode file`` and ``rosbags-convert --compress-mode file``
    write), None when the files are stored as they are (or compressed message by message)."""
    mode = str(info.get("compression_mode") or "").lower()
    fmt = str(info.get("compression_format") or "").lower()
    return fmt if mode == "file" and fmt else None


def message_compression(info: dict[str, Any]) -> str | None:
    """The compression of each message (``compression_mode: message``), None when messages
    are stored as they are (or the files are compressed whole)."""
    mode = str(info.get("compression_mode") or "").lower()
    fmt = str(info.get("compression_format") or "").lower()
    return fmt if mode == "message" and fmt else None


def readable_files(path: Path, info: dict[str, Any] | None = None) -> list[Path]:
    """The storage files of a rosbag2 directory as files a reader can open: those listed, or
    for a bag compressed file by file, their decompressed copies in a temporary folder of
    this process (removed at exit; the bag itself is never touched).

    Every reader of a rosbag2 directory (summary, info, score, export, timeline) takes its
    files from here, so they all read the same bags.

    Raises:
        BagError: an unsupported file compression, or a compressed file that does not
            decompress.
    """
    info = read_metadata(path) if info is None else info
    files = storage_files(path, info)
    comp = file_compression(info)
    if comp is None:
        return files
    if comp != "zstd":
        raise BagError(
            f"unsupported rosbag2 file compression {comp!r} (rosbag2 writes zstd)", path=path
        )
    return [_decompressed(f) for f in files]


def readable_dir(path: Path) -> Path:
    """The rosbag2 directory as a reader that opens a whole directory (rosbags) should see it:
    ``path`` itself, or for a compressed bag a directory of this process's temporary folder
    holding links to :func:`readable_files` (the copies of files compressed whole) and the
    metadata without the compression: the caller decompresses messages compressed one by one
    (:func:`message_compression`) itself, within the budget. A file's decompression is that
    of :func:`readable_files`, done once."""
    info = read_metadata(path)
    if file_compression(info) is None and message_compression(info) is None:
        return path
    files = readable_files(path, info)
    key = (f"dir:{path.resolve()}", len(files), 0)
    done = _DECOMPRESSED.get(key)
    if done is not None and done.exists():
        return done
    out = _scratch() / f"bag{len(_DECOMPRESSED)}"
    out.mkdir(parents=True, exist_ok=True)
    for f in files:
        (out / f.name).symlink_to(f.resolve())
    plain = dict(info, compression_format="", compression_mode="")
    plain["relative_file_paths"] = [f.name for f in files]
    listed = info.get("files")
    if isinstance(listed, list) and len(listed) == len(files):
        plain["files"] = [dict(e, path=f.name) for e, f in zip(listed, files, strict=True)]
    import yaml  # lazy: PyYAML, 10-20 ms, only for a compressed rosbag2 folder

    text = yaml.safe_dump({"rosbag2_bagfile_information": plain}, sort_keys=False)
    (out / "metadata.yaml").write_text(text, encoding="utf-8")
    _DECOMPRESSED[key] = out
    return out


def _decompressed(file: Path) -> Path:
    try:
        st = file.stat()
    except OSError as err:
        raise BagError(f"cannot read storage file: {err.strerror}", path=file) from err
    key = (str(file.resolve()), st.st_size, st.st_mtime_ns)
    done = _DECOMPRESSED.get(key)
    if done is not None and done.exists():
        return done
    name = file.name[: -len(".zstd")] if file.name.endswith(".zstd") else file.name
    out = _scratch() / str(len(_DECOMPRESSED)) / name
    out.parent.mkdir(parents=True, exist_ok=True)
    try:
        with open_regular(file) as src, out.open("wb") as dst:
            inflate_file("zstd", src, dst, st.st_size, "")
    except OSError as err:
        out.unlink(missing_ok=True)
        raise BagError(f"cannot read storage file: {why_not(err)}", path=file) from err
    except BagError as err:
        out.unlink(missing_ok=True)
        raise BagError(err.message, path=file) from err
    _DECOMPRESSED[key] = out
    return out


def sqlite_rows(
    path: Path, conns: Sequence[Conn], lo: int | None, hi: int | None
) -> Iterator[tuple[U8, I64, I64, I64]] | None:
    """Batches of (bytes, data starts, data lengths, timestamps) ordered by time, or None
    when the bag is compressed (then rosbags reads it)."""
    info = read_metadata(path)
    if (info.get("compression_format") or info.get("compression_mode")) and (
        file_compression(info) is None
    ):
        return None  # compressed message by message: rosbags decompresses each
    files = [f for f in readable_files(path, info) if f.suffix == ".db3"]
    topics = sorted({c.topic for c in conns})
    from ertools.io.rosbag2.sqlite_storage import topic_rows  # lazy: sqlite3 1.5 ms, .db3 only

    return topic_rows(files, topics, lo, hi)
