"""BagWriter: bulk serialisation byte-exact, round trips over every format, stored definitions."""

from __future__ import annotations

import hashlib
import time
from pathlib import Path

import numpy as np
import pytest
from mcap.reader import make_reader
from rosbags.highlevel import AnyReader
from rosbags.rosbag1 import Reader

from ertools.errors import UsageError
from ertools.simulator.packing import pack_messages
from ertools.simulator.writer import FORMATS, BagWriter
from ertools.states import MSG_TYPES, BmBoxState, ClientState, Machine

T0 = 1_448_013_600_123_456_789


def _path(tmp_path: Path, fmt: str) -> Path:
    return tmp_path / {"ros1": "x.bag", "mcap": "x.mcap"}.get(fmt, "x_rosbag2")


def _reference_objects(bag: BagWriter, frame: str, child: str) -> list[tuple[str, object]]:
    """The same messages built as rosbags objects, serialised by rosbags itself."""
    c = bag.msgclass
    sec, nsec = divmod(T0, 1_000_000_000)
    stamp = c("builtin_interfaces/Time")(sec=sec, nanosec=nsec)
    header = (
        c("std_msgs/Header")(stamp=stamp, frame_id=frame)
        if bag.ros2
        else c("std_msgs/Header")(seq=0, stamp=stamp, frame_id=frame)
    )
    pose = c("geometry_msgs/Pose")(
        position=c("geometry_msgs/Point")(x=1.5, y=-2.25, z=0.125),
        orientation=c("geometry_msgs/Quaternion")(x=0.1, y=0.2, z=0.3, w=0.9),
    )
    tf = c("geometry_msgs/TransformStamped")(
        header=header,
        child_frame_id=child,
        transform=c("geometry_msgs/Transform")(
            translation=c("geometry_msgs/Vector3")(x=1.5, y=-2.25, z=0.125),
            rotation=c("geometry_msgs/Quaternion")(x=0.1, y=0.2, z=0.3, w=0.9),
        ),
    )
    return [
        ("geometry_msgs/msg/PoseStamped", c("geometry_msgs/PoseStamped")(header=header, pose=pose)),
        ("geometry_msgs/msg/Pose2D", c("geometry_msgs/Pose2D")(x=1.5, y=-2.25, theta=0.75)),
        ("tf2_msgs/msg/TFMessage", c("tf2_msgs/TFMessage")(transforms=[tf])),
    ]


@pytest.mark.parametrize("ros2", [False, True])
@pytest.mark.parametrize("frame", ["", "w", "ab", "abc", "world", "abcdefgh"])
def test_bulk_packing_matches_rosbags_serialiser(tmp_path: Path, ros2: bool, frame: str) -> None:
    # Frame lengths 0..8 walk the CDR string padding through every alignment case.
    bag = BagWriter(tmp_path / ("y" if ros2 else "y.bag"), "mcap" if ros2 else "ros1")
    child = frame[::-1] + "c"
    refs = dict(_reference_objects(bag, frame, child))
    sec, nsec = divmod(T0, 1_000_000_000)
    pose = np.array([[1.5, -2.25, 0.125, 0.1, 0.2, 0.3, 0.9]])
    header = (
        [("i4", [sec]), ("u4", [nsec])] if ros2 else [("u4", [0]), ("u4", [sec]), ("u4", [nsec])]
    )
    ours = {
        "geometry_msgs/msg/PoseStamped": [*header, ("str", frame), ("f8", pose)],
        "geometry_msgs/msg/Pose2D": [("f8", np.array([[1.5, -2.25, 0.75]]))],
        "tf2_msgs/msg/TFMessage": [
            ("u4", [1]),
            *header,
            ("str", frame),
            ("str", child),
            ("f8", pose),
        ],
    }
    for msgtype, fields in ours.items():
        packed = pack_messages(1, fields, cdr=ros2)[0].tobytes()
        assert packed == bag.serialize(refs[msgtype], msgtype), msgtype


