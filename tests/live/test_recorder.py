"""The recorder end to end on 127.0.0.1: a simulated Motive streams, the MCAP holds its poses."""

from __future__ import annotations

import math
import platform
import socket
import sys
import threading
import time
from pathlib import Path

import pytest
from mcap.reader import make_reader

from ertools.configs.mocap import parse_mocap_config
from ertools.io.reader import read_poses
from ertools.live.natnet import FrameExtras, NatNetVersion, RigidBody, encode_frame
from ertools.live.recorder import Recorder, RecordOptions, RecordSummary
from ertools.live.simulate import SimulatedBody, SimulatedMotive, make_frame
from ertools.live.tail import is_finished, read_complete
from tests.live.live_helpers import fake_sntp_server, read_mcap

pytestmark = [pytest.mark.slow, pytest.mark.xdist_group("timing")]

CONFIG = parse_mocap_config(
    """
rigid_bodies:
  '3': {pose: robot_at_home/pose, pose2d: robot_at_home/pose2d,
        child_frame_id: robot_at_home, parent_frame_id: world}
  '6': {pose: origin/pose, pose2d: origin/pose2d, child_frame_id: origin, parent_frame_id: world}
"""
)
FIRST = 1000


def run_recording(
    tmp_path: Path,
    motive_kwargs: dict[str, object],
    *,
    group: str | None = None,
    **option_kwargs: object,
) -> tuple[RecordSummary, SimulatedMotive, list[str]]:
    """Recorder in a thread, Motive in another; the recorder stops when Motive is done."""
    options = RecordOptions(
        out_dir=tmp_path,
        name="test",
        namespace="/fbm2h",
        group=group,
        port=0,
        interface="127.0.0.1",
        health_interval_s=0.5,
        **option_kwargs,  # type: ignore[arg-type]
    )
    lines: list[str] = []
    recorder = Recorder(CONFIG, options, report=lines.append)
    port = recorder.open()
    result: list[RecordSummary] = []
    thread = threading.Thread(target=lambda: result.append(recorder.run()), daemon=True)
    thread.start()
    assert recorder.ready.wait(5)
    target = (group or "127.0.0.1", port)
    motive = SimulatedMotive(
        target=target,
        multicast_interface="127.0.0.1" if group else None,
        **motive_kwargs,  # type: ignore[arg-type]
    )
    motive.run()
    # Give the recorder a moment to drain the socket (loopback delivery is immediate; the
    # recorder reads every 0.1 s at worst), then stop it.
    threading.Event().wait(0.3)
    recorder.stop_event.set()
    thread.join(timeout=5)
    assert result, "recorder did not stop"
    return result[0], motive, lines


def expected_poses(motive: SimulatedMotive, body_id: int) -> list[RigidBody]:
    """The tracked poses of one body, in the order they were sent (the ground truth)."""
    return [
        rb
        for frame in motive.sent
        for rb in frame.rigid_bodies
        if rb.body_id == body_id and rb.tracking_valid
    ]


def test_recording_holds_exactly_the_sent_poses(tmp_path: Path) -> None:
    untracked = (FIRST + 40, FIRST + 70)  # 30 frames of body 3 with tracking lost
    summary, motive, lines = run_recording(
        tmp_path,
        {
            "bodies": (SimulatedBody(3, untracked=untracked), SimulatedBody(6, radius=2.0)),
            "n_frames": 150,
            "rate_hz": 200.0,
            "malformed_at": (FIRST + 10,),
            "skip": (FIRST + 100, FIRST + 101),  # a drop of two frames
            "extras": FrameExtras(
                marker_sets=(("robot_at_home", ((0.1, 0.2, 0.3),) * 5),),
                skeletons=((1, (RigidBody(40, (0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0)),)),),
                labeled_markers=5,
            ),
        },
    )
    assert len(summary.files) == 1 and is_finished(summary.files[0])
    messages, clean = read_mcap(summary.files[0])
    assert clean
    by_topic: dict[str, list[tuple[int, object]]] = {}
    for topic, t, msg in messages:
        by_topic.setdefault(topic, []).append((t, msg))

    # Counters against what the simulator did.
    assert summary.frames == 148  # 150 generated, 2 skipped
    assert summary.dropped == 2
    assert summary.undecodable == motive.malformed_sent == 1
    assert summary.untracked == {3: 30, 6: 0}
    assert summary.written == {3: 118, 6: 148}
    assert summary.natnet_version == "4.1"

    for body_id, name in ((3, "robot_at_home"), (6, "origin")):
        sent = expected_poses(motive, body_id)
        poses = by_topic[f"/fbm2h/{name}/pose"]
        assert len(poses) == len(sent) == summary.written[body_id]
        for (t, msg), rb in zip(poses, sent, strict=True):
            p, q = msg.pose.position, msg.pose.orientation  # type: ignore[attr-defined]
            # Exact: the simulator rounds to float32, which the packet carries unchanged.
            assert (p.x, p.y, p.z) == rb.position
            assert (q.x, q.y, q.z, q.w) == rb.orientation_xyzw
            assert msg.header.frame_id == "world"  # type: ignore[attr-defined]
            stamp = msg.header.stamp  # type: ignore[attr-defined]
            assert stamp.sec * 1_000_000_000 + stamp.nanosec == t
        pose2d = by_topic[f"/fbm2h/{name}/pose2d"]
        assert len(pose2d) == len(sent)
        for (_, msg), rb in zip(pose2d, sent, strict=True):
            qx, qy, qz, qw = rb.orientation_xyzw
            yaw = math.atan2(2 * (qw * qz + qx * qy), 1 - 2 * (qy * qy + qz * qz))
            assert (msg.x, msg.y) == rb.position[:2]  # type: ignore[attr-defined]
            assert msg.theta == pytest.approx(yaw, abs=1e-12)  # type: ignore[attr-defined]
    tf = by_topic["/tf"]
    assert len(tf) == summary.written[3] + summary.written[6]
    children = [m.transforms[0].child_frame_id for _, m in tf]  # type: ignore[attr-defined]
    assert children.count("robot_at_home") == 118 and children.count("origin") == 148
    # Host-clock stamps only increase.
    times = [t for t, _ in by_topic["/fbm2h/origin/pose"]]
    assert times == sorted(times)
    assert any("tracking LOST at frame 1040" in line for line in lines)
    assert any("tracking regained at frame 1070" in line for line in lines)
    assert any(line.startswith("health: ") and "undecodable 1" in line for line in lines)


