"""Record OptiTrack NatNet rigid bodies into MCAP files, as the 2015 GT logger did with ROS.

2015: Motive -> mocap_optitrack (NatNet -> PoseStamped, Pose2D, tf) -> rosbag record --split.
Here one loop does all three without ROS: receive a datagram, decode its rigid bodies, write a
``PoseStamped``, a ``Pose2D`` and a ``tf2_msgs/TFMessage`` per configured, tracked body, stamped
with the host clock at receipt (the 2015 node stamped ``ros::Time::now()``; NTP keeps the host
clock on the Referee Box's). On Linux the kernel's arrival stamp is used (SO_TIMESTAMPNS).

Differences from 2015, on purpose:
* a body whose tracking-valid flag is off is not written (mocap_optitrack republished whatever
  Motive sent); the frames are counted as untracked;
* the files are MCAP (ROS 2 CDR messages), not ROS 1 bags, and survive a crash up to the last
  flush (at most ``flush_interval_s``, default 0.5 s);
* each file carries metadata: the recorder's settings, the NTP offset measured when the file was
  opened, and at close the file's counters (frames, drops, undecodable packets, untracked).

The loop is single-threaded and never blocks longer than the socket timeout (0.1 s), so
flushing, splitting and health lines happen on time even when no data arrives; only the NTP
query at a split blocks longer (at most ``ntp_timeout_s``), while datagrams wait in the socket
buffer with their kernel arrival stamps.
"""

from __future__ import annotations

import contextlib
import platform
import socket
import struct
import sys
import threading
import time
from collections.abc import Callable
from dataclasses import field
from pathlib import Path

from ertools._version import __version__
from ertools.configs.mocap import MocapConfig, RigidBodyConfig, normalize_namespace
from ertools.errors import BagError, ConfigError, ErtoolsError
from ertools.frozen_dataclass import frozen_dataclass
from ertools.live.clock import query_sntp, unreachable_metadata
from ertools.live.logfile import LogFile, log_file_name
from ertools.live.natnet import (
    HEADER,
    FrameDecoder,
    FrameOfData,
    NatNetVersion,
    UndecodablePacketError,
    message_id,
    quat_is_finite,
)
from ertools.live.rosmsg import POSE_2D, POSE_STAMPED, TF_MESSAGE, Ros2Serializer, yaw_of
from ertools.live.stats import BodyCounters, RecorderStats

Report = Callable[[str], None]
UP_AXES = ("z", "y")
# NatNet message IDs other than NAT_FRAMEOFDATA (7): connect, server info, request, response,
# model definition requests and replies, message strings, disconnect, keep-alive, unrecognized.
OTHER_MESSAGE_IDS = frozenset({0, 1, 2, 3, 4, 5, 6, 8, 9, 10, 100})


@frozen_dataclass
class RecordOptions:
    """How and where to record.

    Attributes:
        out_dir: folder for the MCAP files (created if missing).
        name: file name part: ``log_<name>_<stamp>_<n>.mcap``.
        namespace: prefix of relative topics (``/fbm2h``), "" for none.
        group: multicast group to join, or None to receive unicast.
        port: UDP data port (NatNet: 1511); 0 picks a free one (tests).
        interface: local address to join the group on / bind to ("0.0.0.0": any).
        split_s: start a new file every this many seconds (2015: hourly).
        duration_s: stop after this long (None: until stopped).
        ntp_server, ntp_port: where to measure the clock offset at every file start.
        natnet_version: the stream's NatNet version, None to detect it from the first frame.
        up_axis: ``z`` writes Motive's coordinates unchanged (Motive streaming "Up Axis: Z");
            ``y`` maps Motive's default Y-up frame to a Z-up one as mocap_optitrack did for
            Motive >= 1.7: (x, y, z) -> (-x, z, y).
        flush_interval_s: chunk flush period: the most a crash can lose.
        health_interval_s: period of the health line.
        fsync: fsync at every flush (survives power loss, costs a disk round trip).
        compression: MCAP chunk compression (zstd, lz4, none).
        source: accept datagrams from this sender address only (None: any). Several Motive
            instances may stream on one group (seed 4.2); the frames do not say which sent them.
    """

    out_dir: Path
    name: str = "mocap"
    namespace: str = ""
    group: str | None = "224.0.0.1"
    port: int = 1511
    interface: str = "0.0.0.0"
    split_s: float = 3600.0
    duration_s: float | None = None
    ntp_server: str | None = None
    ntp_port: int = 123
    ntp_timeout_s: float = 1.0
    natnet_version: NatNetVersion | None = None
    up_axis: str = "z"
    flush_interval_s: float = 0.5
    health_interval_s: float = 5.0
    fsync: bool = False
    compression: str = "zstd"
    source: str | None = None

    def validate(self) -> None:
        if self.split_s <= 0 or self.flush_interval_s <= 0 or self.health_interval_s <= 0:
            raise ConfigError("--split, flush and health intervals must be > 0 seconds")
        if self.duration_s is not None and self.duration_s <= 0:
            raise ConfigError("--duration must be > 0 seconds")
        if self.up_axis not in UP_AXES:
            raise ConfigError(f"--up-axis must be one of {UP_AXES}, got {self.up_axis!r}")
        if not self.name or any(c in self.name for c in "/\\ "):
            raise ConfigError(f"--name {self.name!r} must be a plain word (it goes in file names)")
        if self.natnet_version is not None and not self.natnet_version.supported:
            raise ConfigError(f"NatNet {self.natnet_version} is not supported (3.x and 4.x are)")