def _write_everything(path: Path, fmt: str) -> dict[str, object]:
    n = 50
    t_hdr = T0 + np.arange(n, dtype=np.int64) * 8_333_333
    xyz = np.column_stack([np.linspace(0, 1, n), np.linspace(1, 2, n), np.full(n, 0.3)])
    yaw = np.linspace(-1, 1, n)
    quat = np.column_stack([np.zeros(n), np.zeros(n), np.sin(yaw / 2), np.cos(yaw / 2)])
    with BagWriter(path, fmt) as bag:  # type: ignore[arg-type]
        # Written out of time order on purpose: the file must come out sorted.
        bag.write_state(Machine.CLIENT, "/fbm3w/client_state", T0 + 5, ClientState.READY, "r")
        bag.write_pose_stamped(
            "/fbm3w/robot_at_work/pose", t_hdr + 300_000, t_hdr, "world", xyz, quat, callerid="/m"
        )
        bag.write_pose2d("/fbm3w/robot_at_work/pose2d", t_hdr + 310_000, xyz[:, 0], xyz[:, 1], yaw)
        bag.write_tf(t_hdr + 320_000, t_hdr, "world", "robot_at_work", xyz, quat, callerid="/m")
        bag.write_tf(T0, T0 + 100_000_000, "world", "map", (0, 0, 0), (0, 0, 0, 1), callerid="/s")
        bag.write_state(
            Machine.BMBOX,
            "/fbm3w/bmbox_state",
            [T0, T0 + 100_000_000],
            [BmBoxState.READY, BmBoxState.TRANSMITTING_GOAL],
            ["", "line"],
        )
        bag.write_string("/note", T0 + 7, "hello")
        bag.write_log(T0 + 1, T0, "/fbm3w/mocap_node", "NATNet Version : 2.7.0.0")
        bag.write_map("fbm3w", T0 + 2, T0 - 5, np.array([[0, 100, -1], [0, 0, 100]], np.int8))
    return {"t_hdr": t_hdr, "xyz": xyz, "quat": quat, "yaw": yaw}


@pytest.mark.slow_cases("rosbag2-mcap")
@pytest.mark.parametrize("fmt", FORMATS)
def test_round_trip_every_format(tmp_path: Path, fmt: str) -> None:
    path = _path(tmp_path, fmt)
    truth = _write_everything(path, fmt)
    counts: dict[str, int] = {}
    types: dict[str, str] = {}
    times: list[int] = []
    poses, tf_body, pose2d, bm = [], [], [], []
    with AnyReader([path]) as reader:
        for conn, t, raw in reader.messages():
            msg = reader.deserialize(raw, conn.msgtype)
            counts[conn.topic] = counts.get(conn.topic, 0) + 1
            types[conn.topic] = conn.msgtype
            times.append(t)
            if conn.topic.endswith("/pose"):
                p, q = msg.pose.position, msg.pose.orientation
                stamp = msg.header.stamp.sec * 1_000_000_000 + msg.header.stamp.nanosec
                poses.append((t, stamp, p.x, p.y, p.z, q.x, q.y, q.z, q.w, msg.header.frame_id))
            elif conn.topic.endswith("/pose2d"):
                pose2d.append((msg.x, msg.y, msg.theta))
            elif conn.topic == "/tf":
                tr = msg.transforms[0]
                if tr.child_frame_id == "robot_at_work":
                    tf_body.append(tr.transform.translation.x)
            elif conn.topic == "/fbm3w/bmbox_state":
                bm.append((t, msg.state, msg.payload))
            elif conn.topic == "/rosout":
                assert msg.msg == "NATNet Version : 2.7.0.0"
            elif conn.topic == "/fbm3w/map":
                assert (msg.info.width, msg.info.height) == (3, 2)
                assert msg.data.tolist() == [0, 100, -1, 0, 0, 100]
    assert counts == {
        "/fbm3w/client_state": 1,
        "/fbm3w/robot_at_work/pose": 50,
        "/fbm3w/robot_at_work/pose2d": 50,
        "/tf": 51,
        "/fbm3w/bmbox_state": 2,
        "/note": 1,
        "/rosout": 1,
        "/fbm3w/map": 1,
        "/fbm3w/map_metadata": 1,
    }
    assert types["/fbm3w/bmbox_state"] == "rockin_scoring/msg/BmBoxState"
    assert types["/tf"] == "tf2_msgs/msg/TFMessage"
    assert types["/rosout"] == (
        "rosgraph_msgs/msg/Log" if fmt == "ros1" else "rcl_interfaces/msg/Log"
    )
    assert times == sorted(times)
    arr = np.array([row[:9] for row in poses], dtype=object)
    t_hdr = truth["t_hdr"]
    assert isinstance(t_hdr, np.ndarray)
    assert [int(v) for v in arr[:, 0]] == (t_hdr + 300_000).tolist()
    assert [int(v) for v in arr[:, 1]] == t_hdr.tolist()
    # Exact equality: float64 values go through the file unchanged.
    assert np.array_equal(np.array(arr[:, 2:5], float), truth["xyz"])
    assert np.array_equal(np.array(arr[:, 5:9], float), truth["quat"])
    assert {row[9] for row in poses} == {"world"}
    assert np.array_equal(np.array(pose2d)[:, 2], truth["yaw"])
    assert np.array_equal(np.array(tf_body), np.asarray(truth["xyz"])[:, 0])
    assert bm == [
        (T0, BmBoxState.READY, ""),
        (T0 + 100_000_000, BmBoxState.TRANSMITTING_GOAL, "line"),
    ]


