"""Pose messages that all share one byte layout, decoded with one gather.

A logger writes every message of a pose topic with the same frame names, so every message has
the same length and its fields sit at the same offsets. The layout is learnt from the first
message (with the field rules of :mod:`ertools.io.decode.fast`); all messages are then copied
as rows of one ``(N, size)`` array in a single gather, the structural bytes (string lengths,
frame names, CDR header and padding, the TF transform count) are compared with the first
message's, and stamps and poses are read as strided columns of the rows. That is one pass
over the messages' bytes instead of one gather per field.

Whenever a message differs in structure (another frame name, another length, several
transforms in a TF message), :func:`decode_uniform` returns None and the caller decodes field
by field, which handles every layout the standard definitions allow.
"""

from __future__ import annotations

import sys

import numpy as np
import numpy.typing as npt

from ertools.arrays import I64, U8, Bool
from ertools.frozen_dataclass import frozen_dataclass
from ertools.io.decode.fast import Decoded, gather

# Odometry after its pose: pose covariance (36), twist (6), twist covariance (36) float64.
_ODOM_TAIL = 36 + 6 + 36
# PoseWithCovarianceStamped after its pose: the pose covariance.
_COVARIANCE = 36


@frozen_dataclass
class Layout:
    """Where the fields of every message of a topic are, relative to the message start.

    ``stamp`` is None for types without a header (Pose2D); ``values`` counts the float64 at
    ``values_at`` (7 = xyz + quaternion, 3 = Pose2D x, y, theta). ``fixed`` are the byte
    ranges every message must share with the first one.
    """

    size: int
    stamp: tuple[int, int, str] | None  # (sec offset, nsec offset, sec dtype)
    values_at: int
    values: int
    fixed: tuple[tuple[int, int], ...]
    frame: str
    child: str | None
    ref: bytes  # the message the layout was learnt from: the bytes ``fixed`` must repeat


@frozen_dataclass(eq=False)
class Rows:
    """Preallocated result rows a decoder writes into (header stamps, positions, orientations)."""

    t_header: I64
    xyz: npt.NDArray[np.float64]
    quat: npt.NDArray[np.float64]


class _Probe:
    """A read position in one message (the first), moved field by field like
    :class:`ertools.io.decode.fast.Cursor`, recording which bytes may vary between messages."""

    def __init__(self, raw: bytes, cdr: bool) -> None:
        self.raw = raw
        self.cdr = cdr
        self.origin = 4 if cdr else 0
        self.pos = self.origin
        self.varying: list[tuple[int, int]] = []

    def _align(self, n: int) -> None:
        if self.cdr:
            rel = self.pos - self.origin
            self.pos = self.origin + (rel + n - 1) // n * n

    def number(self, size: int, *, varies: bool) -> int:
        """Offset of a ``size``-byte number (4 or 8 aligned in CDR)."""
        self._align(size)
        at = self.pos
        if at + size > len(self.raw):
            raise ValueError("field past the end of the message")
        self.pos += size
        if varies:
            self.varying.append((at, self.pos))
        return at

    def string(self) -> str:
        at = self.number(4, varies=False)
        n = int.from_bytes(self.raw[at : at + 4], "little")
        text = self.raw[self.pos : self.pos + n]
        if len(text) != n or (self.cdr and (n < 1 or text[-1:] != b"\x00")):
            raise ValueError("malformed string")
        self.pos += n
        return (text[:-1] if self.cdr else text).decode("utf-8")

    def floats(self, count: int) -> int:
        self._align(8)
        at = self.pos
        self.pos += 8 * count
        if self.pos > len(self.raw):
            raise ValueError("field past the end of the message")
        self.varying.append((at, self.pos))
        return at


def _header(p: _Probe) -> tuple[tuple[int, int, str], str]:
    if not p.cdr:
        p.number(4, varies=True)  # seq
    sec = p.number(4, varies=True)
    nsec = p.number(4, varies=True)
    return (sec, nsec, "<i4" if p.cdr else "<u4"), p.string()


