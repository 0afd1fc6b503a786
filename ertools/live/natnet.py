"""Decode (and encode) OptiTrack NatNet frame-of-mocap-data packets, NatNet 3.x and 4.x.

Only what a ground-truth logger needs is kept: the frame number, each rigid body's ID, position,
orientation, mean marker error and tracking-valid flag, and the frame's timestamps. Every other
section of the frame (marker sets, legacy markers, skeletons, assets, labeled markers, force
plates, devices) is walked over so that the rigid-body section and the suffix are found.

The layout follows the public NatNet SDK description (``NatNetClient.py`` of the SDK samples):

* header: ``int16`` message ID (7 = NAT_FRAMEOFDATA) and ``uint16`` payload size;
* NatNet >= 4.1 adds a byte count after every section's item count;
* NatNet >= 4.1 adds the asset section between skeletons and labeled markers;
* NatNet >= 4.0 adds the precision timestamp (two ``uint32``) to the suffix;
* NatNet >= 3.0 moved rigid-body markers out of the frame and added three ``uint64``
  hardware timestamps to the suffix.

A frame packet does not say which NatNet version wrote it (a client learns it from the server
info on the command port), so the version is either given or detected: the layouts of 3.x, 4.0
and 4.1+ differ in size, and only the right one consumes exactly the payload size the header
announces. A packet that no supported layout decodes exactly is undecodable:
:class:`UndecodablePacketError`, never another exception. Versions before 3.0 (rigid-body
markers inline) are not supported.
"""

from __future__ import annotations

import math
import struct
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

from ertools.frozen_dataclass import frozen_dataclass

NAT_FRAMEOFDATA = 7
HEADER = struct.Struct("<hH")
_I32 = struct.Struct("<i")
_RIGID_BODY = struct.Struct("<i3f4ffh")  # id, x y z, qx qy qz qw, mean error, params
_ASSET_MARKER = struct.Struct("<i3ffhf")  # id, x y z, size, params, residual
_LABELED_MARKER = _ASSET_MARKER  # same 26 bytes from 3.0 on
_VEC3 = struct.Struct("<3f")
_SUFFIX_HEAD = struct.Struct("<iid")  # timecode, timecode sub, timestamp (s, double)
_STAMPS = struct.Struct("<QQQ")  # camera mid-exposure, data received, transmit
_PRECISION = struct.Struct("<II")  # precision timestamp seconds, fraction
_PARAMS = struct.Struct("<h")

# Bit 0 of a rigid body's params: Motive tracked it in this frame.
TRACKING_VALID = 0x01


class UndecodablePacketError(ValueError):
    """A datagram that is not a NatNet frame of a supported version (truncated, garbage...)."""


@dataclass(frozen=True, order=True)
class NatNetVersion:
    """A NatNet bitstream version (major.minor)."""

    major: int
    minor: int

    @classmethod
    def parse(cls, text: str) -> NatNetVersion:
        """``"4.1"`` -> NatNetVersion(4, 1); raises ValueError on anything else."""
        parts = text.strip().split(".")
        if len(parts) < 2 or not all(p.isdigit() for p in parts[:2]):
            raise ValueError(f"NatNet version {text!r} is not MAJOR.MINOR (e.g. 4.1)")
        return cls(int(parts[0]), int(parts[1]))

    @property
    def supported(self) -> bool:
        return self.major in (3, 4)

    @property
    def has_byte_counts(self) -> bool:
        return (self.major, self.minor) >= (4, 1)

    @property
    def has_assets(self) -> bool:
        return (self.major, self.minor) >= (4, 1)

    @property
    def has_precision_timestamp(self) -> bool:
        return self.major >= 4

    def __str__(self) -> str:
        return f"{self.major}.{self.minor}"


# One representative per distinct frame layout, newest first (auto-detection order).
LAYOUTS: tuple[NatNetVersion, ...] = (
    NatNetVersion(4, 1),
    NatNetVersion(4, 0),
    NatNetVersion(3, 1),
)


@frozen_dataclass
class RigidBody:
    """One rigid body of a frame, in Motive's world frame (metres, quaternion x y z w)."""

    body_id: int
    position: tuple[float, float, float]
    orientation_xyzw: tuple[float, float, float, float]
    mean_error: float = 0.0
    params: int = TRACKING_VALID

    @property
    def tracking_valid(self) -> bool:
        return bool(self.params & TRACKING_VALID)


