"""Structure-aware, seeded mutations of ROS1 and MCAP files.

:func:`sites` parses a seed file into its records and fields (offset, length, category, name),
walking into uncompressed chunks; :func:`mutate` picks one mutation from a NumPy generator:
a truncation (at a record boundary or anywhere), one field changed (a bit, a byte, zeroed,
all ones, +-1, a random value: in record headers, op codes, lengths, index and chunk-info
records, MCAP summary, footer and compression fields) or a few random bytes anywhere.
The same generator state gives the same mutant.
"""

from __future__ import annotations

import functools
import struct
from dataclasses import dataclass

import numpy as np

ROS1_MAGIC = b"#ROSBAG V2.0\n"
MCAP_MAGIC = b"\x89MCAP0\r\n"

# Field categories; mutate() picks a category first so that rare ones are hit as often.
CATEGORIES = ("op", "length", "header", "index", "chunk_info", "summary", "compression", "data")


@dataclass(frozen=True)
class Site:
    offset: int
    length: int
    category: str
    name: str


@dataclass(frozen=True)
class Layout:
    sites: tuple[Site, ...]
    boundaries: tuple[int, ...]  # record starts (and the file end)


# ROS1 ---------------------------------------------------------------------------------------

ROS1_OPS = {
    0: "?",
    2: "message",
    3: "bag_header",
    4: "index_data",
    5: "chunk",
    6: "chunk_info",
    7: "connection",
}
ROS1_FIELD_CATEGORY = {
    "op": "op",
    "conn": "header",
    "time": "header",
    "ver": "header",
    "index_pos": "summary",
    "conn_count": "summary",
    "chunk_count": "summary",
    "chunk_pos": "chunk_info",
    "start_time": "chunk_info",
    "end_time": "chunk_info",
    "count": "index",
    "compression": "compression",
    "size": "compression",
    "topic": "header",
}


def _ros1_records(
    data: bytes, pos: int, end: int, prefix: str, out: list[Site], bounds: list[int]
) -> None:
    while pos + 4 <= end:
        bounds.append(pos)
        (hlen,) = struct.unpack_from("<I", data, pos)
        out.append(Site(pos, 4, "length", f"{prefix}header_len"))
        hstart, hend = pos + 4, pos + 4 + hlen
        if hend + 4 > end:
            return
        fields: dict[str, tuple[int, int]] = {}
        p = hstart
        while p + 4 <= hend:
            (flen,) = struct.unpack_from("<I", data, p)
            out.append(Site(p, 4, "length", f"{prefix}field_len"))
            body = data[p + 4 : p + 4 + flen]
            eq = body.find(b"=")
            if eq > 0:
                name = body[:eq].decode("ascii", "replace")
                fields[name] = (p + 4 + eq + 1, flen - eq - 1)
            p += 4 + flen
        op = data[fields["op"][0]] if "op" in fields and fields["op"][1] == 1 else 0
        kind = ROS1_OPS.get(op, "?")
        for name, (off, n) in fields.items():
            cat = ROS1_FIELD_CATEGORY.get(name, "header")
            if kind == "index_data" and name in ("conn", "ver", "count"):
                cat = "index"
            if kind == "chunk_info" and name in ("ver", "count"):
                cat = "chunk_info"
            out.append(Site(off, n, cat, f"{prefix}{kind}.{name}"))
        (dlen,) = struct.unpack_from("<I", data, hend)
        out.append(Site(hend, 4, "length", f"{prefix}{kind}.data_len"))
        dstart, dend = hend + 4, min(hend + 4 + dlen, end)
        if kind == "chunk":
            comp = (
                data[fields["compression"][0] : sum(fields["compression"])]
                if "compression" in fields
                else b""
            )
            if comp == b"none":
                _ros1_records(data, dstart, dend, "chunk.", out, bounds)
            elif dend > dstart:
                out.append(Site(dstart, dend - dstart, "data", f"{kind}.compressed"))
        elif kind == "index_data":
            for e in range(dstart, dend - 11, 12):
                out.append(Site(e, 8, "index", "index_data.entry_time"))
                out.append(Site(e + 8, 4, "index", "index_data.entry_offset"))
        elif kind == "chunk_info":
            for e in range(dstart, dend - 7, 8):
                out.append(Site(e, 4, "chunk_info", "chunk_info.entry_conn"))
                out.append(Site(e + 4, 4, "chunk_info", "chunk_info.entry_count"))
        elif kind in ("message", "connection") and dend > dstart:
            out.append(Site(dstart, dend - dstart, "data", f"{prefix}{kind}.data"))
        pos = hend + 4 + dlen
    bounds.append(min(pos, end))


