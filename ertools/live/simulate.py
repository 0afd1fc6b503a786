"""A simulated Motive: streams NatNet frames of bodies on known paths, for tests and demos.

Bodies drive circles (yaw along the tangent) so every pose is known in advance. A body can be
untracked for a span of frames (Motive then streams it with the tracking-valid flag off and its
last pose), frames can be skipped (a network drop: a gap in frame numbers) and malformed
packets inserted. Sending is paced at ``rate_hz``, bounded by the frame count, and stops early
when ``stop`` is set.
"""

from __future__ import annotations

import math
import socket
import struct
import threading
import time
from dataclasses import dataclass, field

from ertools.frozen_dataclass import frozen_dataclass
from ertools.live.natnet import (
    TRACKING_VALID,
    FrameExtras,
    FrameOfData,
    NatNetVersion,
    RigidBody,
    encode_frame,
)

_F32 = struct.Struct("<f")


def f32(value: float) -> float:
    """``value`` rounded to float32, as it travels in a NatNet packet."""
    return float(_F32.unpack(_F32.pack(value))[0])


@frozen_dataclass
class SimulatedBody:
    """A rigid body on a circle of ``radius`` around (cx, cy) at height ``z``.

    ``untracked`` is a half-open frame-number range [first, last) with tracking lost.
    """

    body_id: int
    radius: float = 1.0
    center: tuple[float, float] = (0.0, 0.0)
    z: float = 0.3
    period_s: float = 10.0
    phase: float = 0.0
    untracked: tuple[int, int] | None = None

    def pose(self, t_s: float) -> tuple[tuple[float, float, float], tuple[float, ...]]:
        a = self.phase + 2.0 * math.pi * t_s / self.period_s
        x = self.center[0] + self.radius * math.cos(a)
        y = self.center[1] + self.radius * math.sin(a)
        yaw = a + math.pi / 2.0  # heading along the tangent
        q = (0.0, 0.0, math.sin(yaw / 2.0), math.cos(yaw / 2.0))
        return (f32(x), f32(y), f32(self.z)), tuple(f32(v) for v in q)


def make_frame(
    frame_number: int, t_s: float, bodies: tuple[SimulatedBody, ...], last: dict[int, RigidBody]
) -> FrameOfData:
    """The frame Motive would stream at ``t_s`` (untracked bodies keep their last pose)."""
    rbs = []
    for b in bodies:
        lost = b.untracked is not None and b.untracked[0] <= frame_number < b.untracked[1]
        if lost and b.body_id in last:
            prev = last[b.body_id]
            rbs.append(RigidBody(b.body_id, prev.position, prev.orientation_xyzw, 0.0, 0))
            continue
        xyz, q = b.pose(t_s)
        rb = RigidBody(
            body_id=b.body_id,
            position=xyz,
            orientation_xyzw=(q[0], q[1], q[2], q[3]),
            mean_error=f32(0.0002 + 0.0001 * (frame_number % 3)),
            params=0 if lost else TRACKING_VALID,
        )
        last[b.body_id] = rb
        rbs.append(rb)
    return FrameOfData(
        frame_number=frame_number,
        rigid_bodies=tuple(rbs),
        timestamp_s=t_s,
        stamp_transmit=int(t_s * 1e7),
    )


@dataclass
class SimulatedMotive:
    """Sends ``n_frames`` frames to ``target`` (unicast, or a multicast group).

    Attributes:
        sent: every frame actually sent, in order (the ground truth).
        malformed_sent: how many malformed datagrams were sent.
    """

    target: tuple[str, int]
    bodies: tuple[SimulatedBody, ...]
    n_frames: int = 200
    rate_hz: float = 100.0
    version: NatNetVersion = field(default_factory=lambda: NatNetVersion(4, 1))
    extras: FrameExtras | None = None
    malformed_at: tuple[int, ...] = ()  # frame numbers after which a malformed packet goes
    skip: tuple[int, ...] = ()  # frame numbers never sent (a drop)
    multicast_interface: str | None = None
    first_frame: int = 1000
    stop: threading.Event = field(default_factory=threading.Event)
    sent: list[FrameOfData] = field(default_factory=list)
    malformed_sent: int = 0

    def run(self) -> None:
        with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as sock:
            if self.multicast_interface is not None:
                sock.setsockopt(
                    socket.IPPROTO_IP,
                    socket.IP_MULTICAST_IF,
                    socket.inet_aton(self.multicast_interface),
                )
                sock.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_LOOP, 1)
            last: dict[int, RigidBody] = {}
            t0 = time.monotonic()
            for k in range(self.n_frames):
                if self.stop.is_set():
                    break
                delay = t0 + k / self.rate_hz - time.monotonic()
                if delay > 0:
                    time.sleep(delay)
                number = self.first_frame + k
                frame = make_frame(number, k / self.rate_hz, self.bodies, last)
                if number in self.skip:
                    continue
                sock.sendto(encode_frame(frame, self.version, self.extras), self.target)
                self.sent.append(frame)
                if number in self.malformed_at:
                    packet = encode_frame(frame, self.version, self.extras)
                    sock.sendto(packet[: len(packet) // 2], self.target)  # cut short
                    self.malformed_sent += 1

    def start(self) -> threading.Thread:
        thread = threading.Thread(target=self.run, name="simulated-motive", daemon=True)
        thread.start()
        return thread