def test_multicast_on_loopback(tmp_path: Path) -> None:
    summary, motive, _ = run_recording(
        tmp_path,
        {"bodies": (SimulatedBody(6),), "n_frames": 40, "rate_hz": 200.0},
        group="224.0.0.1",
    )
    assert summary.frames == 40 and summary.written[6] == 40
    assert len(expected_poses(motive, 6)) == 40


def test_split_every_second_with_clock_metadata(tmp_path: Path) -> None:
    with fake_sntp_server(0.125) as ntp_port:
        summary, motive, _ = run_recording(
            tmp_path,
            {"bodies": (SimulatedBody(3),), "n_frames": 260, "rate_hz": 100.0},
            split_s=1.0,
            ntp_server="127.0.0.1",
            ntp_port=ntp_port,
        )
    # 2.6 s of frames plus ~0.3 s: three files, same start stamp, n = 0, 1, 2 (rosbag naming).
    names = [p.name for p in summary.files]
    assert len(names) == 3
    stamps = {n.rsplit("_", 1)[0] for n in names}
    assert len(stamps) == 1 and stamps.pop().startswith("log_test_")
    assert [n.rsplit("_", 1)[1] for n in names] == ["0.mcap", "1.mcap", "2.mcap"]
    sent = expected_poses(motive, 3)
    got = []

    for path in summary.files:
        assert is_finished(path)
        messages, clean = read_mcap(path)
        assert clean
        got += [m.pose.position for topic, _, m in messages if topic.endswith("/pose")]
        with open(path, "rb") as f:
            meta = {m.name: m.metadata for m in make_reader(f).iter_metadata()}
        # Measured at each file start against a server 0.125 s ahead: within delay/2.
        clock = meta["ertools.clock"]
        assert clock["status"] == "ok"
        assert abs(float(clock["offset_s"]) - 0.125) <= float(clock["delay_s"]) / 2 + 2e-6
        assert meta["ertools.recorder"]["namespace"] == "/fbm2h"
        assert int(meta["ertools.recorder.stats"]["body.3.written"]) == sum(
            1 for topic, _, _ in messages if topic == "/fbm2h/robot_at_home/pose"
        )
    # Nothing lost or repeated across the splits.
    assert [(p.x, p.y, p.z) for p in got] == [rb.position for rb in sent]


def test_up_axis_y_maps_motive_y_up_to_z_up(tmp_path: Path) -> None:
    summary, motive, _ = run_recording(
        tmp_path, {"bodies": (SimulatedBody(6),), "n_frames": 5, "rate_hz": 100.0}, up_axis="y"
    )
    messages, _ = read_mcap(summary.files[0])
    poses = [m for topic, _, m in messages if topic == "/fbm2h/origin/pose"]
    for msg, rb in zip(poses, expected_poses(motive, 6), strict=True):
        x, y, z = rb.position
        qx, qy, qz, qw = rb.orientation_xyzw
        p, q = msg.pose.position, msg.pose.orientation
        assert (p.x, p.y, p.z) == (-x, z, y)  # Motive Y-up -> Z-up, as mocap_optitrack
        assert (q.x, q.y, q.z, q.w) == (-qx, qz, qy, qw)