@frozen_dataclass
class FrameOfData:
    """The parts of a NAT_FRAMEOFDATA packet a logger needs.

    ``timestamp_s`` is Motive's frame time (seconds since Motive started); the ``stamp_*``
    fields are the camera hardware clock ticks of NatNet >= 3.0 (0 when absent).
    """

    frame_number: int
    rigid_bodies: tuple[RigidBody, ...]
    timestamp_s: float = 0.0
    timecode: int = 0
    timecode_sub: int = 0
    stamp_camera_mid_exposure: int = 0
    stamp_data_received: int = 0
    stamp_transmit: int = 0
    precision_timestamp_s: int = 0
    precision_timestamp_frac: int = 0
    params: int = 0


@frozen_dataclass
class FrameExtras:
    """The sections a logger skips, for the encoder (to test that skipping finds the bodies).

    Attributes:
        marker_sets: (name, marker positions) per marker set.
        other_markers: legacy unlabeled marker positions.
        skeletons: (skeleton id, its rigid bodies) per skeleton.
        assets: (asset id, its rigid bodies, number of markers) per asset (NatNet >= 4.1).
        labeled_markers: number of labeled markers to emit.
        force_plates: (id, channels of float samples) per plate.
        devices: (id, channels of float samples) per device.
    """

    marker_sets: tuple[tuple[str, tuple[tuple[float, float, float], ...]], ...] = ()
    other_markers: tuple[tuple[float, float, float], ...] = ()
    skeletons: tuple[tuple[int, tuple[RigidBody, ...]], ...] = ()
    assets: tuple[tuple[int, tuple[RigidBody, ...], int], ...] = ()
    labeled_markers: int = 0
    force_plates: tuple[tuple[int, tuple[tuple[float, ...], ...]], ...] = ()
    devices: tuple[tuple[int, tuple[tuple[float, ...], ...]], ...] = ()


def message_id(datagram: bytes) -> int | None:
    """The NatNet message ID of a datagram, or None when it is shorter than a header."""
    if len(datagram) < HEADER.size:
        return None
    return int(HEADER.unpack_from(datagram)[0])


class _Cursor:
    """Bounds-checked reading: every short read is an UndecodablePacketError, never IndexError."""

    def __init__(self, data: memoryview, start: int, end: int) -> None:
        self.data = data
        self.pos = start
        self.end = end

    def unpack(self, fmt: struct.Struct) -> tuple[Any, ...]:
        if self.pos + fmt.size > self.end:
            raise UndecodablePacketError(f"truncated at byte {self.pos} (needs {fmt.size} more)")
        values = fmt.unpack_from(self.data, self.pos)
        self.pos += fmt.size
        return values

    def count(self, what: str, min_item_size: int) -> int:
        (n,) = self.unpack(_I32)
        # A count that cannot fit in what is left is garbage: refuse it before looping on it.
        if n < 0 or n * min_item_size > self.end - self.pos:
            raise UndecodablePacketError(f"impossible {what} count {n} at byte {self.pos - 4}")
        return int(n)

    def skip(self, nbytes: int) -> None:
        if nbytes < 0 or self.pos + nbytes > self.end:
            raise UndecodablePacketError(
                f"section of {nbytes} bytes overruns the packet at {self.pos}"
            )
        self.pos += nbytes

    def cstring(self) -> None:
        idx = bytes(self.data[self.pos : self.end]).find(b"\0")
        if idx < 0:
            raise UndecodablePacketError(f"unterminated name at byte {self.pos}")
        self.pos += idx + 1


def _rigid_body(c: _Cursor) -> RigidBody:
    bid, x, y, z, qx, qy, qz, qw, err, params = c.unpack(_RIGID_BODY)
    return RigidBody(
        body_id=int(bid),
        position=(float(x), float(y), float(z)),
        orientation_xyzw=(float(qx), float(qy), float(qz), float(qw)),
        mean_error=float(err),
        params=int(params),
    )


def _section(c: _Cursor, v: NatNetVersion, what: str, min_item: int) -> tuple[int, int | None]:
    """Item count, and for NatNet >= 4.1 the section's end offset from its byte count."""
    n = c.count(what, min_item)
    if not v.has_byte_counts:
        return n, None
    (size,) = c.unpack(_I32)
    if size < 0 or c.pos + size > c.end:
        raise UndecodablePacketError(f"{what} byte count {size} overruns the packet")
    return n, c.pos + size


def _close_section(c: _Cursor, end: int | None, what: str) -> None:
    if end is not None and c.pos != end:
        raise UndecodablePacketError(f"{what} section is {c.pos - end:+d} bytes off its byte count")


