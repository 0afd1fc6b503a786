"""One read of several topics (issue 39): the one-gather decoder against the general path and
against rosbags' own deserializer, bit for bit, on bags made to stress it: frame names that
vary in length message by message, several connections mixed in every chunk, records at odd
offsets, windows that cut chunks, compressed and uncompressed chunks, and random layouts.
"""

from __future__ import annotations

import itertools
import struct
import threading
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from mcap.writer import CompressionType

from ertools.errors import BagError, TopicError
from ertools.io import assemble, bulk, pipeline, reader
from ertools.io.decode.posebatch import PoseBatch
from ertools.io.files import open_bag
from ertools.io.model import POSE_TYPES, PoseSource
from ertools.io.pipeline import Request
from ertools.io.ros1 import runs as ros1_runs
from ertools.io.ros1.entries import merged_columns
from ertools.io.summary import summary
from tests.helpers.bagmaker import FORMATS, Spec, bag_name, write
from tests.helpers.fastpath import (
    POSE_TOPICS,
    REAL_BAG,
    assert_same,
    reference_bag,
    reference_batch,
    sample_bags,
)
from tests.helpers.scene import DT, T0, Scene

STATE_TOPICS = ("/fbm3w/bmbox_state", "/fbm3w/refbox_state")


def fast_many(
    path: Path, topics: list[str], windows: list[tuple[int | None, int | None]] | None = None
) -> list[PoseBatch]:
    """Every topic decoded in bulk from one read of the file."""
    windows = windows or [(None, None)] * len(topics)
    with open_bag(path) as bag:
        requests = [
            Request(tuple(bag.topic_conns(t)), lo, hi)
            for t, (lo, hi) in zip(topics, windows, strict=True)
        ]
        out = bulk.try_fast_batches(bag, requests)
    assert all(b is not None for b in out), f"the fast path did not apply to {path}"
    return [b for b in out if b is not None]


@pytest.fixture
def no_field_decoder(monkeypatch: pytest.MonkeyPatch) -> None:
    """The field-by-field decoder refuses to run: what passes was decoded by layouts."""

    def refuse(*args: Any, **kwargs: Any) -> Any:
        raise AssertionError("the field-by-field decoder was needed")

    monkeypatch.setattr(assemble, "decode", refuse)


@pytest.fixture
def general_path(monkeypatch: pytest.MonkeyPatch) -> None:
    """No one-gather path: every run goes through its checked spans."""
    monkeypatch.setattr(assemble.Decoder, "fast", lambda *args, **kwargs: False)


@pytest.fixture
def field_path(monkeypatch: pytest.MonkeyPatch, general_path: None) -> None:
    """Neither the one-gather path nor layouts: every message decoded field by field."""
    monkeypatch.setattr(assemble, "layout_of", lambda *args, **kwargs: None)


@pytest.mark.slow_cases("rosbag2-sqlite3", "rosbag2-mcap")
def test_one_read_of_every_topic_equals_rosbags(
    scene_bag: tuple[str, Path], no_field_decoder: None
) -> None:
    """All pose topics of the scene from one read (two /tf connections of other frame names
    among them), each as rosbags reads it alone; no message needed the field decoder."""
    _fmt, path = scene_bag
    for topic, batch in zip(POSE_TOPICS, fast_many(path, list(POSE_TOPICS)), strict=True):
        assert_same(batch, reference_batch(path, topic))


@pytest.mark.slow_cases(
    "rosbag2-sqlite3-general_path",
    "rosbag2-sqlite3-field_path",
    "rosbag2-mcap-general_path",
    "rosbag2-mcap-field_path",
)
@pytest.mark.parametrize("mode", ["general_path", "field_path"])
def test_general_and_field_paths_equal_the_one_gather_path(
    scene_bag: tuple[str, Path], mode: str, request: pytest.FixtureRequest
) -> None:
    _fmt, path = scene_bag
    fast = fast_many(path, list(POSE_TOPICS))
    request.getfixturevalue(mode)
    slow = fast_many(path, list(POSE_TOPICS))
    for a, b in zip(fast, slow, strict=True):
        assert_same(a, b)


