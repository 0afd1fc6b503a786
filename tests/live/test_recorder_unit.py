"""Recorder bookkeeping fed datagram by datagram (no network): drops, duplicates, others."""

from __future__ import annotations

import struct
from pathlib import Path

import pytest

from ertools.configs.mocap import parse_mocap_config
from ertools.live.natnet import FrameOfData, NatNetVersion, RigidBody, encode_frame
from ertools.live.recorder import Recorder, RecordOptions, record
from ertools.live.tail import is_finished, read_complete
from tests.live.live_helpers import read_mcap

pytestmark = pytest.mark.xdist_group("timing")

CONFIG = parse_mocap_config("rigid_bodies: {'3': {pose: robot/pose}}")
V = NatNetVersion(3, 1)


def frame(number: int, *bodies: RigidBody) -> bytes:
    return encode_frame(FrameOfData(number, tuple(bodies)), V)


def body(bid: int, x: float, params: int = 1) -> RigidBody:
    return RigidBody(bid, (x, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0), 0.0, params)


def test_counters_follow_the_frame_numbers(tmp_path: Path) -> None:
    lines: list[str] = []
    rec = Recorder(CONFIG, RecordOptions(out_dir=tmp_path, natnet_version=V), report=lines.append)
    path = rec.start_file()
    t = 1_445_609_740_000_000_000
    feed = [
        frame(10, body(3, 1.0)),
        frame(11, body(3, 2.0)),
        frame(11, body(3, 2.0)),  # the same frame twice (e.g. two routes): written once
        frame(15, body(3, 3.0)),  # 12, 13, 14 lost
        frame(16, body(3, 0.0, params=0)),  # untracked
        frame(17, body(9, 5.0)),  # not configured; body 3 missing from the frame
        struct.pack("<hH", 5, 4) + b"\0" * 4,  # a well-formed model definition: not ours
        b"\x07\x00\xff",  # garbage
        frame(2, body(3, 4.0)),  # Motive restarted
    ]
    for k, data in enumerate(feed):
        rec.handle_datagram(data, t + k * 10_000_000)
    rec.finish()
    s, b = rec.stats, rec.stats.bodies[3]
    # 7 frames arrived, one of them twice: 6 distinct frames counted.
    assert (s.frames, s.duplicates, s.dropped, s.restarts) == (6, 1, 3, 1)
    assert (s.other_messages, s.undecodable, s.unconfigured) == (1, 1, {9})
    assert (b.written, b.untracked, b.missing) == (4, 1, 1)
    messages, clean = read_mcap(path)
    assert clean
    xs = [(lt, m.pose.position.x) for topic, lt, m in messages if topic == "/robot/pose"]
    # Stamps are the receive times handed in; positions in order, the duplicate once.
    assert xs == [(t, 1.0), (t + 10_000_000, 2.0), (t + 30_000_000, 3.0), (t + 80_000_000, 4.0)]
    assert any("rigid body ID 9 is streamed but not configured" in line for line in lines)


@pytest.mark.slow
def test_record_function_without_data(tmp_path: Path) -> None:
    """The library call: no sender, a short duration: one closed, empty-but-valid file."""

    options = RecordOptions(
        out_dir=tmp_path / "new", group=None, port=0, interface="127.0.0.1", duration_s=0.35,
        health_interval_s=0.2,
    )  # fmt: skip
    lines: list[str] = []
    summary = record(CONFIG, options, report=lines.append)
    (path,) = summary.files
    assert path.parent == tmp_path / "new" and is_finished(path)
    assert (summary.frames, summary.undecodable, summary.natnet_version) == (0, 0, "unknown")
    assert read_complete(path).messages == ()
    # The health line after 0.2 s (0.3 s when the loop was late) says nothing came.
    assert any(x.startswith("warning: no NatNet frame in the last 0.") for x in lines)
    assert any("is streaming switched on in Motive" in x for x in lines)
