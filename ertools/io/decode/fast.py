"""Bulk decoding of fixed-layout pose messages straight from raw bytes, with NumPy.

Given one buffer (an uncompressed chunk) and the start and length of every message in it,
each field is read for all messages at once: fixed-size parts with strided gathers, variable
length strings (``frame_id``, ``child_frame_id``) by reading their length fields vectorised
and moving every message's cursor by its own length. There is no Python loop over messages.

Handled: ``geometry_msgs/PoseStamped``, ``Pose2D``, ``TransformStamped``,
``PoseWithCovarianceStamped``, ``nav_msgs/Odometry`` and ``tf/tfMessage`` /
``tf2_msgs/TFMessage`` (any number of transforms per message), in ROS1 encoding and in
little-endian CDR (ROS 2, with its alignment rules). A message whose length
disagrees with the layout (a non-standard definition under a standard name) makes the decoder
give up, and the caller falls back to rosbags' deserializer.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import numpy.typing as npt

from ertools.arrays import F64, I32, I64, U8
from ertools.frozen_dataclass import frozen_dataclass
from ertools.geometry import quat_from_yaw
from ertools.io.decode.posebatch import STAMPED_TYPES, PoseBatch

# The stamped pose types and Pose2D (which has no header).
FAST_TYPES = ("geometry_msgs/Pose2D", *STAMPED_TYPES)


class LayoutMismatchError(ValueError):
    """The bytes do not have the layout of the standard message definition."""


def read_at(buf: U8, pos: I64, dtype: np.dtype[Any]) -> npt.NDArray[Any]:
    """One value of ``dtype`` (any alignment) starting at each ``pos`` of ``buf``.

    ``buf`` is viewed as a run of overlapping ``dtype`` items, one starting at every byte
    (stride 1), and indexed once: NumPy copies whole items, with no per-byte index array.
    """
    size = dtype.itemsize
    if len(pos) and (int(pos.min()) < 0 or int(pos.max()) + size > len(buf)):
        raise LayoutMismatchError("field past the end of the buffer")
    if len(buf) < size:
        return np.empty((0, *dtype.shape), dtype=dtype.base)
    items = np.ndarray((len(buf) - size + 1,), dtype=dtype, buffer=buf, strides=(1,))
    return items[pos]


def gather(buf: U8, pos: I64, width: int) -> U8:
    """(N, width) bytes starting at each ``pos``."""
    if len(pos) == 0 or width == 0:
        return np.empty((len(pos), width), np.uint8)
    out: U8 = read_at(buf, pos, np.dtype((np.void, width))).view(np.uint8).reshape(-1, width)
    return out


class Cursor:
    """Per-message read positions in one buffer, advanced field by field (vectorised).

    ``origin`` is where CDR alignment counts from (after the 4-byte encapsulation header);
    for ROS1 nothing is aligned.
    """

    def __init__(self, buf: U8, start: I64, cdr: bool) -> None:
        self.buf = buf
        self.cdr = cdr
        self.origin = start + 4 if cdr else start
        self.pos = self.origin.copy()

    def _align(self, n: int) -> None:
        if self.cdr:
            rel = self.pos - self.origin
            self.pos = self.origin + (rel + (n - 1)) // n * n

    def u32(self) -> I64:
        self._align(4)
        v = read_at(self.buf, self.pos, np.dtype("<u4")).astype(np.int64)
        self.pos = self.pos + 4
        return v

    def i32(self) -> I64:
        self._align(4)
        v = read_at(self.buf, self.pos, np.dtype("<i4")).astype(np.int64)
        self.pos = self.pos + 4
        return v

    def string(self) -> tuple[I64, I64]:
        """(start, length) of a string field; CDR's terminating NUL is not part of it."""
        n = self.u32()
        start = self.pos.copy()
        self.pos = self.pos + n
        if self.cdr:
            if np.any(n < 1):
                raise LayoutMismatchError("CDR string without terminator")
            n = n - 1
        return start, n

    def f64(self, count: int) -> F64:
        self._align(8)
        v = read_at(self.buf, self.pos, np.dtype(("<f8", (count,)))).reshape(-1, count)
        self.pos = self.pos + 8 * count
        return np.asarray(v, dtype=np.float64)

    def skip_f64(self, count: int) -> None:
        self._align(8)
        self.pos = self.pos + 8 * count

    def take(self, index: I64) -> Cursor:
        sub = Cursor.__new__(Cursor)
        sub.buf, sub.cdr = self.buf, self.cdr
        sub.origin, sub.pos = self.origin[index], self.pos[index]
        return sub


def _utf8(raw: bytes) -> str:
    """Text of a string field; bytes that are not UTF-8 are no standard message (fall back)."""
    try:
        return raw.decode("utf-8")
    except UnicodeDecodeError as err:
        raise LayoutMismatchError(f"string field is not UTF-8 ({err})") from err


