"""SNTP clock check: how far the local clock is from an NTP server (RFC 4330, one query).

The 2015 system kept every machine on the Referee Box's clock with chrony (seed 3.4, Listing 1)
and logged with the host clock. This module does not set the clock; it measures it, so that
``ertools clock`` can tell an operator before a run whether chrony did its job, and the recorder
can write the offset into each file for the scorers to check later.

One request is a 48-byte packet built by hand. With t1 = our transmit time, t2 = the server's
receive time, t3 = the server's transmit time and t4 = our receive time::

    offset = ((t2 - t1) + (t3 - t4)) / 2     (server clock minus local clock)
    delay  = (t4 - t1) - (t3 - t2)

The error of ``offset`` is at most ``delay / 2`` (when the path is asymmetric).
"""

from __future__ import annotations

import socket
import struct
import time
from collections.abc import Callable

from ertools.errors import ClockError
from ertools.frozen_dataclass import frozen_dataclass
from ertools.timeutil import iso_utc

NTP_PORT = 123
# Seconds from the NTP era 0 epoch (1900-01-01) to the Unix epoch (1970-01-01).
NTP_UNIX_DELTA_S = 2_208_988_800
_PACKET = struct.Struct("!BBbb11I")  # LI/VN/mode, stratum, poll, precision, 11 words
PACKET_SIZE = 48
MODE_CLIENT = 3
MODE_SERVER = 4
MODE_BROADCAST = 5
LEAP_ALARM = 3


def ns_to_ntp(t_ns: int) -> tuple[int, int]:
    """Unix nanoseconds -> (NTP seconds, 32-bit fraction)."""
    sec, rem = divmod(t_ns, 1_000_000_000)
    return (sec + NTP_UNIX_DELTA_S) & 0xFFFFFFFF, (rem << 32) // 1_000_000_000


def ntp_to_ns(seconds: int, fraction: int) -> int:
    """(NTP seconds, fraction) -> Unix nanoseconds (era 0: 1900 to 2036)."""
    return (seconds - NTP_UNIX_DELTA_S) * 1_000_000_000 + ((fraction * 1_000_000_000) >> 32)


@frozen_dataclass
class ClockCheck:
    """The result of one SNTP exchange.

    Attributes:
        server: host queried; port: its UDP port.
        offset_s: server clock minus local clock (positive: the local clock is behind).
        delay_s: round-trip delay; ``offset_s`` is within ``delay_s / 2`` of the truth.
        stratum: the server's stratum (1 = primary reference).
        measured_at_ns: local Unix time of the exchange.
    """

    server: str
    port: int
    offset_s: float
    delay_s: float
    stratum: int
    measured_at_ns: int

    def within(self, tolerance_s: float) -> bool:
        return abs(self.offset_s) <= tolerance_s

    def describe(self) -> str:
        return (
            f"offset {self.offset_s:+.6f} s, delay {self.delay_s:.6f} s, "
            f"stratum {self.stratum}, server {self.server}:{self.port}"
        )

    def to_metadata(self) -> dict[str, str]:
        """Key/value strings for an MCAP metadata record."""

        return {
            "ntp_server": f"{self.server}:{self.port}",
            "status": "ok",
            "offset_s": f"{self.offset_s:.9f}",
            "delay_s": f"{self.delay_s:.9f}",
            "stratum": str(self.stratum),
            "measured_at": iso_utc(self.measured_at_ns),
            "measured_at_ns": str(self.measured_at_ns),
        }


def build_request(transmit_ns: int) -> bytes:
    """A client request (LI 0, version 4, mode 3) carrying our transmit time."""
    sec, frac = ns_to_ntp(transmit_ns)
    words = [0] * 11
    words[9], words[10] = sec, frac
    return _PACKET.pack((0 << 6) | (4 << 3) | MODE_CLIENT, 0, 0, 0, *words)


def parse_reply(
    reply: bytes, request: bytes, t1_ns: int, t4_ns: int, server: str, port: int
) -> ClockCheck:
    """Check a server reply against our request and compute offset and delay.

    Raises:
        ClockError: a short, foreign (originate mismatch), unsynchronised or kiss-o'-death reply.
    """
    where = f"NTP server {server}:{port}"
    if len(reply) < PACKET_SIZE:
        raise ClockError(f"{where} sent a {len(reply)}-byte reply, expected {PACKET_SIZE}")
    first, stratum, _poll, _prec, *words = _PACKET.unpack_from(reply)
    leap, mode = first >> 6, first & 0x7
    if mode not in (MODE_SERVER, MODE_BROADCAST):
        raise ClockError(f"{where} replied with NTP mode {mode}, not a server reply")
    # The originate field must echo our transmit field: anything else answers someone else.
    if reply[24:32] != request[40:48]:
        raise ClockError(f"{where} reply does not answer our request (originate mismatch)")
    if stratum == 0:
        code = reply[12:16].decode("ascii", "replace")
        raise ClockError(f"{where} refused the request (kiss-o'-death {code!r}); retry later")
    if leap == LEAP_ALARM:
        raise ClockError(f"{where} says its own clock is not synchronised (leap indicator 3)")
    # Words after the 4 leading bytes: root delay, root dispersion, reference ID, reference
    # (3-4), originate (5-6), receive (7-8) and transmit (9-10) timestamps.
    t2 = ntp_to_ns(words[7], words[8])
    t3 = ntp_to_ns(words[9], words[10])
    if words[9] == 0 and words[10] == 0:
        raise ClockError(f"{where} sent no transmit timestamp")
    offset_ns = ((t2 - t1_ns) + (t3 - t4_ns)) / 2
    delay_ns = (t4_ns - t1_ns) - (t3 - t2)
    return ClockCheck(
        server=server,
        port=port,
        offset_s=offset_ns / 1e9,
        delay_s=max(delay_ns, 0) / 1e9,
        stratum=int(stratum),
        measured_at_ns=t1_ns,
    )


def query_sntp(
    server: str,
    port: int = NTP_PORT,
    *,
    timeout_s: float = 2.0,
    clock: Callable[[], int] = time.time_ns,
) -> ClockCheck:
    """One SNTP exchange with ``server``.

    Raises:
        ClockError: unreachable (timeout, unknown host, network error) or a bad reply.
    """
    where = f"NTP server {server}:{port}"
    try:
        infos = socket.getaddrinfo(server, port, socket.AF_INET, socket.SOCK_DGRAM)
    except (socket.gaierror, UnicodeError) as err:
        raise ClockError(f"{where}: unknown host ({err})") from err
    address = infos[0][4]
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as sock:
        sock.settimeout(timeout_s)
        t1 = clock()
        request = build_request(t1)
        try:
            sock.sendto(request, address)
            deadline = time.monotonic() + timeout_s
            while True:
                reply, peer = sock.recvfrom(1024)
                t4 = clock()
                if peer[0] == address[0]:
                    break
                if time.monotonic() > deadline:  # pragma: no cover - only stray datagrams
                    raise TimeoutError
        except TimeoutError:
            raise ClockError(
                f"{where} unreachable: no reply within {timeout_s:g} s (is the host up and "
                "serving NTP on that port?)"
            ) from None
        except OSError as err:
            raise ClockError(f"{where} unreachable: {err.strerror or err}") from err
    return parse_reply(reply, request, t1, t4, server, port)


def unreachable_metadata(server: str, port: int, reason: str) -> dict[str, str]:
    """The metadata written when the offset could not be measured (recording goes on)."""
    return {"ntp_server": f"{server}:{port}", "status": f"unreachable: {reason}"}