# MCAP ---------------------------------------------------------------------------------------

# opcode -> (name, fields); field kinds: u8 u16 u32 u64, str (u32 length + bytes), b4 (u32
# length + bytes), b8 (u64 length + bytes), m (u32 byte length + entries), rest (to the end).
MCAP_RECORDS: dict[int, tuple[str, list[tuple[str, str, str]]]] = {
    0x01: ("header", [("profile", "str", "header"), ("library", "str", "header")]),
    0x02: (
        "footer",
        [
            ("summary_start", "u64", "summary"),
            ("summary_offset_start", "u64", "summary"),
            ("summary_crc", "u32", "summary"),
        ],
    ),
    0x03: (
        "schema",
        [
            ("id", "u16", "header"),
            ("name", "str", "header"),
            ("encoding", "str", "header"),
            ("data", "b4", "data"),
        ],
    ),
    0x04: (
        "channel",
        [
            ("id", "u16", "header"),
            ("schema_id", "u16", "header"),
            ("topic", "str", "header"),
            ("message_encoding", "str", "header"),
            ("metadata", "m", "header"),
        ],
    ),
    0x05: (
        "message",
        [
            ("channel_id", "u16", "header"),
            ("sequence", "u32", "header"),
            ("log_time", "u64", "header"),
            ("publish_time", "u64", "header"),
            ("data", "rest", "data"),
        ],
    ),
    0x06: (
        "chunk",
        [
            ("message_start_time", "u64", "chunk_info"),
            ("message_end_time", "u64", "chunk_info"),
            ("uncompressed_size", "u64", "compression"),
            ("uncompressed_crc", "u32", "compression"),
            ("compression", "str", "compression"),
            ("records", "b8", "data"),
        ],
    ),
    0x07: ("message_index", [("channel_id", "u16", "index"), ("records", "m", "index")]),
    0x08: (
        "chunk_index",
        [
            ("message_start_time", "u64", "chunk_info"),
            ("message_end_time", "u64", "chunk_info"),
            ("chunk_start_offset", "u64", "chunk_info"),
            ("chunk_length", "u64", "chunk_info"),
            ("message_index_offsets", "m", "chunk_info"),
            ("message_index_length", "u64", "chunk_info"),
            ("compression", "str", "compression"),
            ("compressed_size", "u64", "compression"),
            ("uncompressed_size", "u64", "compression"),
        ],
    ),
    0x0B: (
        "statistics",
        [
            ("message_count", "u64", "summary"),
            ("schema_count", "u16", "summary"),
            ("channel_count", "u32", "summary"),
            ("attachment_count", "u32", "summary"),
            ("metadata_count", "u32", "summary"),
            ("chunk_count", "u32", "summary"),
            ("message_start_time", "u64", "summary"),
            ("message_end_time", "u64", "summary"),
            ("channel_message_counts", "m", "summary"),
        ],
    ),
    0x0E: (
        "summary_offset",
        [
            ("group_opcode", "u8", "summary"),
            ("group_start", "u64", "summary"),
            ("group_length", "u64", "summary"),
        ],
    ),
    0x0F: ("data_end", [("data_section_crc", "u32", "summary")]),
}
SIZES = {"u8": 1, "u16": 2, "u32": 4, "u64": 8}
# entry size of maps and arrays, by record and field
MAP_ENTRY = {
    ("message_index", "records"): 16,
    ("chunk_index", "message_index_offsets"): 10,
    ("statistics", "channel_message_counts"): 10,
}


def _mcap_records(
    data: bytes, pos: int, end: int, prefix: str, out: list[Site], bounds: list[int]
) -> None:
    while pos + 9 <= end:
        bounds.append(pos)
        op = data[pos]
        (length,) = struct.unpack_from("<Q", data, pos + 1)
        name, fields = MCAP_RECORDS.get(op, (f"op{op:#x}", []))
        out.append(Site(pos, 1, "op", f"{prefix}{name}.opcode"))
        out.append(Site(pos + 1, 8, "length", f"{prefix}{name}.length"))
        p, rend = pos + 9, min(pos + 9 + length, end)
        compression = b""
        for fname, kind, cat in fields:
            label = f"{prefix}{name}.{fname}"
            if kind in SIZES:
                if p + SIZES[kind] > rend:
                    break
                out.append(Site(p, SIZES[kind], cat, label))
                p += SIZES[kind]
            elif kind == "rest":
                if rend > p:
                    out.append(Site(p, rend - p, cat, label))
                p = rend
            else:
                w = 8 if kind == "b8" else 4
                if p + w > rend:
                    break
                n = int.from_bytes(data[p : p + w], "little")
                out.append(Site(p, w, "length", f"{label}_len"))
                body, p = p + w, min(p + w + n, rend)
                if fname == "compression":
                    compression = data[body:p]
                    if p > body:
                        out.append(Site(body, p - body, cat, label))
                elif kind == "m" and (name, fname) in MAP_ENTRY:
                    step = MAP_ENTRY[(name, fname)]
                    for e in range(body, p - step + 1, step):
                        out.append(Site(e, step, cat, f"{label}.entry"))
                elif name == "chunk" and fname == "records" and compression == b"":
                    _mcap_records(data, body, p, "chunk.", out, bounds)
                elif p > body:
                    out.append(Site(body, p - body, cat if kind != "str" else "header", label))
        pos += 9 + length
    bounds.append(min(pos, end))