def test_read_complete_agrees_with_mcap_reader(tmp_path: Path) -> None:
    summary, _, _ = run_recording(
        tmp_path, {"bodies": (SimulatedBody(3),), "n_frames": 30, "rate_hz": 100.0}
    )
    ours = read_complete(summary.files[0])
    theirs, _ = read_mcap(summary.files[0])
    assert ours.finished and not ours.problem
    assert [(m.topic, m.log_time_ns) for m in ours.messages] == [(t, lt) for t, lt, _ in theirs]


def test_ertools_io_reads_the_recording(tmp_path: Path) -> None:
    summary, motive, _ = run_recording(
        tmp_path, {"bodies": (SimulatedBody(3),), "n_frames": 30, "rate_hz": 100.0}
    )
    stream = read_poses(summary.files, "/fbm2h/robot_at_home/pose")
    sent = expected_poses(motive, 3)
    assert len(stream) == len(sent)
    assert [tuple(row) for row in stream.xyz] == [rb.position for rb in sent]


def test_unsupported_version_is_counted_not_fatal(tmp_path: Path) -> None:
    # The stream is 3.1; the recorder is told 4.1: every frame is undecodable, none crashes.
    summary, _, lines = run_recording(
        tmp_path,
        {
            "bodies": (SimulatedBody(3),),
            "n_frames": 20,
            "rate_hz": 200.0,
            "version": NatNetVersion(3, 1),
        },
        natnet_version=NatNetVersion(4, 1),
    )
    assert summary.frames == 0 and summary.undecodable == 20
    assert sum("undecodable NatNet packet" in line for line in lines) == 1  # said once


@pytest.mark.skipif(
    sys.platform != "linux" or platform.machine() not in ("x86_64", "aarch64"),
    reason="kernel receive timestamps (SO_TIMESTAMPNS) are used on Linux x86_64/aarch64",
)
def test_stamps_are_kernel_arrival_times(tmp_path: Path) -> None:
    """Frames that wait in the socket keep the time they arrived, not the time they are read."""
    options = RecordOptions(
        out_dir=tmp_path,
        name="k",
        group=None,
        port=0,
        interface="127.0.0.1",
        duration_s=0.5,
        namespace="/fbm2h",
    )
    recorder = Recorder(CONFIG, options, clock=lambda: 42)  # 42: a read-time stamp would show
    port = recorder.open()
    # 20 frames at 100 Hz sent before the recorder reads anything: they queue in the socket.
    motive = SimulatedMotive(("127.0.0.1", port), (SimulatedBody(6),), n_frames=20, rate_hz=100.0)
    sent_from = time.time_ns()
    motive.run()
    sent_to = time.time_ns()
    summary = recorder.run()
    messages, _ = read_mcap(summary.files[0])
    stamps = [t for topic, t, _ in messages if topic == "/fbm2h/origin/pose"]
    assert len(stamps) == 20
    # Arrival times lie inside the sending window (loopback delivery takes microseconds), and
    # span the 0.19 s of pacing although all were read within a few milliseconds.
    assert sent_from <= stamps[0] and stamps[-1] <= sent_to
    assert stamps[-1] - stamps[0] >= 150_000_000


def test_source_filter_ignores_a_second_motive(tmp_path: Path) -> None:
    options = RecordOptions(
        out_dir=tmp_path, name="src", group=None, port=0, interface="127.0.0.1",
        source="127.0.0.1", duration_s=0.6, namespace="/fbm2h",
    )  # fmt: skip
    lines: list[str] = []
    recorder = Recorder(CONFIG, options, report=lines.append)
    port = recorder.open()
    # Another "Motive" on 127.0.0.2 streams the same body ID 6 at another place.
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as other:
        other.bind(("127.0.0.2", 0))
        far = (SimulatedBody(6, center=(50.0, 50.0)),)
        for k in range(5):
            packet = encode_frame(make_frame(5000 + k, 0.0, far, {}), NatNetVersion(4, 1))
            other.sendto(packet, ("127.0.0.1", port))
    motive = SimulatedMotive(("127.0.0.1", port), (SimulatedBody(6),), n_frames=10, rate_hz=200.0)
    motive.run()
    summary = recorder.run()
    assert recorder.stats.foreign == 5
    assert summary.frames == 10 and summary.written[6] == 10
    messages, _ = read_mcap(summary.files[0])
    xs = [m.pose.position.x for topic, _, m in messages if topic == "/fbm2h/origin/pose"]
    assert xs == [rb.position[0] for rb in expected_poses(motive, 6)]  # none near x = 50
    assert sum("ignoring datagrams from 127.0.0.2" in line for line in lines) == 1