def decode_strings(buf: U8, start: I64, length: I64) -> tuple[I32, tuple[str, ...]]:
    """Codes into a table of distinct strings, grouping messages by string length."""
    codes = np.zeros(len(start), dtype=np.int32)
    names: dict[str, int] = {}
    if len(length) and np.all(length == length[0]):
        # The usual case, one frame name for the whole topic: compare every row with the first.
        n = int(length[0])
        rows = gather(buf, start, n)
        if n == 0 or np.array_equal(rows, np.broadcast_to(rows[0], rows.shape)):
            return codes, (_utf8(bytes(rows[0])) if n else "",)
    for n in np.unique(length):
        sel = np.flatnonzero(length == n)
        if n == 0:
            codes[sel] = names.setdefault("", len(names))
            continue
        rows = np.ascontiguousarray(gather(buf, start[sel], int(n)))
        uniq, inverse = np.unique(
            rows.view(np.dtype((np.void, int(n)))).reshape(-1), return_inverse=True
        )
        table = np.array(
            [names.setdefault(_utf8(bytes(u)), len(names)) for u in uniq], dtype=np.int32
        )
        codes[sel] = table[inverse.reshape(-1)]
    return codes, tuple(names)


@frozen_dataclass(eq=False)
class Decoded:
    """Columns decoded from one buffer (rows in message order, TF transforms expanded)."""

    msg_index: I64
    t_header: I64
    xyz: F64
    quat_xyzw: F64
    frame: tuple[I64, I64]
    child: tuple[I64, I64] | None
    has_header: bool = True
    # Set when every row has the same names (the uniform decoder checked them): no string pass.
    frame_text: str | None = None
    child_text: str | None = None


def _header(cur: Cursor) -> tuple[I64, tuple[I64, I64]]:
    if not cur.cdr:
        cur.u32()  # seq
        sec = cur.u32()
    else:
        sec = cur.i32()
    nsec = cur.u32()
    return sec * 1_000_000_000 + nsec, cur.string()


def _transform_stamped(cur: Cursor) -> tuple[I64, tuple[I64, I64], tuple[I64, I64], F64]:
    t, frame = _header(cur)
    child = cur.string()
    return t, frame, child, cur.f64(7)


def decode(msgtype: str, cdr: bool, buf: U8, start: I64, length: I64) -> Decoded:
    """Decode every message (``start``, ``length`` into ``buf``) of one pose type.

    Raises:
        LayoutMismatchError: the bytes do not fit the standard layout (caller falls back).
        KeyError: ``msgtype`` is not handled here.
    """
    n = len(start)
    if cdr and n:
        head = gather(buf, start, 2)
        if np.any(head[:, 1] != 1) or np.any(head[:, 0] != 0):
            raise LayoutMismatchError("not little-endian plain CDR")
    cur = Cursor(buf, start, cdr)
    idx = np.arange(n, dtype=np.int64)
    end = start + length
    if msgtype == "geometry_msgs/PoseStamped":
        t, frame = _header(cur)
        v = cur.f64(7)
        result = Decoded(idx, t, v[:, :3], v[:, 3:], frame, None)
    elif msgtype == "geometry_msgs/PoseWithCovarianceStamped":
        t, frame = _header(cur)
        v = cur.f64(7)
        cur.skip_f64(36)  # pose covariance
        result = Decoded(idx, t, v[:, :3], v[:, 3:], frame, None)
    elif msgtype == "geometry_msgs/Pose2D":
        v = cur.f64(3)

        xyz = np.column_stack([v[:, 0], v[:, 1], np.zeros(n)])
        e = np.zeros(n, dtype=np.int64)
        result = Decoded(
            idx, e, xyz, quat_from_yaw(v[:, 2]).reshape(n, 4), (e, e), None, has_header=False
        )
    elif msgtype == "geometry_msgs/TransformStamped":
        t, frame, child, v = _transform_stamped(cur)
        result = Decoded(idx, t, v[:, :3], v[:, 3:], frame, child)
    elif msgtype == "nav_msgs/Odometry":
        t, frame = _header(cur)
        child = cur.string()
        v = cur.f64(7)
        cur.skip_f64(36 + 6 + 36)  # pose covariance, twist, twist covariance
        result = Decoded(idx, t, v[:, :3], v[:, 3:], frame, child)
    elif msgtype in ("tf/tfMessage", "tf2_msgs/TFMessage"):
        result = _tf(cur, idx)
    else:
        raise KeyError(msgtype)
    if not np.array_equal(cur.pos, end):
        raise LayoutMismatchError(f"{msgtype}: message lengths disagree with the standard layout")
    return result