def _pose_topics(path: Path) -> list[str]:
    return [t.name for t in summary(path).topics if t.msgtype in POSE_TYPES and t.count]


def _recorded_bags() -> list[Any]:
    """The real 2015 bag and every sample bag with a pose topic, each once (as pytest params);
    the state-only runs (referee-scored RSBB runs, a BmBox-only log) have nothing to read here."""
    real = [pytest.param(REAL_BAG, marks=pytest.mark.real, id="real-2015")]
    return real + [pytest.param(p, id=p.name) for p in sample_bags() if _pose_topics(p)]


@pytest.mark.slow
@pytest.mark.parametrize("path", _recorded_bags())
def test_one_read_of_a_recorded_bag_equals_rosbags_and_the_general_path(
    path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Every pose topic of a bag the loggers of 2015 wrote (or the samples made like them),
    from one read: each as rosbags deserializes it alone, and as the general path decodes it
    (checked spans, layouts per data length, the field decoder)."""
    if not path.exists():
        pytest.skip(f"{path} not present")
    topics = _pose_topics(path)
    assert topics, f"{path.name} has no pose topic"
    fast = fast_many(path, topics)
    monkeypatch.setattr(assemble.Decoder, "fast", lambda *args, **kwargs: False)
    general = fast_many(path, topics)
    for topic, a, b in zip(topics, fast, general, strict=True):
        assert_same(a, b)
        assert_same(a, reference_batch(path, topic))


@pytest.mark.slow_cases("rosbag2-sqlite3", "rosbag2-mcap")
def test_windows_cutting_chunks_in_one_read(scene_bag: tuple[str, Path], scene: Scene) -> None:
    """Each request of one read keeps its own window (the scene's 2000-byte chunks hold a few
    messages each, so every window edge falls inside a chunk)."""
    _fmt, path = scene_bag
    t = scene.t_rec
    windows: list[tuple[int | None, int | None]] = [
        (int(t[7]), int(t[33])),
        (int(t[20]) + 50, None),
        (None, int(t[12]) + 1),
        (int(t[40]), int(t[40])),
        (int(t[3]), int(t[48])),
    ]
    batches = fast_many(path, list(POSE_TOPICS), windows)
    for topic, (lo, hi), batch in zip(POSE_TOPICS, windows, batches, strict=True):
        assert_same(batch, reference_batch(path, topic, lo, hi))
        assert len(batch) > 0


def test_windowed_reads_stay_windowed(
    tmp_path: Path, scene: Scene, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A read of two topics with two windows loads only chunks that overlap one of them."""
    path = write(tmp_path / "w.bag", "ros1", scene.spec, chunk_bytes=1500)
    loaded: list[int] = []
    copied, mapped = ros1_runs.chunk_group, ros1_runs.populated_group

    def spy(bag: Any, chunks: list[Any], scratch: list[Any]) -> Any:
        loaded.extend(c.pos for c in chunks)
        return copied(bag, chunks, scratch)

    def spy_map(bag: Any, chunks: list[Any], scratch: list[Any]) -> Any:
        loaded.extend(c.pos for c in chunks)
        return mapped(bag, chunks, scratch)

    monkeypatch.setattr(ros1_runs, "chunk_group", spy)
    monkeypatch.setattr(ros1_runs, "populated_group", spy_map)
    t = scene.t_rec
    windows: list[tuple[int | None, int | None]] = [
        (int(t[5]), int(t[9])),
        (int(t[38]), int(t[41])),
    ]
    topics = ["/fbm3w/robot_at_work/pose", "/tf"]
    batches = fast_many(path, topics, windows)
    for topic, (lo, hi), batch in zip(topics, windows, batches, strict=True):
        assert_same(batch, reference_batch(path, topic, lo, hi))
    with open_bag(path) as bag:
        spans = {c.pos: (c.start_ns, c.end_ns) for c in bag.layout.chunks}
    assert loaded and len(set(loaded)) < len(spans) // 2
    for pos in loaded:
        a, b = spans[pos]
        assert any(b >= lo and a <= hi for lo, hi in windows if lo is not None and hi is not None)


def _odd_frames_spec(seed: int) -> Spec:
    """Pose topics with frame names whose length changes message by message, three
    publishers mixed on one topic, TF messages with 0 to 3 transforms, and strings of random
    length between them (so records start at every possible alignment)."""
    rng = np.random.default_rng(seed)
    s = Spec()
    pose = [s.conn("/poses", "geometry_msgs/PoseStamped", f"/pub{k}") for k in range(3)]
    flat = [s.conn("/pose2d", "geometry_msgs/Pose2D", f"/flat{k}") for k in range(2)]
    tf = [s.conn("/tf", "tf2_msgs/TFMessage", f"/tf{k}") for k in range(2)]
    odom = s.conn("/odom", "nav_msgs/Odometry")
    text = s.conn("/chatter", "std_msgs/String")
    names = ["", "w", "map", "world", "base_link", "a_rather_long_frame_name", "é"]
    for i in range(240):
        t = T0 + i * DT // 3
        xyz = rng.normal(size=3)
        q = rng.normal(size=4)
        kind = i % 6
        if kind == 0:
            k = int(rng.integers(0, 3))
            frame = names[k + 2] if rng.random() < 0.8 else str(rng.choice(names))
            s.add(pose[k], t, stamp=t - 1000 * k, frame=frame, xyz=xyz, q=q)
        elif kind == 1:
            s.add(flat[int(rng.integers(0, 2))], t, x=xyz[0], y=xyz[1], theta=xyz[2])
        elif kind == 2:
            count = int(rng.choice([0, 1, 1, 1, 2, 3]))
            transforms = [
                dict(stamp=t + j, frame="world", child=str(rng.choice(names)), xyz=xyz, q=q)
                for j in range(count)
            ]
            s.add(tf[int(rng.integers(0, 2))], t, transforms=transforms)
        elif kind == 3:
            s.add(odom, t, stamp=t, frame=str(rng.choice(names)), child="base", xyz=xyz, q=q)
        else:
            s.add(text, t, data="x" * int(rng.integers(0, 17)))
    return s


ODD_TOPICS = ["/poses", "/pose2d", "/tf", "/odom"]


@pytest.mark.slow
@pytest.mark.parametrize("fmt", FORMATS)
def test_odd_frames_mixed_connections_and_alignments_equal_rosbags(
    tmp_path: Path, fmt: str
) -> None:
    path = write(bag_name(tmp_path, fmt), fmt, _odd_frames_spec(5), chunk_bytes=3000)
    batches = fast_many(path, ODD_TOPICS)
    for topic, batch in zip(ODD_TOPICS, batches, strict=True):
        ref = reference_batch(path, topic)
        assert len(ref) > 20
        assert_same(batch, ref)


@pytest.mark.slow
@pytest.mark.parametrize("compression", ["none", "zstd", "lz4"])
def test_mcap_chunk_compressions_equal_rosbags(
    tmp_path: Path, scene: Scene, compression: str
) -> None:
    kind = {"none": CompressionType.NONE, "zstd": CompressionType.ZSTD, "lz4": CompressionType.LZ4}
    path = write(
        tmp_path / f"{compression}.mcap",
        "mcap-ros1",
        scene.spec,
        chunk_bytes=2500,
        compression=kind[compression],
    )
    for topic, batch in zip(POSE_TOPICS, fast_many(path, list(POSE_TOPICS)), strict=True):
        assert_same(batch, reference_batch(path, topic))


@pytest.mark.slow_cases("rosbag2-sqlite3", "rosbag2-mcap")
def test_read_pose_sources_equals_one_source_at_a_time(
    scene_bag: tuple[str, Path], monkeypatch: pytest.MonkeyPatch
) -> None:
    """A topic by header stamps, one by record times and a tf frame: the same streams as
    three reads, from one pass over the file."""
    _fmt, path = scene_bag
    sources = [
        PoseSource(topic="/fbm3w/robot_at_work/pose"),
        PoseSource(topic="/fbm3w/robot_at_work/pose2d", time_source="record"),
        PoseSource(frame="robot_at_work"),
        PoseSource(topic="/fbm3w/tfs", time_source="record"),
    ]
    alone = [reader.read_pose_source(path, s) for s in sources]
    passes: list[int] = []
    real = reader.try_fast_batches

    def spy(bag: Any, requests: Any) -> Any:
        passes.append(len(requests))
        return real(bag, requests)

    monkeypatch.setattr(reader, "try_fast_batches", spy)
    together = reader.read_pose_sources(path, sources)
    with open_bag(path) as bag:
        publishers = len(bag.topic_conns("/tf"))  # (two, but one in rosbag2)
    # one pass: three topics and each /tf publisher (for the frame; no /tf_static)
    assert passes == [3 + publishers]
    for a, b in zip(alone, together, strict=True):
        np.testing.assert_array_equal(a.t_ns, b.t_ns)
        np.testing.assert_array_equal(a.xyz.view(np.int64), b.xyz.view(np.int64))
        np.testing.assert_array_equal(a.quat_xyzw.view(np.int64), b.quat_xyzw.view(np.int64))
        assert (a.frame_id, a.child_frame_id) == (b.frame_id, b.child_frame_id)


def test_read_pose_sources_names_the_missing_source(scene_bag: tuple[str, Path]) -> None:
    _fmt, path = scene_bag
    sources = [PoseSource(topic="/fbm3w/robot_at_work/pose"), PoseSource(topic="/nope")]
    with pytest.raises(TopicError, match=r"/nope not in .* pose topics there: "):
        reader.read_pose_sources(path, sources)


@pytest.mark.slow_cases("rosbag2-sqlite3", "rosbag2-mcap")
def test_state_topics_in_one_pass_equal_one_at_a_time(
    scene_bag: tuple[str, Path], monkeypatch: pytest.MonkeyPatch
) -> None:
    _fmt, path = scene_bag
    alone = [reader.read_states(path, t) for t in STATE_TOPICS]
    passes: list[int] = []
    real = bulk.locate_many

    def spy(bag: Any, requests: Any, progress: Any = None) -> Any:
        passes.append(len(requests))
        return real(bag, requests, progress)

    monkeypatch.setattr(bulk, "locate_many", spy)
    states = reader.read_benchmark_states(path, "fbm3w")
    assert passes == [2]  # the two state topics of the scene, one pass
    for a, b in zip(alone, (states.bmbox, states.refbox), strict=True):
        assert b is not None
        np.testing.assert_array_equal(a.t_ns, b.t_ns)
        np.testing.assert_array_equal(a.state, b.state)
        assert a.payload == b.payload


# --- hostile bytes: the one-gather path refuses nothing the general path accepts, and what
# the general path refuses fails with its own message


def _plain_bag(tmp_path: Path, n: int = 40, chunk_bytes: int = 100_000) -> Path:
    s = Spec()
    pose = s.conn("/p", "geometry_msgs/PoseStamped")
    other = s.conn("/q", "geometry_msgs/PoseStamped")
    for i in range(n):
        t = T0 + i * DT
        s.add(pose, t, stamp=t, frame="world", xyz=(i, 0, 0), q=(0, 0, 0, 1))
        s.add(other, t + 1, stamp=t, frame="map", xyz=(0, i, 0), q=(0, 0, 0, 1))
    return write(tmp_path / "plain.bag", "ros1", s, chunk_bytes=chunk_bytes)


def _record_time_fields(data: bytes) -> Iterator[int]:
    """Where the time value of every message record's header lies (by its field name)."""
    at = data.find(b"\x0d\x00\x00\x00time=")
    while at >= 0:
        yield at + 9
        at = data.find(b"\x0d\x00\x00\x00time=", at + 1)


@pytest.mark.parametrize("what", ["time", "length"])
def test_damaged_record_fails_alike_alone_and_in_one_read(tmp_path: Path, what: str) -> None:
    path = _plain_bag(tmp_path)
    data = bytearray(path.read_bytes())
    # the 11th message record of the chunk (its time, or its data length: 4 bytes after the
    # header, which ends with the time value)
    at = list(_record_time_fields(bytes(data)))[10]
    if what == "time":
        data[at : at + 4] = struct.pack("<I", 12345)
    else:
        data[at + 8 : at + 12] = struct.pack("<I", 1 << 20)
    path.write_bytes(bytes(data))
    with pytest.raises(BagError) as alone:
        reader.read_poses(path, "/p")  # the 11th record, of the even ones
    with pytest.raises(BagError) as together:
        reader.read_pose_sources(path, [PoseSource(topic="/p"), PoseSource(topic="/q")])
    assert str(alone.value) == str(together.value)
    assert "chunk" in str(alone.value)


def test_errors_of_requests_decoded_side_by_side_come_in_request_order(tmp_path: Path) -> None:
    """Two damaged topics in one group of chunks (their requests decoded on two threads): the
    error raised is the first request's, as one thread decoding them in turn raises it."""
    path = _plain_bag(tmp_path)
    data = bytearray(path.read_bytes())
    fields = list(_record_time_fields(bytes(data)))
    at_p, at_q = fields[10], fields[21]  # an even (/p) and an odd (/q) record
    data[at_p : at_p + 4] = struct.pack("<I", 12345)  # /p: time differs from its index entry
    data[at_q + 8 : at_q + 12] = struct.pack("<I", 1 << 20)  # /q: data runs past its chunk
    path.write_bytes(bytes(data))
    errors = {}
    for topic in ("/p", "/q"):
        with pytest.raises(BagError) as alone:
            reader.read_poses(path, topic)
        errors[topic] = str(alone.value)
    assert errors["/p"] != errors["/q"]
    for first, second in (("/p", "/q"), ("/q", "/p")):
        sources = [PoseSource(topic=first), PoseSource(topic=second)]
        with pytest.raises(BagError) as together:
            reader.read_pose_sources(path, sources)
        assert str(together.value) == errors[first]


@pytest.mark.parametrize("fmt", ["ros1", "mcap-cdr"])
def test_a_lone_request_decoded_on_two_lanes_equals_rosbags(
    tmp_path: Path, scene: Scene, monkeypatch: pytest.MonkeyPatch, fmt: str
) -> None:
    """One source of a read has its groups decoded on two lanes at once (their rows written
    into one result side by side): the same rows as rosbags, /tf's two publishers too."""
    path = write(bag_name(tmp_path, fmt, "s"), fmt, scene.spec, chunk_bytes=1500)
    threads: set[str] = set()
    real = assemble.Decoder.run

    def spy(self: assemble.Decoder, run: Any) -> None:
        threads.add(threading.current_thread().name)
        real(self, run)

    monkeypatch.setattr(assemble.Decoder, "run", spy)
    monkeypatch.setattr(pipeline, "GROUP_BYTES", 3000)
    monkeypatch.setattr(pipeline, "workers", lambda: 2)
    for topic in ("/fbm3w/robot_at_work/pose", "/fbm3w/robot_at_work/pose2d", "/tf"):
        threads.clear()
        (batch,) = fast_many(path, [topic])
        assert_same(batch, reference_batch(path, topic))
        assert threads == {"ertools-lane-0", "ertools-lane-1"}


@pytest.mark.parametrize("fmt", ["ros1", "mcap-cdr"])
def test_a_lone_request_of_one_group_is_decoded_on_the_calling_thread(
    tmp_path: Path, scene: Scene, monkeypatch: pytest.MonkeyPatch, fmt: str
) -> None:
    """A source whose chunks make one group (a robot's log) starts no lane: the calling
    thread decodes it, to the same rows as rosbags."""
    path = write(bag_name(tmp_path, fmt, "s"), fmt, scene.spec, chunk_bytes=1500)
    threads: list[str] = []
    real = assemble.Decoder.run

    def spy(self: assemble.Decoder, run: Any) -> None:
        threads.append(threading.current_thread().name)
        real(self, run)

    monkeypatch.setattr(assemble.Decoder, "run", spy)
    monkeypatch.setattr(pipeline, "workers", lambda: 2)
    for topic in ("/fbm3w/robot_at_work/pose", "/fbm3w/robot_at_work/pose2d", "/tf"):
        threads.clear()
        (batch,) = fast_many(path, [topic])
        assert_same(batch, reference_batch(path, topic))
        assert threads == [threading.main_thread().name]


def test_a_lone_request_on_two_lanes_raises_the_first_error(tmp_path: Path) -> None:
    """Two damaged records of one topic in different groups, decoded on two lanes: the error
    raised is the earlier group's, as one thread decoding the groups in turn raises it."""
    path = _plain_bag(tmp_path, n=400, chunk_bytes=2000)
    data = bytearray(path.read_bytes())
    fields = list(_record_time_fields(bytes(data)))
    at_early, at_late = fields[300], fields[700]  # /p records in different groups
    data[at_early + 8 : at_early + 12] = struct.pack("<I", 1 << 20)
    data[at_late : at_late + 4] = struct.pack("<I", 12345)
    path.write_bytes(bytes(data))
    mp = pytest.MonkeyPatch()
    errors = []
    try:
        mp.setattr(pipeline, "GROUP_BYTES", 4000)
        for cores in (1, 2):
            mp.setattr(pipeline, "workers", lambda cores=cores: cores)
            with pytest.raises(BagError) as err:
                reader.read_poses(path, "/p")
            errors.append(str(err.value))
    finally:
        mp.undo()
    assert errors[0] == errors[1]


# --- property tests


@pytest.mark.slow
@settings(max_examples=200, deadline=None)
@given(st.lists(st.lists(st.integers(0, 30), max_size=12), min_size=1, max_size=4), st.data())
def test_merged_columns_are_a_stable_sort(parts: list[list[int]], data: st.DataObject) -> None:
    """Each connection's entries (times, and their places end to end as a second column)
    merged as one stable sort by time orders them: ties keep the connection's rank, then
    their own order; parts not in time order are sorted."""
    arrays = [np.array(sorted(p) if data.draw(st.booleans()) else p, dtype=np.int64) for p in parts]
    t = np.concatenate(arrays)
    cut = np.cumsum([0, *map(len, arrays)]).tolist()
    places = [np.arange(a, b, dtype=np.int64) for a, b in itertools.pairwise(cut)]
    merged_t, order = merged_columns(arrays, [arrays, places])
    expected = np.argsort(t, kind="stable")
    np.testing.assert_array_equal(order, expected)
    np.testing.assert_array_equal(merged_t, t[expected])


# A few bit patterns rosbags must give back as they are: signed zero, the extremes, NaN with a
# payload, infinities.
SPECIAL = [0.0, -0.0, 1e308, -1e-308, 5e-324, float("inf"), float("-inf")]


@st.composite
def layouts(draw: st.DrawFn) -> tuple[Spec, str, int]:
    """A random bag: topics of every pose type on one to three connections each, frame names
    of random lengths, TF messages of random sizes, strings between them."""
    fmt = draw(st.sampled_from(["ros1", "ros1-lz4", "mcap-ros1", "mcap-cdr", "rosbag2-mcap"]))
    s = Spec()
    kinds = {
        "/p": "geometry_msgs/PoseStamped",
        "/f": "geometry_msgs/Pose2D",
        "/tf": "tf2_msgs/TFMessage",
        "/ts": "geometry_msgs/TransformStamped",
    }
    conns = {
        t: [s.conn(t, ty, f"/n{k}") for k in range(draw(st.integers(1, 3)))]
        for t, ty in kinds.items()
    }
    if fmt.startswith("rosbag2"):
        conns = {t: c[:1] for t, c in conns.items()}  # one connection per topic in rosbag2
    text = s.conn("/s", "std_msgs/String")
    names = st.text(alphabet="abcxyz_/", max_size=9)
    value = st.one_of(st.floats(allow_nan=False, width=64), st.sampled_from(SPECIAL))
    n = draw(st.integers(1, 60))
    t = T0
    for _ in range(n):
        t += draw(st.integers(0, 5_000_000))
        topic = draw(st.sampled_from([*kinds, "/s"]))
        xyz = [draw(value) for _ in range(3)]
        q = [draw(value) for _ in range(4)]
        # (rosbags writes the seconds of a stamp as int32 in both encodings)
        stamp = draw(st.integers(0, 2**31 - 1)) * 10**9 + draw(st.integers(0, 10**9 - 1))
        if topic == "/s":
            s.add(text, t, data="y" * draw(st.integers(0, 11)))
            continue
        conn = draw(st.sampled_from(conns[topic]))
        if topic == "/p":
            s.add(conn, t, stamp=stamp, frame=draw(names), xyz=xyz, q=q)
        elif topic == "/f":
            s.add(conn, t, x=xyz[0], y=xyz[1], theta=draw(st.floats(-10, 10)))
        elif topic == "/ts":
            s.add(conn, t, stamp=stamp, frame=draw(names), child=draw(names), xyz=xyz, q=q)
        else:
            transforms = [
                dict(stamp=stamp, frame=draw(names), child=draw(names), xyz=xyz, q=q)
                for _ in range(draw(st.integers(0, 3)))
            ]
            s.add(conn, t, transforms=transforms)
    return s, fmt, draw(st.sampled_from([300, 2000, 100_000]))


@pytest.mark.slow
@settings(
    max_examples=25,
    deadline=None,
    suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow],
)
@given(layouts())
def test_random_layouts_equal_rosbags(
    tmp_path_factory: pytest.TempPathFactory, layout: tuple[Spec, str, int]
) -> None:
    spec, fmt, chunk = layout
    folder = tmp_path_factory.mktemp("random")
    path = write(bag_name(folder, fmt), fmt, spec, chunk_bytes=chunk)
    with open_bag(path) as bag:
        present = [t for t in ("/p", "/f", "/tf", "/ts") if bag.topic_conns(t)]
    if not present:
        return
    for topic, batch in zip(present, fast_many(path, present), strict=True):
        assert_same(batch, reference_batch(path, topic))


