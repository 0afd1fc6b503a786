"""`ertools export` / ertools.exporting.formats: files read back with NumPy give the written
poses back.

The expected values are the generator's (conftest.make_scene: stamps, positions, quaternions
written into every bag format) and, for the sample bag, the messages as rosbags reads them:
never ertools' own reader. Positions and quaternions are written as repr, which parses back
to the same double, so TUM and CSV values compare exactly; times are compared in integer
nanoseconds.
"""

from __future__ import annotations

import math
from decimal import Decimal
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from rosbags.highlevel import AnyReader

from ertools.cli.main import main
from ertools.errors import BagError
from ertools.exporting.formats import (
    format_csv,
    format_tum,
    rotation_matrices,
    seconds_text,
    write_poses,
)
from ertools.streams import PoseStream
from tests.helpers.scene import Scene

POSE = "/fbm3w/robot_at_work/pose"
REPO = Path(__file__).resolve().parents[2]
SAMPLE_GT = REPO / "sample_bags/robotlog/log_fbm2h_mocap_2015-11-20-11-59-59_0.bag"
SAMPLE_TOPIC = "/fbm2h/robot_at_home/pose"


def _ns(text: str) -> int:
    """Decimal seconds text to int ns, exactly (Decimal, not float)."""
    return int(Decimal(text) * 1_000_000_000)


def _read_tum(path: Path) -> tuple[np.ndarray, np.ndarray]:
    """(t_ns, 7 value columns) of a TUM file: the stamp column parsed as text, the rest by NumPy."""
    stamps = np.loadtxt(path, usecols=0, dtype=str, ndmin=1)
    values = np.loadtxt(path, usecols=range(1, 8), ndmin=2)
    return np.array([_ns(s) for s in stamps], dtype=np.int64), values


def _quat_matrix(q: np.ndarray) -> np.ndarray:
    """Rotation matrices of unit quaternions (x, y, z, w), the textbook formula."""
    x, y, z, w = (q / np.linalg.norm(q, axis=1, keepdims=True)).T
    return np.stack(
        [
            np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)], 1),
            np.stack([2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)], 1),
            np.stack([2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)], 1),
        ],
        1,
    )


@pytest.mark.slow_cases("rosbag2-mcap", "rosbag2-sqlite3")
def test_tum_round_trip_every_format(
    scene: Scene, scene_bag: tuple[str, Path], tmp_path: Path
) -> None:
    _, bag = scene_bag
    out = tmp_path / "poses.tum"
    assert main(["export", str(bag), "--topic", POSE, "--format", "tum", "-o", str(out)]) == 0
    t_ns, v = _read_tum(out)
    np.testing.assert_array_equal(t_ns, scene.t_hdr)
    np.testing.assert_array_equal(v[:, :3], scene.xyz)
    np.testing.assert_array_equal(v[:, 3:], scene.quat)


def test_csv_round_trip_every_format(
    scene: Scene, scene_bag: tuple[str, Path], tmp_path: Path
) -> None:
    _, bag = scene_bag
    out = tmp_path / "poses.csv"
    args = ["export", str(bag), "--topic", POSE, "--time-source", "record", "--format", "csv"]
    assert main([*args, "-o", str(out)]) == 0
    lines = out.read_text().splitlines()
    assert lines[0] == "t_ns,t_s,x,y,z,qx,qy,qz,qw,frame_id"
    assert len(lines) == scene.n + 1
    t_ns = np.loadtxt(out, delimiter=",", skiprows=1, usecols=0, dtype=np.int64)
    t_s = np.loadtxt(out, delimiter=",", skiprows=1, usecols=1, dtype=str)
    v = np.loadtxt(out, delimiter=",", skiprows=1, usecols=range(2, 9))
    frames = np.loadtxt(out, delimiter=",", skiprows=1, usecols=9, dtype=str)
    np.testing.assert_array_equal(t_ns, scene.t_rec)  # --time-source record
    np.testing.assert_array_equal([_ns(s) for s in t_s], scene.t_rec)
    np.testing.assert_array_equal(v[:, :3], scene.xyz)
    np.testing.assert_array_equal(v[:, 3:], scene.quat)
    assert set(frames.tolist()) == {"world"}


def test_kitti_round_trip_and_times(
    scene: Scene, scene_bag: tuple[str, Path], tmp_path: Path
) -> None:
    _, bag = scene_bag
    out, times = tmp_path / "poses.kitti", tmp_path / "times.txt"
    args = ["export", str(bag), "--topic", POSE, "--format", "kitti", "-o", str(out)]
    assert main([*args, "--times", str(times)]) == 0
    m = np.loadtxt(out).reshape(-1, 3, 4)
    assert m.shape == (scene.n, 3, 4)
    np.testing.assert_array_equal(m[:, :, 3], scene.xyz)  # positions are written as they are
    # SciPy's matrix vs the textbook formula: a few ulp apart.
    np.testing.assert_allclose(m[:, :, :3], _quat_matrix(scene.quat), rtol=0, atol=1e-12)
    t = [_ns(s) for s in np.loadtxt(times, dtype=str)]
    np.testing.assert_array_equal(t, scene.t_hdr - scene.t_hdr[0])


def test_tf_source_is_the_pose_of_the_child(
    scene: Scene, scene_bag: tuple[str, Path], tmp_path: Path
) -> None:
    _, bag = scene_bag
    out = tmp_path / "tf.tum"
    assert main(["export", str(bag), "--tf", "world:robot_at_work", "-o", str(out)]) == 0
    t_ns, v = _read_tum(out)
    np.testing.assert_array_equal(t_ns, scene.t_hdr)
    np.testing.assert_array_equal(v[:, :3], scene.xyz)
    np.testing.assert_array_equal(v[:, 3:], scene.quat)


