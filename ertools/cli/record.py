"""Record OptiTrack Motive rigid bodies (NatNet over UDP) into MCAP files, with no ROS.

Does what the 2015 GT logger did with mocap_optitrack + rosbag record (seed 4.3, 4.4): every
configured rigid body (seed Listing 2) is written as geometry_msgs/PoseStamped, Pose2D and
tf2_msgs/TFMessage, stamped with the host clock, into files split every --split seconds and
named like rosbag's (log_<name>_<YYYY-MM-DD-HH-MM-SS>_<n>.mcap). Frames where Motive lost
a body are not written but counted. A crash loses at most the last --flush seconds.

A health line goes to stderr every --health seconds; Ctrl-C or SIGTERM closes the file cleanly
and prints a summary on stdout.
"""

from __future__ import annotations

import argparse
import signal
import threading
from pathlib import Path

from ertools.cli.options import add_out_dir, port, positive
from ertools.cli.output import note
from ertools.configs.mocap import load_mocap_config, normalize_namespace, parse_mocap_config
from ertools.errors import UsageError
from ertools.live.natnet import NatNetVersion
from ertools.live.recorder import Recorder, RecordOptions
from ertools.live.recover import recover
from ertools.live.simulate import SimulatedBody, SimulatedMotive

EPILOG = """examples:
  ertools record --config configs/mocap_home.yaml --out-dir logs/ --namespace /fbm2h
  ertools record --config configs/mocap_work.yaml --out-dir logs/ --namespace /fbm3w \\
      --interface 192.168.1.20 --ntp-server 192.168.1.1
  ertools record --config mocap.yaml --out-dir logs/ --unicast --interface 0.0.0.0 --port 1511
  ertools record --simulate --out-dir /tmp/demo --duration 10     # no Motive needed

output files: log_<name>_<YYYY-MM-DD-HH-MM-SS>_<n>.mcap; --name defaults to <namespace>_mocap
(log_fbm2h_mocap_2015-10-23-16-15-40_0 in 2015) or mocap.
"""

# Listing 2's bodies, used by --simulate when no --config is given.
SIMULATE_CONFIG = """
rigid_bodies:
  '3': {pose: robot_at_home/pose, pose2d: robot_at_home/pose2d,
        child_frame_id: robot_at_home, parent_frame_id: world}
  '6': {pose: origin/pose, pose2d: origin/pose2d, child_frame_id: origin, parent_frame_id: world}
  '7': {pose: ref_board/pose, pose2d: ref_board/pose2d,
        child_frame_id: ref_board, parent_frame_id: world}
"""


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--config", type=Path, help="mocap YAML (seed Listing 2: rigid_bodies)")
    add_out_dir(parser, "write the MCAP files into DIR (needed to record)", old=("--out",))
    parser.add_argument(
        "--recover",
        type=Path,
        metavar="FILE",
        help="make FILE, a recording cut short (kill -9, power lost), whole: every complete "
        "message kept, summary and index written (the cut bytes kept as FILE.cut); "
        "nothing is recorded",
    )
    parser.add_argument("--name", help="file name part (default <namespace>_mocap or mocap)")
    parser.add_argument(
        "--namespace", default="", help="prefix of the config's relative topics, e.g. /fbm2h"
    )
    net = parser.add_argument_group("network")
    net.add_argument(
        "--group", help="multicast group (default: the config's, else 224.0.0.1 as seed 4.1)"
    )
    net.add_argument(
        "--unicast", action="store_true", help="receive unicast on --interface instead of a group"
    )
    net.add_argument("--port", type=port, help="NatNet data port (default 1511)")
    net.add_argument(
        "--interface",
        default="0.0.0.0",
        help="local address to join the group on / bind to (default 0.0.0.0: any)",
    )
    net.add_argument(
        "--source",
        metavar="ADDR",
        help="accept datagrams from this sender only (Motive's address; others are counted)",
    )
    net.add_argument(
        "--natnet-version",
        default="auto",
        help="the stream's NatNet version, e.g. 3.1, 4.0, 4.1 (default auto: from the first frame)",
    )
    out = parser.add_argument_group("files")
    out.add_argument(
        "--split", type=positive, default=3600.0, metavar="S", help="new file every S s (3600)"
    )
    out.add_argument("--duration", type=positive, metavar="S", help="stop after S seconds")
    out.add_argument(
        "--flush",
        type=positive,
        default=0.5,
        metavar="S",
        help="flush a chunk every S s: the most a crash loses (0.5)",
    )
    out.add_argument("--fsync", action="store_true", help="fsync every flush (power-loss safe)")
    out.add_argument("--compression", choices=("zstd", "lz4", "none"), default="zstd")
    out.add_argument(
        "--up-axis",
        choices=("z", "y"),
        default="z",
        help="z: Motive streams Z-up, written as is (default); y: Motive's Y-up mapped to Z-up "
        "as mocap_optitrack did",
    )
    mon = parser.add_argument_group("health and clock")
    mon.add_argument(
        "--health", type=positive, default=5.0, metavar="S", help="health line every S s (5)"
    )
    mon.add_argument("--ntp-server", metavar="HOST", help="measure the clock offset at each file")
    mon.add_argument("--ntp-port", type=port, default=123)
    parser.add_argument(
        "--simulate",
        action="store_true",
        help="demo: a simulated Motive streams the config's bodies over 127.0.0.1",
    )


