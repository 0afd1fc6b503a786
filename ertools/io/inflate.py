"""Every decompression of ertools: bz2, lz4 and zstd, for ROS1 chunks, MCAP chunks and
rosbag2 storage compressed file by file, through one bounded function.

A chunk says how large it is uncompressed; that size is checked against the budget
(:data:`ertools.io.budget.MAX_CHUNK_BYTES`) before anything is decompressed, the output goes
into a buffer of exactly that size, and the decompressor is stepped so it never produces more:
a stream that would inflate past its declared size is damage, found after at most one byte
too many (a bz2 stream a few hundred bytes long may hold gigabytes of zeros).
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from typing import Any, BinaryIO, Protocol, TypeVar

from ertools.errors import BagError
from ertools.io import budget

# Uncompressed bytes asked of a bz2 or lz4 decompressor at a time (its output is then copied
# into place): the transient copy stays small whatever the chunk's size.
STEP = 4 * budget.MiB

STORED = ("", "none")

T = TypeVar("T")


class _Stepper(Protocol):
    """What the bz2 and lz4 frame decompressors share."""

    eof: bool
    unused_data: bytes
    needs_input: bool

    def decompress(self, data: bytes, max_length: int = -1) -> bytes: ...


def check_declared(size: int, where: str, what: str = "chunk") -> None:
    """Refuse a declared uncompressed size over :data:`~ertools.io.budget.MAX_CHUNK_BYTES`."""
    if size > budget.MAX_CHUNK_BYTES:
        raise BagError(
            budget.over_budget(
                f"{what} {where}",
                f"{size} bytes uncompressed",
                budget.MAX_CHUNK_BYTES,
                "MAX_CHUNK_BYTES",
            )
        )


def inflate(compression: str, data: Any, size: int, where: str, what: str = "chunk") -> Any:
    """The ``size`` uncompressed bytes of ``data`` (bytes-like; stored data as it is).

    Raises:
        BagError: ``size`` over the budget, data that inflates to more or fewer bytes than
            ``size``, corrupt data, or an unknown compression.
    """
    if compression in STORED:
        return data
    check_declared(size, where, what)
    if compression == "zstd":
        out = bytearray(size)
        inflate_into(compression, data, memoryview(out), where, what)
        return out
    pieces = list(_checked(compression, data, size, where, what))
    # one piece (a chunk of up to STEP bytes) is returned as it is, without a copy
    return b"".join(pieces)


def inflate_message(compression: str, data: bytes, where: str) -> Any:
    """One message of a rosbag2 bag compressed message by message: a zstd frame, whose header
    states its size (rosbag2 writes it; a frame without one is refused, as rosbags does).

    Raises:
        BagError: as :func:`inflate`.
    """
    if compression != "zstd":
        raise BagError(f"unsupported message compression {compression!r} {where}")
    import zstandard  # lazy: zstandard, 6 ms

    try:
        size = zstandard.frame_content_size(data)
    except zstandard.ZstdError as err:
        raise BagError(f"corrupt zstd message {where} ({err})") from err
    if size < 0:
        raise BagError(f"damaged zstd message {where}: its frame states no size")
    return inflate(compression, data, size, where, "message")


def inflate_into(
    compression: str, data: Any, out: memoryview, where: str, what: str = "chunk"
) -> None:
    """Decompress ``data`` into ``out``, which is exactly its declared uncompressed size.

    Raises:
        BagError: as :func:`inflate`.
    """
    size = len(out)
    check_declared(size, where, what)
    if compression == "zstd":
        got, more = _guarded(compression, where, what, lambda: _zstd(data, out))
        _verdict(compression, got, more, size, where, what)
        return
    got = 0
    for piece in _checked(compression, data, size, where, what):
        out[got : got + len(piece)] = piece
        got += len(piece)


def _checked(compression: str, data: Any, size: int, where: str, what: str) -> Iterator[bytes]:
    """The pieces of a bz2 or lz4 stream, exactly ``size`` bytes in all (or a BagError)."""
    if compression == "bz2":
        import bz2  # lazy: bz2, 1 ms, only for a bz2-compressed chunk

        make: Any = bz2.BZ2Decompressor
    elif compression == "lz4":
        import lz4.frame  # lazy: lz4, 7 ms

        make = lz4.frame.LZ4FrameDecompressor
    else:
        raise BagError(f"unsupported {what} compression {compression!r} {where}")
    steps = _stepped(make, data, size)
    got = 0
    while True:
        piece = _guarded(compression, where, what, lambda: next(steps, None))
        if piece is None:
            break
        if got + len(piece) > size:
            _verdict(compression, got, True, size, where, what)
        got += len(piece)
        yield piece
    _verdict(compression, got, False, size, where, what)


def _guarded(compression: str, where: str, what: str, step: Callable[[], T]) -> T:
    try:
        return step()
    except BagError:
        raise
    except Exception as err:
        # bz2 raises OSError, lz4 RuntimeError, zstandard its own ZstdError on corrupt input
        raise BagError(f"corrupt {compression} {what} {where} ({err})") from err


def _verdict(compression: str, got: int, more: bool, size: int, where: str, what: str) -> None:
    if more:
        raise BagError(
            f"damaged {compression} {what} {where}: it inflates to more than the {size} bytes "
            "its header declares (decompression stopped there)"
        )
    if got != size:
        raise BagError(
            f"damaged {compression} {what} {where}: it inflates to {got} bytes, not the {size} "
            "its header declares"
        )


def _zstd(data: Any, out: memoryview) -> tuple[int, bool]:
    import zstandard  # lazy: zstandard, 6 ms

    # zstd's own frame header may state another size: reading into ``out`` bounds it anyway
    # (``decompress(max_output_size=)`` trusts the frame's size over its argument)
    reader = zstandard.ZstdDecompressor().stream_reader(data, read_across_frames=True)
    got = 0
    while got < len(out):
        n = reader.readinto(out[got:])
        if n == 0:
            break
        got += n
    return got, got == len(out) and bool(reader.read(1))


def _stepped(make: Any, data: Any, size: int) -> Iterator[bytes]:
    """The output of a bz2 or lz4 stream (several streams end to end, as both formats allow)
    in pieces of at most :data:`STEP` bytes, and one byte past ``size`` at most."""
    if size == 0 and len(data) == 0:
        return
    got = 0
    dec: _Stepper = make()
    feed = bytes(data)
    while True:
        piece = dec.decompress(feed, max_length=min(STEP, size - got + 1))
        feed = b""
        if piece:
            got += len(piece)
            yield piece
            if got > size:
                return
        if dec.eof:
            if not dec.unused_data:
                return
            feed = dec.unused_data
            dec = make()
        elif dec.needs_input:
            raise ValueError("the compressed stream ends before its end mark")


def inflate_file(
    compression: str, src: BinaryIO, dst: BinaryIO, compressed_size: int, where: str
) -> int:
    """Decompress a whole file (a rosbag2 storage file compressed file by file) from ``src``
    into ``dst`` in pieces; returns the bytes written.

    Raises:
        BagError: over the budget (:data:`~ertools.io.budget.MAX_FILE_COPY_BYTES`, or
            :func:`~ertools.io.budget.allowance` of its compressed size), corrupt data, or an
            unsupported compression.
    """
    if compression != "zstd":
        raise BagError(f"unsupported file compression {compression!r} {where}")
    import zstandard  # lazy: zstandard, 6 ms

    limit = min(budget.MAX_FILE_COPY_BYTES, budget.allowance(compressed_size))
    name = "MAX_FILE_COPY_BYTES" if limit == budget.MAX_FILE_COPY_BYTES else "MAX_INFLATE_PER_BYTE"
    written = 0
    try:
        reader = zstandard.ZstdDecompressor().stream_reader(src, read_across_frames=True)
        while True:
            piece = reader.read(min(STEP, limit + 1 - written))
            if not piece:
                return written
            written += len(piece)
            if written > limit:
                raise BagError(
                    budget.over_budget(
                        f"zstd-compressed file{where}",
                        f"more than {limit} bytes uncompressed (decompression stopped there)",
                        limit,
                        name,
                    )
                )
            dst.write(piece)
    except (BagError, OSError):
        raise
    except Exception as err:
        raise BagError(f"damaged zstd-compressed file{where} ({err})") from err


class Allowance:
    """The uncompressed bytes the chunks of one file have declared so far, refused once past
    :func:`~ertools.io.budget.allowance` of the file's size (each chunk counted once)."""

    def __init__(self, file_size: int, path: str) -> None:
        self.limit = budget.allowance(file_size)
        self.file_size = file_size
        self.path = path or None
        self.declared = 0

    def add(self, size: int, where: str, what: str = "chunk") -> None:
        """Count one more chunk (at ``where``) of ``size`` declared bytes.

        Raises:
            BagError: the chunk is over :data:`~ertools.io.budget.MAX_CHUNK_BYTES`, or the
                file's chunks now declare more than the file's allowance (naming the file).
        """
        try:
            check_declared(size, where, what)
        except BagError as err:
            raise BagError(err.message, path=self.path) from err
        self.declared += max(size, 0)
        if self.declared > self.limit:
            raise BagError(
                budget.over_budget(
                    f"the chunks of this {self.file_size}-byte file, up to the {what} {where}",
                    f"{self.declared} bytes uncompressed",
                    self.limit,
                    "MAX_INFLATE_PER_BYTE x the file's size + MAX_CHUNK_BYTES",
                ),
                path=self.path,
            )