# --- tf frames read publisher by publisher


def _publishers_spec(shared: bool) -> Spec:
    """/tf of two publishers: a mocap node whose messages carry world->robot and, every third
    one, world->other too; a second node publishing world->map, and (``shared``) also
    world->robot now and then, at the record time and stamp of a mocap message (a tie the
    read must order as one read of both publishers does)."""
    rng = np.random.default_rng(11)
    s = Spec()
    mocap = s.conn("/tf", "tf2_msgs/TFMessage", "/mocap")
    other = s.conn("/tf", "tf2_msgs/TFMessage", "/other")
    pose = s.conn("/p", "geometry_msgs/PoseStamped")
    for i in range(90):
        t = T0 + i * DT
        xyz, q = rng.normal(size=3), rng.normal(size=4)
        robot = dict(stamp=t - 7, frame="world", child="robot", xyz=xyz, q=q)
        extra = [dict(stamp=t - 5, frame="/world", child="other", xyz=-xyz, q=q)]
        s.add(mocap, t, transforms=[robot, *(extra if i % 3 == 0 else [])])
        s.add(pose, t + 1, stamp=t, frame="world", xyz=xyz, q=q)
        if i % 10 == 0:
            s.add(
                other, t + 2, transforms=[dict(stamp=t, frame="world", child="map", xyz=xyz, q=q)]
            )
        if shared and i % 7 == 0:
            tie = dict(stamp=t - 7, frame="world", child="robot", xyz=2 * xyz, q=-q)
            s.add(other, t, transforms=[tie])
    return s


