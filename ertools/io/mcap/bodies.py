"""The bodies of MCAP records other than messages, read from a buffer (the file's bytes, or
a chunk's): what a scan needs to know of a schema, a channel, or a record shaped like a chunk.
"""

from __future__ import annotations

import struct
from typing import Any

CHUNK_HEAD = struct.Struct("<QQQII")  # start, end, uncompressed size, crc, compression length
U16 = struct.Struct("<H")
U32 = struct.Struct("<I")
U64 = struct.Struct("<Q")


class CutError(Exception):
    """A record runs past the end of what holds it (file or chunk)."""


def _string(buf: Any, at: int, end: int) -> tuple[str, int]:
    (n,) = U32.unpack_from(buf, at)
    at += 4
    if at + n > end:
        raise CutError
    return bytes(buf[at : at + n]).decode("utf-8"), at + n


def schema(buf: Any, at: int, end: int) -> Any:
    """A schema record's body as ``mcap.records.Schema``."""
    from mcap.records import Schema  # lazy: mcap, 20 ms

    (sid,) = U16.unpack_from(buf, at)
    name, at = _string(buf, at + 2, end)
    encoding, at = _string(buf, at, end)
    (n,) = U32.unpack_from(buf, at)
    if at + 4 + n > end:
        raise CutError
    return Schema(id=sid, name=name, encoding=encoding, data=bytes(buf[at + 4 : at + 4 + n]))


def channel(buf: Any, at: int, end: int) -> Any:
    """A channel record's body as ``mcap.records.Channel``."""
    from mcap.records import Channel  # lazy: mcap, 20 ms

    cid, sid = struct.unpack_from("<HH", buf, at)
    topic, at = _string(buf, at + 4, end)
    encoding, at = _string(buf, at, end)
    (n,) = U32.unpack_from(buf, at)
    at += 4
    stop = at + n
    if stop > end:
        raise CutError
    metadata = {}
    while at < stop:
        key, at = _string(buf, at, stop)
        value, at = _string(buf, at, stop)
        metadata[key] = value
    return Channel(id=cid, schema_id=sid, topic=topic, message_encoding=encoding, metadata=metadata)


_COMPRESSIONS = (b"", b"lz4", b"zstd")


def chunk_shaped(buf: Any, body: int, stop: int) -> bool:
    """Whether ``buf[body:stop]`` reads as a chunk record's body: a compression the format
    names and a records length that ends exactly at ``stop``."""
    if stop - body < CHUNK_HEAD.size + 8:
        return False
    *_times, _usize, _crc, clen = CHUNK_HEAD.unpack_from(buf, body)
    at = body + CHUNK_HEAD.size
    if at + clen + 8 > stop or bytes(buf[at : at + clen]) not in _COMPRESSIONS:
        return False
    (nbytes,) = U64.unpack_from(buf, at + clen)
    return bool(at + clen + 8 + nbytes == stop)
