"""Helpers of the live-side tests: a fake SNTP server, a free UDP port, an MCAP read-back.

A uniquely named module (test folders have no __init__.py, so no relative imports).

Everything network-related stays on 127.0.0.1 and stops by itself (bounded counts, timeouts).
"""

from __future__ import annotations

import socket
import struct
import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

from mcap.reader import NonSeekingReader
from rosbags.typesys import Stores, get_typestore

NTP_DELTA = 2_208_988_800


def _ntp(t_ns: int) -> tuple[int, int]:
    sec, rem = divmod(t_ns, 1_000_000_000)
    return sec + NTP_DELTA, (rem << 32) // 1_000_000_000


@contextmanager
def fake_sntp_server(
    offset_s: float, *, stratum: int = 2, leap: int = 0, echo: bool = True, max_requests: int = 20
) -> Iterator[int]:
    """An SNTP server on 127.0.0.1 whose clock is the local clock + ``offset_s``.

    Written independently of ertools.live.clock (RFC 4330 layout) so the test checks the
    client against the protocol, not against itself. Yields the port.
    """
    sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    sock.bind(("127.0.0.1", 0))
    sock.settimeout(0.1)
    port = sock.getsockname()[1]
    stop = threading.Event()
    offset_ns = round(offset_s * 1e9)

    def serve() -> None:
        served = 0
        while not stop.is_set() and served < max_requests:
            try:
                request, peer = sock.recvfrom(512)
            except TimeoutError:
                continue
            t2 = time.time_ns() + offset_ns
            origin = request[40:48] if echo else b"\x01" * 8
            t3 = time.time_ns() + offset_ns
            reply = (
                struct.pack("!BBbb", (leap << 6) | (4 << 3) | 4, stratum, 4, -20)
                + struct.pack("!II", 0, 0)
                + b"LOCL"
                + struct.pack("!II", *_ntp(t2))
                + origin
                + struct.pack("!II", *_ntp(t2))
                + struct.pack("!II", *_ntp(t3))
            )
            sock.sendto(reply, peer)
            served += 1

    thread = threading.Thread(target=serve, daemon=True)
    thread.start()
    try:
        yield port
    finally:
        stop.set()
        thread.join(timeout=2)
        sock.close()


def free_udp_port() -> int:
    """A UDP port free on 127.0.0.1 right now (for a recorder in a subprocess)."""
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def read_mcap(path: Path) -> tuple[list[tuple[str, int, Any]], bool]:
    """(topic, log_time, decoded message) of every readable message, and whether the read hit
    the end cleanly. Uses mcap's non-seeking reader, which reads a file cut short up to the
    record the cut falls in (then raises; the messages before are kept).
    """

    store = get_typestore(Stores.ROS2_HUMBLE)
    out: list[tuple[str, int, Any]] = []
    clean = True
    with open(path, "rb") as f:
        reader = NonSeekingReader(f)
        try:
            # log_time_order=False: the default sorts everything first, so the exception at
            # the cut would lose every message.
            for schema, channel, message in reader.iter_messages(log_time_order=False):
                msg = store.deserialize_cdr(message.data, schema.name)
                out.append((channel.topic, message.log_time, msg))
        except Exception:  # the truncated tail
            clean = False
    return out, clean
