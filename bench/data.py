"""The benchmark's data: an hour of 120 Hz mocap GT as the 2015 loggers wrote it, a 10 Hz robot
log of the same hour, and 1000 small GT bags. Deterministic (seeded), cached under build/bench/.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import numpy.typing as npt
from bagwrite import Topic, build, msgdef, typestore, write_mcap, write_ros1

F64 = npt.NDArray[np.float64]
I64 = npt.NDArray[np.int64]

T0 = 1_448_017_200_000_000_000  # 2015-11-20 11:00:00 UTC
RATE_HZ = 120
NS = 1_000_000_000
NS_BODY = "/fbm3w/robot_at_work"
GT_TOPIC = f"{NS_BODY}/pose"
ROBOT_TOPIC = "/rockin/homer/marker_pose"
PS, P2D, TFM = "geometry_msgs/PoseStamped", "geometry_msgs/Pose2D", "tf2_msgs/TFMessage"
VERSION = 6  # bump to regenerate the cache
LONG_VERSION = 1  # the same for the long GT (generate_long)
LONG_HOURS = 8
ROBOT_WINDOW_S = 20 * 60


def trajectory(t_s: F64) -> tuple[F64, F64]:
    """A robot driving loops around a 10 m x 6 m arena: positions (N,3), yaw (N,)."""
    x = 5.0 + 3.0 * np.sin(2 * np.pi * t_s / 60.0)
    y = 3.0 + 2.0 * np.sin(2 * np.pi * t_s / 45.0)
    dx = 3.0 * 2 * np.pi / 60.0 * np.cos(2 * np.pi * t_s / 60.0)
    dy = 2.0 * 2 * np.pi / 45.0 * np.cos(2 * np.pi * t_s / 45.0)
    return np.column_stack([x, y, np.full_like(x, 0.21)]), np.arctan2(dy, dx)


def quat(yaw: F64) -> F64:
    z = np.zeros_like(yaw)
    return np.column_stack([z, z, np.sin(yaw / 2), np.cos(yaw / 2)])


def gt_topics(
    start_ns: int, seconds: float, seed: int, ros1: bool = True, body: str = NS_BODY
) -> list[Topic]:
    """PoseStamped + Pose2D + /tf (mocap, 120 Hz) of ``body`` (a namespace) and the static
    world->map on /tf (10 Hz)."""
    rng = np.random.default_rng(seed)
    ts = typestore(ros1)
    n = int(seconds * RATE_HZ)
    stamp = start_ns + (np.arange(n, dtype=np.int64) * NS) // RATE_HZ
    rec = stamp + 3_000_000 + rng.integers(0, 400_000, n)  # logger receives ~3 ms later
    xyz, yaw = trajectory((stamp - T0) / NS)
    xyz = xyz + rng.normal(0, 0.0002, xyz.shape)  # 0.2 mm mocap noise
    q = quat(yaw)
    pose7 = np.column_stack([xyz, q])
    m = int(seconds * 10)
    st_stamp = start_ns + np.arange(m, dtype=np.int64) * NS // 10
    st_rec = st_stamp + 1_000_000
    static7 = np.tile([1.0, 2.0, 0.0, 0.0, 0.0, 0.0, 1.0], (m, 1))
    out = []
    pose2d = np.column_stack([xyz[:, :2], yaw])
    for name, msgtype, t, data in (
        (f"{body}/pose", PS, rec, build(ts, PS, stamp, pose7, ros1=ros1)),
        (f"{body}/pose2d", P2D, rec + 50_000, build(ts, P2D, stamp, pose2d, ros1=ros1)),
        (
            "/tf",
            TFM,
            rec + 100_000,
            build(ts, TFM, stamp, pose7, child=body.rsplit("/", 1)[-1], ros1=ros1),
        ),
    ):
        text, md5 = msgdef(ts, msgtype, ros1)
        out.append(Topic(name, msgtype, text, md5, t, data))
    text, md5 = msgdef(ts, "tf2_msgs/TFMessage", ros1)
    static = build(ts, "tf2_msgs/TFMessage", st_stamp, static7, child="map", ros1=ros1)
    out.append(Topic("/tf", "tf2_msgs/TFMessage", text, md5, st_rec, static, "/static_tf_pub"))
    return out


def robot_topics(start_ns: int, seconds: float, seed: int) -> list[Topic]:
    """The robot's own 10 Hz estimate of its marker pose: GT + 2 cm / 1 degree errors."""
    rng = np.random.default_rng(seed)
    ts = typestore(True)
    n = int(seconds * 10)
    stamp = start_ns + np.arange(n, dtype=np.int64) * NS // 10 + 40_000_000
    xyz, yaw = trajectory((stamp - T0) / NS)
    xyz = xyz + rng.normal(0, 0.02, xyz.shape)
    yaw = yaw + rng.normal(0, np.radians(1.0), n)
    data = build(ts, "geometry_msgs/PoseStamped", stamp, np.column_stack([xyz, quat(yaw)]))
    text, md5 = msgdef(ts, "geometry_msgs/PoseStamped")
    return [
        Topic(
            ROBOT_TOPIC, "geometry_msgs/PoseStamped", text, md5, stamp + 2_000_000, data, "/homer"
        )
    ]


