"""Bulk serialisation for :class:`ertools.simulator.writer.BagWriter`: fixed-layout messages packed
with NumPy (ROS1 and CDR), the rosbags typestore of every type the simulator writes, and the
array helpers the writer's calls share. No file, clock or random source is touched here.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
import numpy.typing as npt

from ertools.arrays import F64, I64, U8
from ertools.states import MSG_DEFINITIONS, MSG_TYPES

# tf2_msgs/TFMessage is not in rosbags' Noetic store; its definition is one line.
_TF_MESSAGE = "geometry_msgs/TransformStamped[] transforms\n"

NS_PER_S = 1_000_000_000


def typestore(ros2: bool) -> Any:
    """A rosbags typestore with every type the simulator writes (cached per process)."""
    key = "ros2" if ros2 else "ros1"
    cached = _STORES.get(key)
    if cached is not None:
        return cached
    from rosbags.typesys import Stores, get_types_from_msg, get_typestore  # lazy: rosbags, 100 ms

    store = get_typestore(Stores.ROS2_HUMBLE if ros2 else Stores.ROS1_NOETIC)
    types: dict[str, Any] = {}
    if not ros2:
        types.update(get_types_from_msg(_TF_MESSAGE, "tf2_msgs/msg/TFMessage"))
    for machine, text in MSG_DEFINITIONS.items():
        types.update(get_types_from_msg(text, rosbags_name(MSG_TYPES[machine])))
    store.register(types)
    _STORES[key] = store
    return store


_STORES: dict[str, Any] = {}


def rosbags_name(name: str) -> str:
    """``pkg/Type`` -> ``pkg/msg/Type`` (rosbags' normalised spelling)."""
    pkg, _, base = name.rpartition("/")
    return name if pkg.endswith("/msg") else f"{pkg}/msg/{base}"


def split_time(t_ns: npt.ArrayLike) -> tuple[I64, I64]:
    """int64 ns -> (sec, nsec) arrays as ROS stores them."""
    t = np.asarray(t_ns, dtype=np.int64)
    return t // NS_PER_S, t % NS_PER_S


# --------------------------------------------------------------------------- bulk packing

Field = tuple[str, Any]  # ("u4"|"i4"|"f8", array (N,) or (N,k)) or ("str", str)


def pack_messages(n: int, fields: Sequence[Field], *, cdr: bool) -> U8:
    """Serialise ``n`` messages of a fixed layout into an (n, size) byte array in one go.

    ROS1 is packed little-endian with no padding and strings as ``uint32 len + bytes``. CDR
    (ROS 2) starts with the 4-byte little-endian encapsulation header, aligns every primitive
    to its size relative to the end of that header, and NUL-terminates strings (the length
    counts the NUL). Tests check the output byte for byte against rosbags' serialisers.
    """
    base = 4 if cdr else 0
    offsets: list[int] = []
    pos = base
    for kind, value in fields:
        width = 8 if kind == "f8" else 4
        if cdr:
            pos += -(pos - base) % width
        offsets.append(pos)
        if kind == "str":
            pos += 4 + len(value.encode()) + (1 if cdr else 0)
        else:
            cols = 1 if np.ndim(value) <= 1 else int(np.shape(value)[-1])
            pos += width * cols
    buf = np.zeros((n, pos), dtype=np.uint8)
    if cdr:
        buf[:, :4] = np.frombuffer(b"\x00\x01\x00\x00", dtype=np.uint8)
    for (kind, value), off in zip(fields, offsets, strict=True):
        if kind == "str":
            raw = value.encode() + (b"\x00" if cdr else b"")
            head = np.frombuffer(np.uint32(len(raw)).tobytes() + raw, dtype=np.uint8)
            buf[:, off : off + head.size] = head
            continue
        dtype = {"u4": "<u4", "i4": "<i4", "f8": "<f8"}[kind]
        arr = np.ascontiguousarray(
            np.broadcast_to(np.asarray(value, dtype=dtype), _shape(n, value))
        )
        raw_cols = arr.reshape(n, -1).view(np.uint8)
        buf[:, off : off + raw_cols.shape[1]] = raw_cols
    return buf


def _shape(n: int, value: Any) -> tuple[int, ...]:
    return (n,) if np.ndim(value) <= 1 else (n, int(np.shape(value)[-1]))


def as_bytes(row: Any) -> bytes:
    return row if isinstance(row, bytes) else bytes(row.tobytes())


def broadcast_rows(
    t_record_ns: npt.ArrayLike, t_header_ns: npt.ArrayLike, xyz: npt.ArrayLike, quat: npt.ArrayLike
) -> tuple[I64, I64, F64, F64]:
    """Broadcast scalar/array inputs to (N,), (N,), (N,3), (N,4)."""
    t_rec = np.atleast_1d(np.asarray(t_record_ns, dtype=np.int64))
    t_hdr = np.atleast_1d(np.asarray(t_header_ns, dtype=np.int64))
    n = max(t_rec.size, t_hdr.size)
    t_rec = np.broadcast_to(t_rec, (n,)).copy()
    t_hdr = np.broadcast_to(t_hdr, (n,)).copy()
    xyz_a = np.broadcast_to(np.asarray(xyz, dtype=np.float64), (n, 3))
    quat_a = np.broadcast_to(np.asarray(quat, dtype=np.float64), (n, 4))
    return t_rec, t_hdr, xyz_a, quat_a