def _skip_channels(c: _Cursor, version: NatNetVersion, what: str) -> None:
    n, end = _section(c, version, what, 8)
    for _ in range(n):
        c.unpack(_I32)  # id
        channels = c.count(f"{what} channel", 4)
        for _ in range(channels):
            frames = c.count(f"{what} sample", 4)
            c.skip(4 * frames)
    _close_section(c, end, what)


def decode_frame(datagram: bytes, version: NatNetVersion) -> FrameOfData:
    """Decode a NAT_FRAMEOFDATA datagram written with NatNet ``version``.

    Raises:
        UndecodablePacketError: not a frame, an unsupported version, truncated, or a layout that
            does not consume exactly the payload size of the header (the wrong version).
    """
    if not version.supported:
        raise UndecodablePacketError(f"NatNet {version} is not supported (3.x and 4.x are)")
    mid = message_id(datagram)
    if mid != NAT_FRAMEOFDATA:
        raise UndecodablePacketError(f"message ID {mid} is not a frame of data ({NAT_FRAMEOFDATA})")
    _, size = HEADER.unpack_from(datagram)
    end = HEADER.size + int(size)
    if len(datagram) < end:
        raise UndecodablePacketError(f"datagram of {len(datagram)} bytes, header announces {end}")
    c = _Cursor(memoryview(datagram), HEADER.size, end)

    (frame_number,) = c.unpack(_I32)

    n, sec_end = _section(c, version, "marker set", 5)
    for _ in range(n):
        c.cstring()
        c.skip(_VEC3.size * c.count("marker", _VEC3.size))
    _close_section(c, sec_end, "marker set")

    n, sec_end = _section(c, version, "legacy marker", _VEC3.size)
    c.skip(_VEC3.size * n)
    _close_section(c, sec_end, "legacy marker")

    n, sec_end = _section(c, version, "rigid body", _RIGID_BODY.size)
    bodies = tuple(_rigid_body(c) for _ in range(n))
    _close_section(c, sec_end, "rigid body")

    n, sec_end = _section(c, version, "skeleton", 8)
    for _ in range(n):
        c.unpack(_I32)
        c.skip(_RIGID_BODY.size * c.count("skeleton rigid body", _RIGID_BODY.size))
    _close_section(c, sec_end, "skeleton")

    if version.has_assets:
        n, sec_end = _section(c, version, "asset", 12)
        for _ in range(n):
            c.unpack(_I32)
            c.skip(_RIGID_BODY.size * c.count("asset rigid body", _RIGID_BODY.size))
            c.skip(_ASSET_MARKER.size * c.count("asset marker", _ASSET_MARKER.size))
        _close_section(c, sec_end, "asset")

    n, sec_end = _section(c, version, "labeled marker", _LABELED_MARKER.size)
    c.skip(_LABELED_MARKER.size * n)
    _close_section(c, sec_end, "labeled marker")

    _skip_channels(c, version, "force plate")
    _skip_channels(c, version, "device")

    timecode, timecode_sub, timestamp = c.unpack(_SUFFIX_HEAD)
    stamps = c.unpack(_STAMPS)
    precision: tuple[Any, ...] = (0, 0)
    if version.has_precision_timestamp:
        precision = c.unpack(_PRECISION)
    (params,) = c.unpack(_PARAMS)
    if c.pos != end:
        raise UndecodablePacketError(
            f"{end - c.pos} bytes left after the frame suffix: not a NatNet {version} frame"
        )
    return FrameOfData(
        frame_number=int(frame_number),
        rigid_bodies=bodies,
        timestamp_s=float(timestamp),
        timecode=int(timecode),
        timecode_sub=int(timecode_sub),
        stamp_camera_mid_exposure=int(stamps[0]),
        stamp_data_received=int(stamps[1]),
        stamp_transmit=int(stamps[2]),
        precision_timestamp_s=int(precision[0]),
        precision_timestamp_frac=int(precision[1]),
        params=int(params),
    )


def detect_version(datagram: bytes) -> tuple[NatNetVersion, FrameOfData]:
    """The layout (newest first) that decodes ``datagram`` exactly, and the frame.

    Raises:
        UndecodablePacketError: when no supported layout fits.
    """
    reasons = []
    for version in LAYOUTS:
        try:
            return version, decode_frame(datagram, version)
        except UndecodablePacketError as err:
            reasons.append(f"{version}: {err}")
    raise UndecodablePacketError("no NatNet 3.x/4.x layout fits (" + "; ".join(reasons) + ")")