def _ros_md5(definition: str) -> str:
    """ROS1 md5sum of a message with only constants and primitive fields (genmsg's rule)."""
    lines = []
    for line in definition.splitlines():
        line = line.strip()
        if not line:
            continue
        if "=" in line:
            decl, value = line.split("=")
            lines.append(f"{' '.join(decl.split())}={value.strip()}")
        else:
            lines.append(" ".join(line.split()))
    consts = [x for x in lines if "=" in x]
    fields = [x for x in lines if "=" not in x]
    return hashlib.md5("\n".join(consts + fields).encode()).hexdigest()


def test_ros1_stores_custom_definitions_and_caller_ids(tmp_path: Path) -> None:
    path = tmp_path / "x.bag"
    _write_everything(path, "ros1")
    with Reader(path) as reader:
        conns = {(c.topic, c.ext.callerid): c for c in reader.connections}
    bm = conns[("/fbm3w/bmbox_state", None)]
    assert bm.msgtype == "rockin_scoring/msg/BmBoxState"
    assert "uint8 WAITING_CLIENT=1" in bm.msgdef.data.replace(" = ", "=")
    assert "string payload" in bm.msgdef.data
    assert bm.digest == _ros_md5(bm.msgdef.data)
    # Two /tf connections told apart by their publisher, as in the 2015 bags.
    assert {cid for (topic, cid) in conns if topic == "/tf"} == {"/m", "/s"}
    assert conns[("/rosout", "/fbm3w/mocap_node")].ext.latching == 1


@pytest.mark.parametrize("fmt", ["mcap", "rosbag2-mcap"])
def test_ros2_formats_store_custom_definitions(tmp_path: Path, fmt: str) -> None:
    path = _path(tmp_path, fmt)
    _write_everything(path, fmt)
    file = path if fmt == "mcap" else next(path.glob("*.mcap"))
    with file.open("rb") as fh:
        summary = make_reader(fh).get_summary()
    assert summary is not None
    schemas = {s.name: s for s in summary.schemas.values()}
    client = schemas["rockin_scoring/msg/ClientState"]
    assert client.encoding == "ros2msg"
    assert b"uint8 COMPLETED_GOAL=5" in client.data.replace(b" = ", b"=")
    assert {c.message_encoding for c in summary.channels.values()} == {"cdr"}


def test_state_type_names_follow_states_module() -> None:
    assert MSG_TYPES[Machine.BMBOX] == "rockin_scoring/BmBoxState"