def _tf(cur: Cursor, idx: I64) -> Decoded:
    count = cur.u32()
    if len(count) and int(count.max()) > 10_000:
        raise LayoutMismatchError("absurd transform count")
    parts: list[tuple[I64, I64, I64, tuple[I64, I64], tuple[I64, I64], F64]] = []
    for step in range(int(count.max()) if len(count) else 0):
        active = np.flatnonzero(count > step)
        sub = cur.take(active)
        t, frame, child, v = _transform_stamped(sub)
        cur.pos[active] = sub.pos
        parts.append((active, np.full(len(active), step, dtype=np.int64), t, frame, child, v))
    if not parts:
        e = np.empty(0, np.int64)
        return Decoded(e, e, np.empty((0, 3)), np.empty((0, 4)), (e, e), (e, e))
    msg = np.concatenate([p[0] for p in parts])
    k = np.concatenate([p[1] for p in parts])
    order = np.lexsort((k, msg))  # message order, then transform order inside a message

    def cat(i: int) -> I64:
        return np.asarray(np.concatenate([p[i] for p in parts])[order], dtype=np.int64)

    v = np.concatenate([p[5] for p in parts])[order]
    frame = (
        np.concatenate([p[3][0] for p in parts])[order],
        np.concatenate([p[3][1] for p in parts])[order],
    )
    child = (
        np.concatenate([p[4][0] for p in parts])[order],
        np.concatenate([p[4][1] for p in parts])[order],
    )
    return Decoded(idx[msg[order]], cat(2), v[:, :3], v[:, 3:], frame, child)


def to_batch(buf: U8, dec: Decoded, t_record: I64) -> PoseBatch:
    """A :class:`PoseBatch` from decoded columns; ``t_record`` is per message."""
    if dec.frame_text is not None:
        return _uniform_batch(dec, t_record)
    starts = [dec.frame[0]]
    lens = [dec.frame[1]]
    if dec.child is not None:
        starts.append(dec.child[0])
        lens.append(dec.child[1])
    codes, names = decode_strings(buf, np.concatenate(starts), np.concatenate(lens))
    n = len(dec.msg_index)
    frame_idx = codes[:n]
    child_idx = codes[n:] if dec.child is not None else None
    frames = names
    if child_idx is None or "" not in names:
        # Rows without a child name point at "" (appended when absent).
        if "" not in names:
            frames = (*names, "")
        empty = frames.index("")
        if child_idx is None:
            child_idx = np.full(n, empty, dtype=np.int32)
    t_rec = t_record[dec.msg_index]
    t_hdr = dec.t_header if dec.has_header else t_rec.copy()
    return PoseBatch(t_rec, t_hdr, dec.xyz, dec.quat_xyzw, frame_idx, child_idx, frames)


def _uniform_batch(dec: Decoded, t_record: I64) -> PoseBatch:
    n = len(dec.msg_index)
    names: dict[str, int] = {"": 0}
    frame = names.setdefault(dec.frame_text or "", len(names))
    child = names.setdefault(dec.child_text or "", len(names))
    t_rec = t_record[dec.msg_index]
    return PoseBatch(
        t_rec,
        dec.t_header if dec.has_header else t_rec.copy(),
        dec.xyz,
        dec.quat_xyzw,
        np.full(n, frame, dtype=np.int32),
        np.full(n, child, dtype=np.int32),
        tuple(names),
    )


def is_state_definition(msgdef: str) -> bool:
    """True when a stored definition is the 2015 state layout: ``uint8 state``, ``string payload``
    (constants and comments aside), so the bulk state decoder applies."""
    fields = []
    for line in msgdef.split("\n"):
        text = line.split("#", 1)[0].strip()
        if text.startswith("==="):
            break
        if not text or "=" in text:
            continue
        fields.append(tuple(text.split()))
    return fields == [("uint8", "state"), ("string", "payload")]


def decode_states(buf: U8, start: I64, length: I64, cdr: bool) -> tuple[U8, list[str]]:
    """(state codes, payloads) of state messages (``uint8 state``, ``string payload``).

    Raises:
        LayoutMismatchError: the bytes do not have that layout.
    """
    n = len(start)
    if n == 0:
        return np.empty(0, np.uint8), []
    end = start + length
    if cdr:
        head = gather(buf, start, 2)
        if np.any(head[:, 1] != 1) or np.any(head[:, 0] != 0):
            raise LayoutMismatchError("not little-endian plain CDR")
        origin = start + 4
        state = gather(buf, origin, 1)[:, 0]
        size = read_at(buf, origin + 4, np.dtype("<u4")).astype(np.int64)
        text = origin + 8
        if np.any(size < 1):
            raise LayoutMismatchError("CDR string without terminator")
        tail = end - (text + size)
        if np.any(tail < 0) or np.any(tail > 3):  # up to 3 bytes of final padding
            raise LayoutMismatchError("state messages longer or shorter than their layout")
        size = size - 1
    else:
        state = gather(buf, start, 1)[:, 0]
        size = read_at(buf, start + 1, np.dtype("<u4")).astype(np.int64)
        text = start + 5
        if not np.array_equal(text + size, end):
            raise LayoutMismatchError("state messages longer or shorter than their layout")
    raw = buf.tobytes()
    payloads = [_utf8(raw[a : a + b]) for a, b in zip(text.tolist(), size.tolist(), strict=True)]
    return np.ascontiguousarray(state), payloads