def _edge_by_hand(path: Path, parent: str, child: str) -> PoseBatch:
    """The rows of one edge of rosbags' /tf, in its order, then stably by stamp (what a tf
    read of one link gives)."""
    ref = reference_batch(path, "/tf")
    rows = np.flatnonzero(
        (np.char.lstrip(ref.frame_names(), "/") == parent) & (ref.child_names() == child)
    )
    rows = rows[np.argsort(ref.t_header[rows], kind="stable")]
    return ref.take(rows)


@pytest.mark.parametrize("shared", [False, True], ids=["own_edges", "shared_edge"])
@pytest.mark.parametrize("fmt", FORMATS)
def test_tf_frames_of_several_publishers_equal_rosbags(
    tmp_path: Path, fmt: str, shared: bool, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Each /tf publisher is its own request; frames of messages with several transforms are
    picked out; an edge two publishers share is read again as one request of both."""
    path = write(bag_name(tmp_path, fmt), fmt, _publishers_spec(shared), chunk_bytes=2500)
    again: list[int] = []
    real = reader.load_pose_batch

    def spy(bag: Any, conns: Any, lo: Any, hi: Any) -> Any:
        again.append(len(conns))
        return real(bag, conns, lo, hi)

    monkeypatch.setattr(reader, "load_pose_batch", spy)
    sources = [PoseSource(topic="/p"), *(PoseSource(frame=f) for f in ("robot", "other", "map"))]
    streams = reader.read_pose_sources(path, sources)
    with open_bag(path) as bag:
        publishers = len(bag.topic_conns("/tf"))  # (one in rosbag2: nothing to share)
    assert again == ([2] if shared and publishers == 2 else [])
    for child, stream in zip(("robot", "other", "map"), streams[1:], strict=True):
        ref = _edge_by_hand(path, "world", child)
        assert len(ref) >= 9 and (stream.frame_id, stream.child_frame_id) == ("world", child)
        np.testing.assert_array_equal(stream.t_ns, ref.t_header)
        np.testing.assert_array_equal(stream.xyz.view(np.int64), ref.xyz.view(np.int64))
        np.testing.assert_array_equal(stream.quat_xyzw.view(np.int64), ref.quat_xyzw.view(np.int64))


@pytest.mark.parametrize("fmt", ["ros1", "ros1-lz4", "mcap-cdr", "mcap-ros1"])
def test_a_request_of_one_publisher_reads_only_its_messages(tmp_path: Path, fmt: str) -> None:
    """One connection of a topic of several (an MCAP channel too, not the whole topic)."""
    path = write(bag_name(tmp_path, fmt), fmt, _publishers_spec(True), chunk_bytes=2500)
    with open_bag(path) as bag, reference_bag(path) as ref:
        conns = bag.topic_conns("/tf")
        assert len(conns) == 2
        fast = bulk.try_fast_batches(bag, [Request((c,)) for c in conns])
        for conn, batch in zip(conns, fast, strict=True):
            assert batch is not None
            expected = reader.slow_pose_batch(
                ref, [c for c in ref.connections if c.id == conn.id], None, None
            )
            assert 9 <= len(expected) < len(reference_batch(path, "/tf"))
            assert_same(batch, expected)