def layout_of(msgtype: str, cdr: bool, raw: bytes) -> Layout | None:
    """The layout of messages shaped like ``raw``, or None when there is no single layout
    (a TF message with other than one transform) or ``raw`` does not parse."""
    if cdr and raw[:2] != b"\x00\x01":
        return None  # not little-endian plain CDR: the field decoder says why
    p = _Probe(raw, cdr)
    child: str | None = None
    stamp: tuple[int, int, str] | None = None
    try:
        if msgtype in ("geometry_msgs/PoseStamped", "geometry_msgs/PoseWithCovarianceStamped"):
            stamp, frame = _header(p)
            values_at, values = p.floats(7), 7
            if msgtype == "geometry_msgs/PoseWithCovarianceStamped":
                p.floats(_COVARIANCE)
        elif msgtype == "geometry_msgs/Pose2D":
            frame = ""
            values_at, values = p.floats(3), 3
        elif msgtype in ("geometry_msgs/TransformStamped", "nav_msgs/Odometry"):
            stamp, frame = _header(p)
            child = p.string()
            values_at, values = p.floats(7), 7
            if msgtype == "nav_msgs/Odometry":
                p.floats(_ODOM_TAIL)
        elif msgtype in ("tf/tfMessage", "tf2_msgs/TFMessage"):
            at = p.number(4, varies=False)
            if int.from_bytes(raw[at : at + 4], "little") != 1:
                return None
            stamp, frame = _header(p)
            child = p.string()
            values_at, values = p.floats(7), 7
        else:
            return None
    except (ValueError, UnicodeDecodeError):
        return None
    if p.pos != len(raw):
        return None
    fixed = []
    start = 0
    for a, b in p.varying:
        if a > start:
            fixed.append((start, a))
        start = b
    if start < len(raw):
        fixed.append((start, len(raw)))
    return Layout(len(raw), stamp, values_at, values, tuple(fixed), frame, child, raw)


def _column(rows: U8, offset: int, dtype: str, count: int = 1) -> npt.NDArray[np.generic]:
    """A strided view of one field of every row (no copy)."""
    n, size = rows.shape
    if count == 1:
        return np.ndarray((n,), dtype=dtype, buffer=rows, offset=offset, strides=(size,))
    step = np.dtype(dtype).itemsize
    return np.ndarray((n, count), dtype=dtype, buffer=rows, offset=offset, strides=(size, step))


def _words(lay: Layout) -> list[tuple[int, str, int]]:
    """(offset, dtype, value) of the words that cover the layout's fixed ranges: 8 bytes, or
    4, 2, 1 for shorter ranges; the last word overlaps the one before when a range is not a
    multiple of it."""
    out: list[tuple[int, str, int]] = []
    for a, b in lay.fixed:
        width = next(w for w in (8, 4, 2, 1) if w <= b - a)
        starts = list(range(a, b - width + 1, width))
        if starts[-1] != b - width:
            starts.append(b - width)
        out.extend(
            (at, f"<u{width}", int.from_bytes(lay.ref[at : at + width], "little")) for at in starts
        )
    return out


def same_structure(rows: U8, skip: int, lay: Layout, member: Bool | None = None) -> bool:
    """Whether every row (a message from byte ``skip`` on; with ``member``, every row where
    it is True) has the bytes of ``lay.ref`` where the layout's fixed ranges are (string
    lengths and names, CDR header and padding, the TF transform count).

    Compared a word at a time, so the cost is a few strided reads per row, not one per byte.
    """
    if not len(rows):
        return True
    bad: Bool | None = None
    for at, kind, want in _words(lay):
        differs = _column(rows, skip + at, kind) != want
        if member is None:
            if bool(differs.any()):
                return False
        else:
            bad = differs if bad is None else np.logical_or(bad, differs, out=bad)
    return member is None or bad is None or not bool(np.any(bad & member))