@functools.lru_cache(maxsize=32)
def layout(data: bytes) -> Layout:
    """The fields and record boundaries of a ROS1 or MCAP file."""
    out: list[Site] = []
    bounds: list[int] = [0]
    if data.startswith(ROS1_MAGIC):
        out.append(Site(0, len(ROS1_MAGIC), "header", "magic"))
        _ros1_records(data, len(ROS1_MAGIC), len(data), "", out, bounds)
    elif data.startswith(MCAP_MAGIC):
        out.append(Site(0, 8, "header", "magic"))
        out.append(Site(len(data) - 8, 8, "summary", "end_magic"))
        _mcap_records(data, 8, len(data) - 8, "", out, bounds)
        bounds.append(len(data) - 8)
    else:
        raise ValueError("not a ROS1 bag or MCAP file")
    bounds.append(len(data))
    return Layout(tuple(out), tuple(sorted(set(bounds))))


def _change_field(buf: bytearray, site: Site, rng: np.random.Generator) -> str:
    """Change the bytes of one field; returns what was done."""
    a, n = site.offset, site.length
    how = int(rng.integers(0, 7))
    if n > 8 or how == 0:  # flip one bit (the only change for long fields but random bytes)
        at = a + int(rng.integers(0, n))
        bit = int(rng.integers(0, 8))
        buf[at] ^= 1 << bit
        return f"bit {bit} of byte {at} flipped"
    value = int.from_bytes(buf[a : a + n], "little")
    top = (1 << (8 * n)) - 1
    if how == 1:
        new = 0
    elif how == 2:
        new = top
    elif how == 3:
        new = (value + 1) & top
    elif how == 4:
        new = (value - 1) & top
    elif how == 5:
        new = (
            int(rng.integers(0, top, endpoint=True, dtype=np.uint64))
            if n == 8
            else int(rng.integers(0, top + 1))
        )
    else:  # a plausible wrong value: a small number, or the value scaled
        new = int(rng.choice([1, 2, 3, 7, 255, 4096, value * 2, value // 2, value + 100])) & top
    buf[a : a + n] = new.to_bytes(n, "little")
    return f"{value} -> {new}"


@dataclass(frozen=True)
class Mutant:
    data: bytes
    what: str  # one line
    edits: tuple[tuple[int, bytes], ...] = ()  # (offset, new bytes) of each change; () for a cut


def mutate(data: bytes, rng: np.random.Generator) -> Mutant:
    """One mutant of ``data``, with a one-line description of the mutation."""
    lay = layout(data)
    kind = float(rng.random())
    if kind < 0.1:
        cut = int(rng.choice(lay.boundaries[1:-1]))
        cut += int(rng.choice([0, 0, 0, -1, 1]))
        cut = min(max(cut, 1), len(data) - 1)
        return Mutant(data[:cut], f"truncated at record boundary byte {cut} of {len(data)}")
    if kind < 0.2:
        cut = int(rng.integers(1, len(data)))
        return Mutant(data[:cut], f"truncated at byte {cut} of {len(data)}")
    buf = bytearray(data)
    if kind < 0.85:
        present = [c for c in CATEGORIES if any(s.category == c for s in lay.sites)]
        cat = present[int(rng.integers(0, len(present)))]
        pool = [s for s in lay.sites if s.category == cat]
        site = pool[int(rng.integers(0, len(pool)))]
        what = _change_field(buf, site, rng)
        edit = (site.offset, bytes(buf[site.offset : site.offset + site.length]))
        return Mutant(bytes(buf), f"{cat} field {site.name} at byte {site.offset}: {what}", (edit,))
    n = int(rng.integers(1, 9))
    at = sorted(int(x) for x in rng.integers(0, len(buf), n))
    for a in at:
        buf[a] = int(rng.integers(0, 256))
    edits = tuple((a, bytes(buf[a : a + 1])) for a in sorted(set(at)))
    return Mutant(bytes(buf), f"random bytes at {at}", edits)
