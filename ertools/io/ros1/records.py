"""ROS1 bag v2.0 records, parsed from raw bytes (no rosbags).

A record is ``header_len u32, header, data_len u32, data``; a header is a run of
``field_len u32, name=value`` fields. The op codes are those of the format specification
(http://wiki.ros.org/Bags/Format/2.0): 0x02 message data, 0x03 bag header, 0x04 index data,
0x05 chunk, 0x06 chunk info, 0x07 connection.
"""

from __future__ import annotations

import re
import struct
from typing import BinaryIO

from ertools.errors import BagError
from ertools.frozen_dataclass import frozen_dataclass
from ertools.io import budget

OP_MSG = 0x02
OP_BAG_HEADER = 0x03
OP_INDEX = 0x04
OP_CHUNK = 0x05
OP_CHUNK_INFO = 0x06
OP_CONNECTION = 0x07

MAGIC_LEN = 13  # b"#ROSBAG V2.0\n"

_U32 = struct.Struct("<I")
_U64 = struct.Struct("<Q")


class RecordError(ValueError):
    """A record that does not parse; ``offset`` is its byte position in the file or chunk."""

    def __init__(self, message: str, offset: int) -> None:
        super().__init__(f"{message} at byte {offset}")
        self.offset = offset


def parse_fields(header: bytes | memoryview, offset: int = 0) -> dict[str, bytes]:
    """The ``name=value`` fields of a record header."""
    fields: dict[str, bytes] = {}
    buf = bytes(header)
    pos = 0
    end = len(buf)
    while pos < end:
        if pos + 4 > end:
            raise RecordError("header field length runs past the header", offset + pos)
        (n,) = _U32.unpack_from(buf, pos)
        pos += 4
        field = buf[pos : pos + n]
        if len(field) != n:
            raise RecordError("header field runs past the header", offset + pos)
        eq = field.find(b"=")
        if eq < 0:
            raise RecordError("header field without '='", offset + pos)
        fields[field[:eq].decode("ascii", "replace")] = field[eq + 1 :]
        pos += n
    return fields


def u32(fields: dict[str, bytes], name: str) -> int:
    return int(_U32.unpack(fields[name][:4])[0])


def u64(fields: dict[str, bytes], name: str) -> int:
    return int(_U64.unpack(fields[name][:8])[0])


def time_ns(fields: dict[str, bytes], name: str) -> int:
    """A ROS time field (sec u32, nsec u32) as ns."""
    sec, nsec = struct.unpack("<II", fields[name][:8])
    return int(sec) * 1_000_000_000 + int(nsec)


def op_of(fields: dict[str, bytes]) -> int:
    op = fields.get("op")
    if not op:
        raise KeyError("op")
    return op[0]


@frozen_dataclass
class Record:
    """A record read from a file: its position, header fields and where its data lies."""

    pos: int
    op: int
    fields: dict[str, bytes]
    data_pos: int
    data_len: int

    @property
    def end(self) -> int:
        return self.data_pos + self.data_len


def read_record(
    f: BinaryIO,
    pos: int,
    file_size: int,
    *,
    with_data: bool = False,
    lazy_ops: frozenset[int] = frozenset(),
) -> tuple[Record, bytes]:
    """The record at ``pos`` (data read only when ``with_data``, and not for records whose op
    is in ``lazy_ops``: a caller that reads a chunk's data later holds one at a time).

    Raises:
        RecordError: the record is cut off by the end of the file or malformed.
        BagError: its header, or (``with_data``) its data, is over the budget
            (:mod:`ertools.io.budget`).
    """
    f.seek(pos)
    raw = f.read(4)
    if len(raw) < 4:
        raise RecordError("record header length cut off by end of file", pos)
    (hlen,) = _U32.unpack(raw)
    if pos + 8 + hlen > file_size:
        raise RecordError("record header cut off by end of file or absurd length", pos)
    if hlen > budget.MAX_RECORD_HEADER_BYTES:
        raise BagError(
            budget.over_budget(
                f"record at byte {pos}",
                f"a header of {hlen} bytes",
                budget.MAX_RECORD_HEADER_BYTES,
                "MAX_RECORD_HEADER_BYTES",
            )
        )
    header = f.read(hlen)
    raw = f.read(4)
    if len(header) < hlen or len(raw) < 4:
        raise RecordError("record cut off by end of file", pos)
    (dlen,) = _U32.unpack(raw)
    data_pos = pos + 8 + hlen
    if data_pos + dlen > file_size:
        raise RecordError(f"record data ({dlen} bytes) cut off by end of file", pos)
    try:
        fields = parse_fields(header, pos + 4)
        op = op_of(fields)
    except KeyError as err:
        raise RecordError("record header without op field", pos) from err
    with_data = with_data and op not in lazy_ops
    if with_data and dlen > budget.MAX_CHUNK_BYTES:
        # a chunk's stored bytes are read whole (and other records are far smaller)
        raise BagError(
            budget.over_budget(
                f"record at byte {pos}",
                f"{dlen} bytes of data",
                budget.MAX_CHUNK_BYTES,
                "MAX_CHUNK_BYTES",
            )
        )
    data = f.read(dlen) if with_data else b""
    return Record(pos, op, fields, data_pos, dlen), data


_TYPE_NAME = re.compile(r"[A-Za-z][A-Za-z0-9_]*(/msg)?/[A-Za-z][A-Za-z0-9_]*")


def connection_fields(record: Record, data: bytes) -> tuple[int, str, dict[str, bytes]]:
    """(conn id, topic, connection-header fields) of a connection record."""
    fields = parse_fields(data, record.data_pos)
    try:
        # Names that are not UTF-8 are damage (rosbags refuses them too); decoded with
        # replacement characters they became topics and types the bag never had.
        topic = record.fields.get("topic", fields.get("topic", b"")).decode("utf-8")
        msgtype = fields.get("type", b"").decode("utf-8")
    except UnicodeDecodeError as err:
        raise RecordError(f"connection topic or type is not UTF-8 ({err})", record.pos) from err
    if "type" not in fields:
        # every writer names the type; without it the topic reads as of no type at all (a
        # damaged field name, found by fuzzing: `tYpe=`), where rosbags refuses the bag
        raise RecordError("connection record without a type field", record.pos)
    if msgtype and not _TYPE_NAME.fullmatch(msgtype):
        # ROS type names are package/Name, each starting with a letter: another name is a
        # damaged byte (rosbags then fails on the definition), not a type the bag holds
        raise RecordError(f"connection type {msgtype!r} is no ROS type name", record.pos)
    return u32(record.fields, "conn"), topic, fields


def chunk_info(record: Record, data: bytes) -> tuple[int, int, int, dict[int, int]]:
    """(chunk_pos, start_ns, end_ns, {conn: count}) of a chunk-info record."""
    ver = u32(record.fields, "ver")
    if ver != 1:
        raise RecordError(f"chunk info version {ver} not supported", record.pos)
    count = u32(record.fields, "count")
    pairs = struct.unpack_from(f"<{2 * count}I", data) if count else ()
    counts = {int(pairs[2 * i]): int(pairs[2 * i + 1]) for i in range(count)}
    return (
        u64(record.fields, "chunk_pos"),
        time_ns(record.fields, "start_time"),
        time_ns(record.fields, "end_time"),
        counts,
    )