# Raw bytes are copied into float64 arrays as they are (one copy per row and block, faster
# than field by field) only where float64 is little-endian in memory, as ROS1 and CDR store it.
_RAW_COPY = np.dtype(np.float64).byteorder == "=" and sys.byteorder == "little"


def _copy_floats(dst: npt.NDArray[np.float64], rows: U8, offset: int) -> None:
    """``dst`` (n, k) float64 from the k little-endian float64 at ``offset`` of each row."""
    n, k = dst.shape
    if not n:
        return
    if _RAW_COPY and dst.flags.c_contiguous:
        block = np.dtype((np.void, 8 * k))
        width = rows.shape[1]
        src = np.ndarray((n,), dtype=block, buffer=rows, offset=offset, strides=(width,))
        dst.view(block).reshape(n)[...] = src
    else:
        dst[...] = _column(rows, offset, "<f8", k)


def write_rows(rows: U8, skip: int, lay: Layout, out: Rows) -> None:
    """Stamps and poses of every row (its message from byte ``skip`` on, in layout ``lay``,
    checked with :func:`same_structure`) into ``out``. Types without a header get stamp 0
    (their time is the record time)."""
    if lay.stamp is not None:
        sec_at, nsec_at, sec_type = lay.stamp
        np.multiply(
            _column(rows, skip + sec_at, sec_type), 1_000_000_000, out=out.t_header, dtype=np.int64
        )
        np.add(out.t_header, _column(rows, skip + nsec_at, "<u4"), out=out.t_header)
        _copy_floats(out.xyz, rows, skip + lay.values_at)
        _copy_floats(out.quat, rows, skip + lay.values_at + 24)
    else:
        out.t_header[...] = 0
        values = _column(rows, skip + lay.values_at, "<f8", lay.values)
        out.xyz[:, :2] = values[:, :2]
        out.xyz[:, 2] = 0.0
        # (rows of other messages, overwritten afterwards, may hold any bits: no warnings)
        with np.errstate(all="ignore"):
            # quat_from_yaw's own operations on the same contiguous input (the same bits),
            # written into place rather than stacked
            half = 0.5 * np.array(values[:, 2], dtype=np.float64)
            out.quat[:, :2] = 0.0
            out.quat[:, 2] = np.sin(half)
            out.quat[:, 3] = np.cos(half)


def decoded(lay: Layout, out: Rows) -> Decoded:
    """The :class:`Decoded` of rows written by :func:`write_rows` (one frame name each)."""
    n = len(out.t_header)
    empty = np.zeros(n, dtype=np.int64)
    child = None if lay.child is None else (empty, empty)
    return Decoded(
        np.arange(n, dtype=np.int64),
        out.t_header,
        out.xyz,
        out.quat,
        (empty, empty),
        child,
        has_header=lay.stamp is not None,
        frame_text=lay.frame,
        child_text=lay.child,
    )


def empty_rows(n: int) -> Rows:
    return Rows(np.empty(n, np.int64), np.empty((n, 3)), np.empty((n, 4)))


def decode_uniform(
    msgtype: str, cdr: bool, buf: U8, start: I64, length: I64, into: Rows | None = None
) -> Decoded | None:
    """Every message (``start``, ``length`` into ``buf``) decoded at once when all share the
    first one's layout; None otherwise (the caller then decodes field by field).

    With ``into``, stamps and poses are written there (no intermediate arrays) and the
    returned columns are views of it.
    """
    n = len(start)
    if n < 2:
        return None
    first = int(start[0])
    lay = layout_of(msgtype, cdr, buf[first : first + int(length[0])].tobytes())
    if lay is None or not bool(np.all(length == lay.size)):
        return None
    if int(start.min()) < 0 or int(start.max()) + lay.size > len(buf):
        return None
    rows = gather(buf, start, lay.size)
    if not same_structure(rows, 0, lay):
        return None
    out = into if into is not None else empty_rows(n)
    write_rows(rows, 0, lay, out)
    return decoded(lay, out)