def _rosbags_poses(path: Path, topic: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Header stamps, positions and quaternions of a PoseStamped topic, read by rosbags."""

    t, xyz, q = [], [], []
    with AnyReader([path]) as reader:
        conns = [c for c in reader.connections if c.topic == topic]
        for conn, _, raw in reader.messages(connections=conns):
            msg = reader.deserialize(raw, conn.msgtype)
            t.append(msg.header.stamp.sec * 1_000_000_000 + msg.header.stamp.nanosec)
            p, o = msg.pose.position, msg.pose.orientation
            xyz.append((p.x, p.y, p.z))
            q.append((o.x, o.y, o.z, o.w))
    return np.array(t, dtype=np.int64), np.array(xyz), np.array(q)


@pytest.mark.slow
@pytest.mark.parametrize("fmt", ["tum", "csv"])
def test_sample_bag_against_rosbags(
    fmt: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    t, xyz, q = _rosbags_poses(SAMPLE_GT, SAMPLE_TOPIC)
    assert len(t) > 1000
    # stdout without -o: the text is pipeable
    assert main(["export", str(SAMPLE_GT), "--topic", SAMPLE_TOPIC, "--format", fmt]) == 0
    out = tmp_path / f"x.{fmt}"
    out.write_text(capsys.readouterr().out)
    if fmt == "tum":
        got_t, v = _read_tum(out)
    else:
        got_t = np.loadtxt(out, delimiter=",", skiprows=1, usecols=0, dtype=np.int64)
        v = np.loadtxt(out, delimiter=",", skiprows=1, usecols=range(2, 9))
    order = np.argsort(t, kind="stable")  # ertools writes time order; rosbags gives record order
    np.testing.assert_array_equal(got_t, t[order])
    np.testing.assert_allclose(v[:, :3], xyz[order], rtol=0, atol=1e-12)
    np.testing.assert_allclose(v[:, 3:], q[order], rtol=0, atol=1e-12)


@pytest.mark.slow
@given(st.lists(st.integers(-(2**62), 2**62), min_size=1, max_size=50))
def test_seconds_text_is_exact(ns: list[int]) -> None:
    text = seconds_text(np.array(ns, dtype=np.int64))
    assert [_ns(s) for s in text] == ns
    assert all(len(s.split(".")[1]) == 9 for s in text)


def test_seconds_text_by_hand() -> None:
    got = seconds_text(np.array([0, 1, -1, -500_000_000, 1_448_020_800_000_358_104], np.int64))
    assert got == ["0.000000000", "0.000000001", "-0.000000001", "-0.500000000",
                   "1448020800.000358104"]  # fmt: skip


@pytest.mark.slow
@given(
    st.lists(
        st.tuples(*[st.floats(allow_nan=False, allow_infinity=False, width=64)] * 7),
        min_size=1,
        max_size=20,
    )
)
def test_floats_round_trip_bit_exact(rows: list[tuple[float, ...]]) -> None:
    a = np.array(rows)
    s = PoseStream(np.arange(len(a), dtype=np.int64), a[:, :3], a[:, 3:], "map")
    back = np.array([[float(x) for x in line.split()[1:]] for line in format_tum(s).splitlines()])
    np.testing.assert_array_equal(back.view(np.int64), a.view(np.int64))  # same bits
    body = format_csv(s).splitlines()[1:]
    back = np.array([[float(x) for x in line.split(",")[2:9]] for line in body])
    np.testing.assert_array_equal(back.view(np.int64), a.view(np.int64))


def test_csv_quotes_an_odd_frame_id() -> None:
    s = PoseStream(np.array([5], np.int64), np.zeros((1, 3)), np.array([[0, 0, 0, 1.0]]), 'a,"b"')
    assert format_csv(s).splitlines()[1].endswith(',"a,""b"""')


def test_empty_stream_is_an_empty_file() -> None:
    assert format_tum(PoseStream.empty()) == ""
    assert format_csv(PoseStream.empty()) == "t_ns,t_s,x,y,z,qx,qy,qz,qw,frame_id\n"


def test_kitti_refuses_a_zero_quaternion() -> None:
    q = np.array([[0, 0, 0, 1.0], [0, 0, 0, 0], [np.nan, 0, 0, 1]])
    with pytest.raises(
        BagError, match=r"2 pose\(s\) have a zero or NaN quaternion \(first at index 1\)"
    ):
        rotation_matrices(q, "x.bag:/pose")


def test_write_poses_creates_the_folder(tmp_path: Path) -> None:
    s = PoseStream(
        np.array([1_448_020_800_000_000_001, 1_448_020_800_008_333_334], np.int64),
        np.array([[1.0, 2.0, 3.0], [0.1, 0.2, 0.3]]),
        np.array([[0, 0, 0, 1.0], [0, 0, math.sin(0.5), math.cos(0.5)]]),
        "world",
    )
    out = write_poses(s, tmp_path / "a" / "b.tum", "tum")
    assert out.read_text() == (
        "1448020800.000000001 1.0 2.0 3.0 0.0 0.0 0.0 1.0\n"
        f"1448020800.008333334 0.1 0.2 0.3 0.0 0.0 {math.sin(0.5)!r} {math.cos(0.5)!r}\n"
    )
    with pytest.raises(ValueError, match="unknown export format 'g2o'"):
        write_poses(s, tmp_path / "c.g2o", "g2o")  # type: ignore[arg-type]
    assert not (tmp_path / "c.g2o").exists()