def test_writer_refuses_existing_path_and_bad_options(tmp_path: Path) -> None:
    existing = tmp_path / "a.bag"
    existing.write_bytes(b"")
    with pytest.raises(UsageError, match="exists"):
        BagWriter(existing)
    with pytest.raises(UsageError, match="format"):
        BagWriter(tmp_path / "b.bag", "ros3")  # type: ignore[arg-type]
    with pytest.raises(UsageError, match="compression"):
        BagWriter(tmp_path / "c.bag", "ros1", compression="zstd")
    with pytest.raises(UsageError, match="no messages"), BagWriter(tmp_path / "d.bag"):
        pass


@pytest.mark.parametrize("compression", ["bz2", "lz4"])
def test_ros1_compressed_chunks(tmp_path: Path, compression: str) -> None:
    path = tmp_path / "c.bag"
    with BagWriter(path, "ros1", compression=compression) as bag:
        bag.write_pose2d("/p", T0 + np.arange(1000), np.arange(1000.0), 0.0, 0.0)
    with Reader(path) as reader:
        xs = [np.frombuffer(raw, "<f8")[0] for _, _, raw in reader.messages()]
    assert xs == list(np.arange(1000.0))
    # The chunk record header names its compression (ROS bag v2.0 format).
    data = path.read_bytes()
    assert f"compression={compression}".encode() in data
    assert b"compression=none" not in data


@pytest.mark.parametrize(
    ("fmt", "compression"), [("rosbag2-mcap", "zstd"), ("mcap", "zstd"), ("mcap", "lz4")]
)
def test_ros2_compressed_round_trip(tmp_path: Path, fmt: str, compression: str) -> None:
    path = _path(tmp_path, fmt)
    with BagWriter(path, fmt, compression=compression) as bag:  # type: ignore[arg-type]
        bag.write_pose2d("/p", T0 + np.arange(2000), np.arange(2000.0), 1.0, 2.0)
    with AnyReader([path]) as reader:
        xs = [reader.deserialize(raw, c.msgtype).x for c, _, raw in reader.messages()]
    assert xs == list(np.arange(2000.0))


@pytest.mark.slow
@pytest.mark.xdist_group("timing")
def test_bulk_write_speed(tmp_path: Path) -> None:
    n = 100_000
    t = T0 + np.arange(n, dtype=np.int64) * 8_333_333
    xyz = np.zeros((n, 3))
    start = time.perf_counter()
    with BagWriter(tmp_path / "big.bag") as bag:
        bag.write_pose_stamped("/b/pose", t + 300_000, t, "world", xyz, (0, 0, 0, 1))
    elapsed = time.perf_counter() - start
    # Measured ~0.6 s; the issue asks for ~100k messages "in a few seconds". 10 s leaves room
    # for a slow CI machine while still catching a per-message rosbags serialise (~3x slower
    # plus object construction) gone quadratic.
    assert elapsed < 10.0
    assert (tmp_path / "big.bag").stat().st_size > n * 85


def test_write_many_keeps_call_order_for_equal_times(tmp_path: Path) -> None:
    path = tmp_path / "m.bag"
    with BagWriter(path) as bag:
        conn = bag.connection("/s", "std_msgs/String")
        cls = bag.msgclass("std_msgs/String")
        bag.write_many(conn, [T0 + 2, T0, T0], [cls(data="c"), cls(data="a"), cls(data="b")])
        bag.write(conn, T0 + 1, cls(data="between"))
        with pytest.raises(UsageError, match="2 times for 1"):
            bag.write_many(conn, [T0, T0], [cls(data="x")])
    with AnyReader([path]) as reader:
        got = [(t, reader.deserialize(raw, c.msgtype).data) for c, t, raw in reader.messages()]
    # Sorted by record time; the two messages at T0 stay in the order they were written.
    assert got == [(T0, "a"), (T0, "b"), (T0 + 1, "between"), (T0 + 2, "c")]