def camera_topic(start_ns: int, seconds: float, size: int = 16 * 1024) -> Topic:
    """A 10 Hz ``sensor_msgs/Image`` of ``size`` bytes of pixels (all frames alike): the heavy
    topic a robot's own log carries next to its pose, never decoded by the pose reader."""
    ts = typestore(True)
    t = ts.types
    n = int(seconds * 10)
    msg = t["sensor_msgs/msg/Image"](
        header=t["std_msgs/msg/Header"](
            seq=0, stamp=t["builtin_interfaces/msg/Time"](sec=0, nanosec=0), frame_id="camera"
        ),
        height=64,
        width=size // 64,
        encoding="mono8",
        is_bigendian=0,
        step=size // 64,
        data=np.zeros(size, dtype=np.uint8),
    )
    raw = np.frombuffer(bytes(ts.serialize_ros1(msg, "sensor_msgs/msg/Image")), dtype=np.uint8)
    stamp = start_ns + np.arange(n, dtype=np.int64) * NS // 10 + 20_000_000
    text, md5 = msgdef(ts, "sensor_msgs/Image")
    return Topic(
        "/homer/camera/image", "sensor_msgs/Image", text, md5, stamp, np.tile(raw, (n, 1)), "/homer"
    )


def check_readback(path: Path, topics: list[Topic], first: int = 3000) -> None:
    """rosbags reads the file back identically: message counts, record times and the raw
    bytes of the first messages of every connection, and a deserialized first pose."""
    from itertools import islice

    from rosbags.highlevel import AnyReader

    with AnyReader([path]) as reader:
        expected = sum(len(t.t_ns) for t in topics)
        if reader.message_count != expected:
            raise SystemExit(f"{path}: rosbags counts {reader.message_count}, wrote {expected}")
        conns = [c for c in reader.connections]
        for topic in topics:
            # connections of one topic are told apart by their message count
            conn = next(c for c in conns if c.topic == topic.name and c.msgcount == len(topic.t_ns))
            for i, (_c, t, raw) in enumerate(islice(reader.messages([conn]), first)):
                if t != topic.t_ns[i] or bytes(raw) != topic.data[i].tobytes():
                    raise SystemExit(f"{path}: {topic.name} message {i} reads back differently")
            if topic.msgtype == PS:
                _c, _t, raw = next(reader.messages([conn]))
                msg = reader.deserialize(raw, conn.msgtype)
                got = np.frombuffer(topic.data[0][-56:].tobytes(), "<f8")
                p, q = msg.pose.position, msg.pose.orientation
                if not np.array_equal(got, [p.x, p.y, p.z, q.x, q.y, q.z, q.w]):
                    raise SystemExit(f"{path}: {topic.name} first pose deserializes differently")