def run(args: argparse.Namespace) -> int:
    if args.recover is not None:
        return _recover(args.recover)
    if args.out_dir is None:
        raise UsageError(
            "the following arguments are required: --out-dir DIR (where the MCAP files go; "
            "`ertools record --help` shows how)"
        )
    if args.config is None and not args.simulate:
        raise UsageError("--config is required (a mocap YAML as seed Listing 2)")
    config = (
        load_mocap_config(args.config)
        if args.config is not None
        else parse_mocap_config(SIMULATE_CONFIG, source="<built-in Listing 2>")
    )
    version = None
    if args.natnet_version != "auto":
        try:
            version = NatNetVersion.parse(args.natnet_version)
        except ValueError as err:
            raise UsageError(str(err)) from None
    ns = normalize_namespace(args.namespace)
    name = args.name or (f"{ns.strip('/').replace('/', '_')}_mocap" if ns else "mocap")
    group = None if args.unicast else (args.group or config.group)
    interface = args.interface
    data_port = args.port if args.port is not None else config.data_port
    duration = args.duration
    if args.simulate:
        group, interface = None, "127.0.0.1"
        data_port = args.port if args.port is not None else 0
        duration = duration if duration is not None else 10.0
    options = RecordOptions(
        out_dir=args.out_dir,
        name=name,
        namespace=ns,
        group=group,
        port=data_port,
        interface=interface,
        split_s=args.split,
        duration_s=duration,
        ntp_server=args.ntp_server,
        ntp_port=args.ntp_port,
        natnet_version=version,
        up_axis=args.up_axis,
        flush_interval_s=args.flush,
        health_interval_s=args.health,
        fsync=args.fsync,
        compression=args.compression,
        source=args.source,
    )
    recorder = Recorder(config, options, report=lambda line: note(f"record: {line}"))
    bound = recorder.open()
    where = f"multicast {group} on {interface}" if group else f"unicast {interface}"
    note(f"record: listening on {where} port {bound}; bodies {[b.name for b in config.bodies]}")

    previous: dict[int, object] = {}
    if threading.current_thread() is threading.main_thread():
        for sig in (signal.SIGINT, signal.SIGTERM):
            previous[sig] = signal.signal(sig, lambda *_: recorder.stop_event.set())
    sim_thread = None
    if args.simulate:
        bodies = tuple(
            SimulatedBody(
                b.body_id,
                radius=1.0 + 0.5 * i,
                phase=float(i),
                untracked=(1000 + 300, 1000 + 400) if i == 0 else None,
            )
            for i, b in enumerate(config.bodies)
        )
        motive = SimulatedMotive(
            target=("127.0.0.1", bound),
            bodies=bodies,
            n_frames=int(120 * (duration or 10.0)),
            rate_hz=120.0,
            # 2.25 s in: after the first 2 s health line, before frame 1300 (docs/live.md shows
            # that order; at 1240, exactly 2 s in, the two raced)
            malformed_at=(1270,),
        )
        sim_thread = motive.start()
        note("record: simulated Motive streaming at 120 Hz (body 0 untracked frames 1300-1399)")
    try:
        summary = recorder.run()
    finally:
        for signum, handler in previous.items():
            signal.signal(signum, handler)  # type: ignore[arg-type]
        if sim_thread is not None:
            motive.stop.set()
            sim_thread.join(timeout=2.0)
    lines = [
        "files:",
        *[f"  - {p}" for p in summary.files],
        f"natnet_version: '{summary.natnet_version}'",
        f"frames: {summary.frames}",
        f"dropped: {summary.dropped}",
        f"undecodable: {summary.undecodable}",
        "bodies:",
    ]
    for b in config.bodies:
        lines.append(
            f"  {b.name}: {{id: {b.body_id}, written: {summary.written.get(b.body_id, 0)}, "
            f"untracked: {summary.untracked.get(b.body_id, 0)}}}"
        )
    print("\n".join(lines))
    return 0


def _recover(path: Path) -> int:
    done = recover(path)
    if done.kept is None:
        note(f"{path}: already whole (it ends with its footer); nothing done")
        return 0
    lost = done.size_bytes - done.complete_bytes
    note(
        f"{path}: whole again: {done.messages} messages kept, summary and index written; "
        f"{lost} bytes after the last complete record dropped; the cut file kept as {done.kept}"
    )
    return 0