@dataclass
class FrameDecoder:
    """Decodes a stream of datagrams; with ``version=None`` the first frame picks the layout.

    Once detected the version is kept, so a later packet of another layout is undecodable
    rather than silently decoded differently.
    """

    version: NatNetVersion | None = None
    detected: bool = field(default=False, init=False)

    def decode(self, datagram: bytes) -> FrameOfData:
        if self.version is None:
            self.version, frame = detect_version(datagram)
            self.detected = True
            return frame
        return decode_frame(datagram, self.version)


# --------------------------------------------------------------------------- encoder


def _pack_rigid_body(b: RigidBody) -> bytes:
    return _RIGID_BODY.pack(b.body_id, *b.position, *b.orientation_xyzw, b.mean_error, b.params)


def _pack_section(version: NatNetVersion, count: int, body: bytes) -> bytes:
    head = _I32.pack(count)
    if version.has_byte_counts:
        head += _I32.pack(len(body))
    return head + body


def _pack_channels(
    version: NatNetVersion, items: Sequence[tuple[int, tuple[tuple[float, ...], ...]]]
) -> bytes:
    body = b""
    for item_id, channels in items:
        body += _I32.pack(item_id) + _I32.pack(len(channels))
        for samples in channels:
            body += _I32.pack(len(samples)) + struct.pack(f"<{len(samples)}f", *samples)
    return _pack_section(version, len(items), body)


def encode_frame(
    frame: FrameOfData, version: NatNetVersion, extras: FrameExtras | None = None
) -> bytes:
    """A NAT_FRAMEOFDATA datagram as Motive streams it with NatNet ``version``.

    For the simulated Motive of the tests and ``ertools record --simulate``.
    """
    if not version.supported:
        raise ValueError(f"NatNet {version} is not supported (3.x and 4.x are)")
    x = extras or FrameExtras()
    parts = [_I32.pack(frame.frame_number)]
    body = b""
    for name, markers in x.marker_sets:
        body += name.encode("utf-8") + b"\0" + _I32.pack(len(markers))
        body += b"".join(_VEC3.pack(*m) for m in markers)
    parts.append(_pack_section(version, len(x.marker_sets), body))
    body = b"".join(_VEC3.pack(*m) for m in x.other_markers)
    parts.append(_pack_section(version, len(x.other_markers), body))
    body = b"".join(_pack_rigid_body(b) for b in frame.rigid_bodies)
    parts.append(_pack_section(version, len(frame.rigid_bodies), body))
    body = b"".join(
        _I32.pack(sid) + _I32.pack(len(rbs)) + b"".join(_pack_rigid_body(b) for b in rbs)
        for sid, rbs in x.skeletons
    )
    parts.append(_pack_section(version, len(x.skeletons), body))
    if version.has_assets:
        body = b""
        for aid, rbs, n_markers in x.assets:
            body += _I32.pack(aid) + _I32.pack(len(rbs)) + b"".join(map(_pack_rigid_body, rbs))
            body += _I32.pack(n_markers) + b"".join(
                _ASSET_MARKER.pack(i, 0.1 * i, 0.0, 0.0, 0.014, 0, 0.0) for i in range(n_markers)
            )
        parts.append(_pack_section(version, len(x.assets), body))
    body = b"".join(
        _LABELED_MARKER.pack((1 << 16) | i, 0.01 * i, 1.0, 2.0, 0.014, 0, 0.0001)
        for i in range(x.labeled_markers)
    )
    parts.append(_pack_section(version, x.labeled_markers, body))
    parts.append(_pack_channels(version, x.force_plates))
    parts.append(_pack_channels(version, x.devices))
    parts.append(_SUFFIX_HEAD.pack(frame.timecode, frame.timecode_sub, frame.timestamp_s))
    parts.append(
        _STAMPS.pack(
            frame.stamp_camera_mid_exposure, frame.stamp_data_received, frame.stamp_transmit
        )
    )
    if version.has_precision_timestamp:
        parts.append(_PRECISION.pack(frame.precision_timestamp_s, frame.precision_timestamp_frac))
    parts.append(_PARAMS.pack(frame.params))
    payload = b"".join(parts)
    if len(payload) > 0xFFFF:
        raise ValueError(f"frame payload of {len(payload)} bytes does not fit a NatNet packet")
    return HEADER.pack(NAT_FRAMEOFDATA, len(payload)) + payload


def quat_is_finite(q: tuple[float, float, float, float]) -> bool:
    """A usable orientation: finite and not all zero (Motive sends zeros for unknown bodies)."""
    return all(math.isfinite(v) for v in q) and any(v != 0.0 for v in q)