def generate(folder: Path, small_bags: int = 1000) -> dict[str, Path]:
    """Write (or reuse) every benchmark file; returns name -> path."""
    folder.mkdir(parents=True, exist_ok=True)
    stamp = folder / "generated.json"
    paths = {
        "gt": folder / "gt_hour.bag",
        "gt_lz4": folder / "gt_hour_lz4.bag",
        "gt_bz2": folder / "gt_hour_bz2.bag",
        "gt_mcap": folder / "gt_hour.mcap",
        "gt_mcap_none": folder / "gt_hour_uncompressed.mcap",
        "robot": folder / "robot_hour.bag",
        "robot_fat": folder / "robot_hour_with_camera.bag",
        "combined": folder / "gt_and_robot_hour.bag",
        "small": folder / "small_bags",
    }
    if stamp.exists() and json.loads(stamp.read_text()).get("version") == VERSION:
        return paths
    for p in paths.values():
        if p.is_file():
            p.unlink()
    hour = gt_topics(T0, 3600, seed=1)
    write_ros1(paths["gt"], hour)
    write_ros1(paths["gt_lz4"], hour, "lz4")
    write_ros1(paths["gt_bz2"], hour, "bz2")
    robot = robot_topics(T0, 3600, seed=2)
    write_ros1(paths["robot"], robot)
    write_ros1(paths["robot_fat"], [*robot, camera_topic(T0, 3600)])
    write_ros1(paths["combined"], [*hour, *robot])
    for key in ("gt", "gt_lz4", "gt_bz2"):
        check_readback(paths[key], hour)
    check_readback(paths["robot"], robot)
    del hour
    hour2 = gt_topics(T0, 3600, seed=1, ros1=False)
    ts2 = typestore(False)
    schemas = {t.msgtype: msgdef(ts2, t.msgtype, False)[0] for t in hour2}
    write_mcap(paths["gt_mcap"], hour2, schemas, "zstd")
    write_mcap(paths["gt_mcap_none"], hour2, schemas, "none")
    check_readback(paths["gt_mcap"], hour2)
    check_readback(paths["gt_mcap_none"], hour2)
    del hour2
    small = paths["small"]
    small.mkdir(exist_ok=True)
    for i in range(small_bags):
        start = T0 + i * 2 * NS
        target = small / f"log_fbm3w_mocap_{i:04d}.bag"
        if target.exists():
            target.unlink()
        write_ros1(target, gt_topics(start, 1.0, seed=100 + i))
    stamp.write_text(json.dumps({"version": VERSION}))
    return paths


def generate_long(folder: Path) -> dict[str, Path]:
    """Write (or reuse) an 8-hour GT log (bench/data.py's hour, 8 times as long: 1.3 GB) and
    a 20-minute robot log in its fifth hour: a robot's run scored against a day's mocap log,
    of which only the window it spans is read."""
    folder.mkdir(parents=True, exist_ok=True)
    stamp = folder / "generated_long.json"
    paths = {
        "gt_long": folder / f"gt_{LONG_HOURS}_hours.bag",
        "robot_window": folder / "robot_20_minutes.bag",
    }
    if stamp.exists() and json.loads(stamp.read_text()).get("version") == LONG_VERSION:
        return paths
    stamp.unlink(missing_ok=True)
    gt = gt_topics(T0, LONG_HOURS * 3600, seed=11)
    write_ros1(paths["gt_long"], gt)
    check_readback(paths["gt_long"], gt)
    del gt
    robot = robot_topics(T0 + 4 * 3600 * NS, ROBOT_WINDOW_S, seed=12)
    write_ros1(paths["robot_window"], robot)
    check_readback(paths["robot_window"], robot)
    stamp.write_text(json.dumps({"version": LONG_VERSION}))
    return paths