@frozen_dataclass
class RecordSummary:
    """What a recording produced."""

    files: tuple[Path, ...]
    frames: int
    dropped: int
    undecodable: int
    written: dict[int, int] = field(default_factory=dict)
    untracked: dict[int, int] = field(default_factory=dict)
    natnet_version: str = "unknown"


@frozen_dataclass
class _Route:
    """Where one body's pose goes (resolved once, channels per file)."""

    body: RigidBodyConfig
    pose_topic: str | None
    pose2d_topic: str | None
    tf: bool


# SO_TIMESTAMPNS (Linux, asm-generic and x86 value; Python's socket module lacks the name): the
# kernel stamps each datagram with CLOCK_REALTIME on arrival, so a recorder busy flushing, splitting
# or querying NTP does not shift the stamps of the datagrams waiting in the socket.
SO_TIMESTAMPNS = 35
_TIMESPEC = struct.Struct("@qq")
_KERNEL_STAMP_MACHINES = ("x86_64", "amd64", "i386", "i686", "aarch64", "arm64", "riscv64")


def enable_kernel_timestamps(sock: socket.socket) -> bool:
    """Ask the kernel to stamp arrivals; False where that is not known to work."""
    if sys.platform != "linux" or platform.machine().lower() not in _KERNEL_STAMP_MACHINES:
        return False
    try:
        sock.setsockopt(socket.SOL_SOCKET, SO_TIMESTAMPNS, 1)
    except OSError:
        return False
    return True


def receive(
    sock: socket.socket, kernel_stamps: bool, clock: Callable[[], int]
) -> tuple[bytes, int, str]:
    """One datagram, its arrival time (kernel stamp, else the host clock now) and sender."""
    if not kernel_stamps:
        data, addr = sock.recvfrom(65536)
        return data, clock(), str(addr[0])
    data, ancillary, _flags, addr = sock.recvmsg(65536, socket.CMSG_SPACE(_TIMESPEC.size))
    for level, kind, payload in ancillary:
        if level == socket.SOL_SOCKET and kind == SO_TIMESTAMPNS and len(payload) >= 16:
            sec, nsec = _TIMESPEC.unpack_from(payload)
            return data, sec * 1_000_000_000 + nsec, str(addr[0])
    return data, clock(), str(addr[0])


def open_socket(group: str | None, port: int, interface: str) -> socket.socket:
    """A UDP socket receiving NatNet data: joined to ``group`` or bound for unicast.

    SO_REUSEADDR lets several recorders on one host share the multicast port, as the 2015
    GTlogger and BMmanager did.
    """
    sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM, socket.IPPROTO_UDP)
    try:
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        # A few seconds of frames in the kernel while a split or NTP query runs.
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4 * 1024 * 1024)
        if group is None:
            sock.bind((interface, port))
        else:
            sock.bind(("", port))
            mreq = socket.inet_aton(group) + socket.inet_aton(interface)
            sock.setsockopt(socket.IPPROTO_IP, socket.IP_ADD_MEMBERSHIP, mreq)
    except OSError as err:
        sock.close()
        what = f"multicast group {group} on {interface}" if group else f"{interface}"
        raise ConfigError(
            f"cannot receive NatNet data on {what} port {port}: {err.strerror or err} "
            "(check --interface, --group and --port)"
        ) from err
    sock.settimeout(0.1)
    return sock


