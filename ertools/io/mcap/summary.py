"""An MCAP file's summary section, read once per file and checked; chunk decompression; the
errors the ``mcap`` library raises on damaged files.

Both MCAP read paths stand on this module: the indexed one (:mod:`ertools.io.mcap.index`) and
the record-by-record one (:mod:`ertools.io.mcap.scan`).
"""

from __future__ import annotations

import os
import struct
from pathlib import Path
from typing import Any, BinaryIO

from ertools.caches import register
from ertools.errors import BagError
from ertools.io.inflate import inflate
from ertools.io.mcap.crc import crc32
from ertools.io.pipeline import pread


# What the mcap library raises on damaged or cut-short files.
def mcap_errors() -> tuple[type[BaseException], ...]:
    import zstandard  # lazy: zstandard, 6 ms
    from mcap.exceptions import McapError  # lazy: mcap, 20 ms

    # lz4 raises RuntimeError on corrupt chunks, zstandard its own ZstdError (found by
    # fuzzing: it escaped as a traceback); absurd record lengths can MemoryError.
    return (
        McapError,
        ValueError,
        EOFError,
        OSError,
        struct.error,
        KeyError,
        RuntimeError,
        MemoryError,
        OverflowError,  # a length near 2**64 handed to read() or a buffer
        zstandard.ZstdError,
    )


# Summaries parsed, by file identity: opening a file and planning a read need the same one.
_SUMMARIES: dict[tuple[int, int, int, int], Any] = {}
register(_SUMMARIES.clear)


def read_summary(f: BinaryIO, path: Path) -> Any:
    """The ``mcap`` library's Summary of an open MCAP file, None when it has none.

    Kept per file (device, inode, size, modification time), so a file changed since is read
    again; the Summary is shared, never modified.
    """
    st = os.fstat(f.fileno())
    key = (st.st_dev, st.st_ino, st.st_size, st.st_mtime_ns)
    if key in _SUMMARIES:
        return _SUMMARIES[key]
    summary = _parse_summary(f, path)
    if len(_SUMMARIES) >= 64:
        _SUMMARIES.clear()
    _SUMMARIES[key] = summary
    return summary


def _parse_summary(f: BinaryIO, path: Path) -> Any:
    from mcap.reader import make_reader  # lazy: mcap, 90 ms

    try:
        f.seek(0)
        summary = make_reader(f).get_summary()
    except mcap_errors() as err:
        raise BagError(f"unreadable MCAP summary ({type(err).__name__}: {err})", path=path) from err
    if summary is None:
        return None
    _check_summary_crc(f, path)
    stats = summary.statistics
    if (
        stats is not None
        and summary.chunk_indexes
        and stats.chunk_count != len(summary.chunk_indexes)
    ):
        # a chunk index record lost to damage (the mcap library skips a record whose op code
        # it does not know): reading through the others would silently skip a chunk
        raise BagError(
            f"damaged MCAP summary: statistics count {stats.chunk_count} chunks, the chunk "
            f"indexes {len(summary.chunk_indexes)}",
            path=path,
        )
    return summary


def _check_summary_crc(f: BinaryIO, path: Path) -> None:
    """Refuse a summary section that fails the CRC its footer gives (0: not computed).

    The ``mcap`` library does not check it; a damaged summary (a chunk index's op code,
    offsets or times, a channel's schema id) would otherwise direct every indexed read. The
    section is what the library has just read, a small part of the file.
    """
    size = file_size(f)
    at = size - 8 - (1 + 8 + 8 + 8 + 4)
    footer = pread(f.fileno(), 1 + 8 + 8 + 8 + 4, at)
    if len(footer) < 29 or footer[0] != 0x02:
        return  # no footer here: the library found none either
    _, _len, start, _offsets, crc = struct.unpack("<BQQQI", footer)
    if not crc or not 0 < start < at:
        return
    # from the first summary record through the footer's summary_offset_start field
    covered = pread(f.fileno(), at + 1 + 8 + 8 + 8 - start, start)
    if crc32(covered) != crc:
        raise BagError("damaged MCAP summary section: it fails its CRC check", path=path)


def decompress(compression: str, data: Any, size: int, where: str) -> Any:
    """Uncompressed MCAP chunk records: exactly ``size`` bytes, within the budget
    (:func:`ertools.io.inflate.inflate`)."""
    return inflate(compression, data, size, where, "MCAP chunk")


def file_size(f: BinaryIO) -> int:
    return os.fstat(f.fileno()).st_size