def _map_up_axis(
    up_axis: str, xyz: tuple[float, float, float], q: tuple[float, float, float, float]
) -> tuple[tuple[float, float, float], tuple[float, float, float, float]]:
    if up_axis == "z":
        return xyz, q
    # Y-up -> Z-up by the proper rotation M = [[-1,0,0],[0,0,1],[0,1,0]] (det +1): points
    # map by M, a quaternion's vector part maps by M too, its scalar part is unchanged.
    return (-xyz[0], xyz[2], xyz[1]), (-q[0], q[2], q[1], q[3])


class Recorder:
    """Receives, decodes and writes; ``run()`` returns when stopped or after the duration."""

    def __init__(
        self,
        config: MocapConfig,
        options: RecordOptions,
        *,
        report: Report | None = None,
        clock: Callable[[], int] = time.time_ns,
    ) -> None:
        options.validate()
        self.config = config
        self.options = options
        self._report = report or (lambda _line: None)
        self._clock = clock
        self._serializer = Ros2Serializer()
        self._decoder = FrameDecoder(options.natnet_version)
        ns = normalize_namespace(options.namespace)
        self._routes = {
            b.body_id: _Route(
                body=b,
                pose_topic=b.pose_topic(ns),
                pose2d_topic=b.pose2d_topic(ns),
                tf=bool(b.child_frame_id and b.parent_frame_id),
            )
            for b in config.bodies
        }
        self.stats = RecorderStats(
            bodies={b.body_id: BodyCounters(name=b.name) for b in config.bodies}
        )
        self.stop_event = threading.Event()
        self.ready = threading.Event()  # set once the first file is open and listening
        self.files: list[Path] = []
        self._sock: socket.socket | None = None
        self._kernel_stamps = False
        self._foreign_seen: set[str] = set()
        self._file: LogFile | None = None
        self._channels: dict[str, int] = {}
        self._file_base: dict[str, int] = {}
        self._start_s = 0.0
        self.port = options.port

    # ------------------------------------------------------------------ lifecycle

    def open(self) -> int:
        """Bind the socket (before the sender starts); returns the bound port."""
        self.options.out_dir.mkdir(parents=True, exist_ok=True)
        self._sock = open_socket(self.options.group, self.options.port, self.options.interface)
        self._kernel_stamps = enable_kernel_timestamps(self._sock)
        self.port = int(self._sock.getsockname()[1])
        return self.port

    def run(self) -> RecordSummary:
        """Record until ``stop_event`` is set or ``duration_s`` has passed."""
        if self._sock is None:
            self.open()
        assert self._sock is not None
        opts = self.options
        t0 = time.monotonic()
        index = 0
        self.start_file()
        file_t0 = last_flush = last_health = t0
        try:
            while not self.stop_event.is_set():
                now = time.monotonic()
                if opts.duration_s is not None and now - t0 >= opts.duration_s:
                    break
                if now - file_t0 >= opts.split_s:
                    index += 1
                    self._close_file()
                    self._open_file(index)
                    file_t0 = last_flush = now
                if now - last_flush >= opts.flush_interval_s:
                    assert self._file is not None
                    self._file.flush()
                    last_flush = now
                if now - last_health >= opts.health_interval_s:
                    self._health(now - last_health)
                    last_health = now
                try:
                    data, t_ns, sender = receive(self._sock, self._kernel_stamps, self._clock)
                except TimeoutError:
                    continue
                except OSError as err:  # e.g. the interface went down: keep trying
                    self._report(f"warning: receive failed: {err.strerror or err}")
                    self.stop_event.wait(0.5)
                    continue
                if opts.source is not None and sender != opts.source:
                    self._foreign(sender)
                    continue
                self.handle_datagram(data, t_ns)
            self.finish()
        except OSError as err:
            where = self._file.path if self._file is not None else opts.out_dir
            with contextlib.suppress(OSError):  # already failing: keep what was flushed
                self.finish()
            raise BagError(
                f"cannot write the log: {err.strerror or err} (disk full? permissions?)",
                path=where,
            ) from err
        except BaseException:
            with contextlib.suppress(OSError):
                self.finish()
            raise
        return self.summary()

    def start_file(self) -> Path:
        """Open the first file (``run`` does; tests feeding ``handle_datagram`` call it)."""
        self.options.out_dir.mkdir(parents=True, exist_ok=True)
        self._start_s = time.time()
        self._open_file(0)
        self.ready.set()
        return self.files[-1]

    def finish(self) -> None:
        """Close the file being written and the socket."""
        self._close_file()
        if self._sock is not None:
            self._sock.close()
            self._sock = None

    def summary(self) -> RecordSummary:
        s = self.stats
        return RecordSummary(
            files=tuple(self.files),
            frames=s.frames,
            dropped=s.dropped,
            undecodable=s.undecodable,
            written={bid: b.written for bid, b in s.bodies.items()},
            untracked={bid: b.untracked for bid, b in s.bodies.items()},
            natnet_version=str(self._decoder.version) if self._decoder.version else "unknown",
        )

    # ------------------------------------------------------------------ files

    def _clock_metadata(self) -> dict[str, str]:
        opts = self.options
        if not opts.ntp_server:
            return {"status": "not measured (no --ntp-server given)"}

        try:
            check = query_sntp(opts.ntp_server, opts.ntp_port, timeout_s=opts.ntp_timeout_s)
        except ErtoolsError as err:
            self._report(f"warning: clock not measured: {err}")
            return unreachable_metadata(opts.ntp_server, opts.ntp_port, str(err))
        self._report(f"clock: {check.describe()}")
        return check.to_metadata()

    def _open_file(self, index: int) -> None:
        opts = self.options
        path = opts.out_dir / log_file_name(opts.name, self._start_s, index)
        self._file = LogFile(path, self._serializer, compression=opts.compression, fsync=opts.fsync)
        self._channels = {}
        self.files.append(path)
        source = (
            f"multicast {opts.group}:{self.port} on {opts.interface}"
            if opts.group
            else f"unicast {opts.interface}:{self.port}"
        )
        self._file.add_metadata(
            "ertools.recorder",
            {
                "tool": "ertools record",
                "ertools_version": __version__,
                "config": self.config.source,
                "namespace": normalize_namespace(opts.namespace),
                "bodies": ",".join(f"{b.body_id}:{b.name}" for b in self.config.bodies),
                "source": source + (f" from {opts.source} only" if opts.source else ""),
                "host": socket.gethostname(),
                "natnet_version": str(opts.natnet_version or "auto"),
                "up_axis": opts.up_axis,
                "file_index": str(index),
                "split_s": f"{opts.split_s:g}",
                "flush_interval_s": f"{opts.flush_interval_s:g}",
                "time_source": (
                    "kernel receive time of the datagram (SO_TIMESTAMPNS, host realtime clock)"
                    if self._kernel_stamps
                    else "host clock (Unix ns) when the datagram was read"
                ),
            },
        )
        self._file.add_metadata("ertools.clock", self._clock_metadata())
        # Channels (and their schemas) up front: every file lists every configured topic, and
        # the first frame is not delayed by building schemas.
        for route in self._routes.values():
            if route.pose_topic:
                self._channel(route.pose_topic, POSE_STAMPED)
            if route.pose2d_topic:
                self._channel(route.pose2d_topic, POSE_2D)
            if route.tf:
                self._channel("/tf", TF_MESSAGE)
        self._file_base = self._counts()
        self._report(f"writing {path}")

    def _counts(self) -> dict[str, int]:
        return {k: int(v) for k, v in self.stats.as_metadata().items() if v.isdigit()}

    def _close_file(self) -> None:
        if self._file is None or self._file.closed:
            return
        meta = self.stats.as_metadata()
        now = self._counts()
        per_file = {k: str(now[k] - self._file_base.get(k, 0)) for k in now}
        meta.update(per_file)
        meta["natnet_version"] = str(self._decoder.version or "unknown")
        meta["scope"] = "counts of this file"
        self._file.close({"ertools.recorder.stats": meta})
        self._report(f"closed {self._file.path} ({self._file.messages} messages)")

    def _foreign(self, sender: str) -> None:
        """A datagram from another host than --source (e.g. a second Motive on the group)."""
        self.stats.foreign += 1
        if sender not in self._foreign_seen:
            self._foreign_seen.add(sender)
            self._report(f"ignoring datagrams from {sender} (not --source {self.options.source})")

    def _health(self, window_s: float) -> None:
        f = self._file
        name, size = (f.path.name, f.size) if f is not None else ("-", 0)
        silent = self.stats.window_frames == 0
        self._report("health: " + self.stats.health_line(window_s, name, size))
        if silent:
            opts = self.options
            where = f"group {opts.group}" if opts.group else "unicast"
            self._report(
                f"warning: no NatNet frame in the last {window_s:.1f} s on {where} port "
                f"{self.port} (interface {opts.interface}): is streaming switched on in Motive "
                "(seed 4.1)? check --group, --interface and --port"
            )

    # ------------------------------------------------------------------ data

    def _channel(self, topic: str, typename: str) -> int:
        cid = self._channels.get(topic)
        if cid is None:
            assert self._file is not None
            cid = self._channels[topic] = self._file.channel(topic, typename)
        return cid

    def handle_datagram(self, data: bytes, t_ns: int) -> None:
        """Decode one datagram and write its configured, tracked bodies."""
        mid = message_id(data)
        if mid in OTHER_MESSAGE_IDS and HEADER.size + HEADER.unpack_from(data)[1] == len(data):
            self.stats.other_messages += 1  # e.g. a model definition: well formed, not ours
            return
        first = self._decoder.version is None
        try:
            frame = self._decoder.decode(data)
        except UndecodablePacketError as err:
            self.stats.undecodable += 1
            if self.stats.undecodable == 1 or self.stats.last_error != str(err):
                self._report(f"warning: undecodable NatNet packet ({len(data)} bytes): {err}")
            self.stats.last_error = str(err)
            return
        if first:
            self._report(f"NatNet stream layout detected: {self._decoder.version}")
        if self.stats.accept_frame_number(frame.frame_number):
            self._write_frame(frame, t_ns)

    def _write_frame(self, frame: FrameOfData, t_ns: int) -> None:
        assert self._file is not None
        seen: set[int] = set()
        for rb in frame.rigid_bodies:
            route = self._routes.get(rb.body_id)
            if route is None:
                if rb.body_id not in self.stats.unconfigured:
                    self.stats.unconfigured.add(rb.body_id)
                    self._report(f"rigid body ID {rb.body_id} is streamed but not configured")
                continue
            seen.add(rb.body_id)
            counters = self.stats.bodies[rb.body_id]
            valid = rb.tracking_valid and quat_is_finite(rb.orientation_xyzw)
            if valid != counters.tracking:
                if counters.tracking is not None:
                    state = "regained" if valid else "LOST"
                    self._report(f"{counters.name}: tracking {state} at frame {frame.frame_number}")
                counters.tracking = valid
            if not valid:
                counters.untracked += 1
                continue
            xyz, q = _map_up_axis(self.options.up_axis, rb.position, rb.orientation_xyzw)
            body = route.body
            if route.pose_topic:
                data = self._serializer.pose_stamped(t_ns, body.parent_frame_id, xyz, q)
                self._file.write(self._channel(route.pose_topic, POSE_STAMPED), t_ns, data)
            if route.pose2d_topic:
                data = self._serializer.pose2d(xyz[0], xyz[1], yaw_of(q))
                self._file.write(self._channel(route.pose2d_topic, POSE_2D), t_ns, data)
            if route.tf and body.child_frame_id:
                data = self._serializer.tf(t_ns, body.parent_frame_id, body.child_frame_id, xyz, q)
                self._file.write(self._channel("/tf", TF_MESSAGE), t_ns, data)
            counters.written += 1
            counters.window_written += 1
        for bid, counters in self.stats.bodies.items():
            if bid not in seen:
                counters.missing += 1


def record(
    config: MocapConfig,
    options: RecordOptions,
    *,
    report: Report | None = None,
    stop: threading.Event | None = None,
) -> RecordSummary:
    """Record until ``stop`` is set or the duration passes (the library call of the CLI)."""
    recorder = Recorder(config, options, report=report)
    if stop is not None:
        recorder.stop_event = stop
    recorder.open()
    return recorder.run()
