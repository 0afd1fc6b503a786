"""tf chains against hand-computed transforms, windows touching only their chunks, fallbacks."""

from __future__ import annotations

import logging
import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from rosbags.rosbag1 import Writer

from ertools.errors import TopicError
from ertools.geometry import compose
from ertools.io.decode.tf import Edge, chain_pose
from ertools.io.files import open_bag
from ertools.io.reader import read_poses, read_tf
from ertools.io.ros1.index import Ros1Bag
from ertools.streams import PoseStream
from tests.helpers.bagmaker import Spec, write
from tests.helpers.scene import DT, T0, Scene


def q_yaw(yaw: float) -> tuple[float, float, float, float]:
    return (0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2))


@pytest.mark.parametrize("fmt", ["ros1", "mcap-cdr"])
@pytest.mark.parametrize("tf_type", ["tf/tfMessage", "tf2_msgs/TFMessage"])
def test_origin_to_ref_board(tmp_path: Path, fmt: str, tf_type: str) -> None:
    """world->origin (static, /tf_static) and world->ref_board (moving) give origin->ref_board."""
    s = Spec()
    static = s.conn("/tf_static", tf_type)
    moving = s.conn("/tf", tf_type)
    # origin: at (1, 0, 0), turned 90 degrees: its x axis is world y.
    s.add(
        static,
        T0,
        transforms=[
            dict(stamp=T0, frame="world", child="origin", xyz=(1, 0, 0), q=q_yaw(math.pi / 2))
        ],
    )
    n = 20
    for i in range(n):
        t = T0 + (i + 1) * DT
        s.add(
            moving,
            t,
            transforms=[
                dict(
                    stamp=t,
                    frame="/world",
                    child="ref_board",
                    xyz=(1 + 0.1 * i, 1, 0.5),
                    q=q_yaw(0.0),
                )
            ],
        )
    path = write(tmp_path / ("x.bag" if fmt == "ros1" else "x.mcap"), fmt, s)
    out = read_tf(path, "origin", "ref_board")
    # By hand: p_origin = R(-90deg) (p_world - (1, 0, 0)); R(-90deg) maps (a, b) to (b, -a).
    i = np.arange(n)
    expected = np.column_stack([np.ones(n), -(0.1 * i), np.full(n, 0.5)])
    assert out.frame_id == "origin" and out.child_frame_id == "ref_board"
    np.testing.assert_array_equal(out.t_ns, T0 + (i + 1) * DT)
    # scipy rotation round-off: 1e-15 scale
    np.testing.assert_allclose(out.xyz, expected, atol=1e-12)
    np.testing.assert_allclose(
        np.abs(out.quat_xyzw @ np.array(q_yaw(-math.pi / 2))), 1.0, atol=1e-12
    )
    back = read_tf(path, "ref_board", "origin")
    assert len(back) == n  # the static link holds; the moving one gives the times


def _stream(t: np.ndarray, xyz: np.ndarray, q: np.ndarray) -> PoseStream:
    return PoseStream(t.astype(np.int64), xyz, q)


finite = st.floats(-10, 10, allow_nan=False)


@settings(max_examples=40, deadline=None)
@given(
    st.tuples(finite, finite, finite),
    st.tuples(finite, finite, finite),
    st.tuples(st.floats(-1, 1), st.floats(-1, 1), st.floats(-1, 1), st.floats(0.1, 1)),
    st.tuples(st.floats(-1, 1), st.floats(-1, 1), st.floats(-1, 1), st.floats(0.1, 1)),
)
def test_chain_recomposes(
    pa: tuple[float, ...], pb: tuple[float, ...], qa: tuple[float, ...], qb: tuple[float, ...]
) -> None:
    """T_world_a * T_a_b (from the chain a <- world -> b) gives back T_world_b."""

    qa_n = np.array(qa) / np.linalg.norm(qa)
    qb_n = np.array(qb) / np.linalg.norm(qb)
    t = np.array([10, 20, 30])
    edges = {
        ("world", "a"): Edge(_stream(t, np.tile(pa, (3, 1)), np.tile(qa_n, (3, 1))), False),
        ("world", "b"): Edge(_stream(t, np.tile(pb, (3, 1)), np.tile(qb_n, (3, 1))), False),
    }
    ab = chain_pose(edges, "a", "b")
    xyz, q = compose(np.tile(pa, (3, 1)), np.tile(qa_n, (3, 1)), ab.xyz, ab.quat_xyzw)
    # float64 round-off of two rotations on values up to 10 m
    np.testing.assert_allclose(xyz, np.tile(pb, (3, 1)), atol=1e-9)
    np.testing.assert_allclose(np.abs(np.sum(q * qb_n, axis=1)), 1.0, atol=1e-9)


def test_unknown_frame_lists_frames(scene_bag: tuple[str, Path]) -> None:
    _, path = scene_bag
    with pytest.raises(TopicError, match="robot_at_work"):
        read_tf(path, "world", "nowhere")


def test_window_reads_only_overlapping_chunks(tmp_path: Path, scene: Scene) -> None:
    path = write(tmp_path / "w.bag", "ros1-lz4", scene.spec, chunk_bytes=1500)
    with open_bag(path) as bag:
        assert isinstance(bag, Ros1Bag)
        conns = bag.topic_conns("/fbm3w/robot_at_work/pose")
        all_chunks, *_ = bag.select(conns, None, None)
        lo, hi = int(scene.t_rec[20]), int(scene.t_rec[25])
        touched, _c, _r, t, _o = bag.select(conns, lo, hi)
        spans = [(c.start_ns, c.end_ns) for c in bag.layout.chunks]
    assert len(all_chunks) > 5
    assert 0 < len(touched) < len(all_chunks)
    assert all(spans[i][1] >= lo and spans[i][0] <= hi for i in touched)
    np.testing.assert_array_equal(t, scene.t_rec[20:26])


def test_non_standard_layout_falls_back(tmp_path: Path, caplog: pytest.LogCaptureFixture) -> None:
    """A Pose2D under the standard name but with an extra field: decoded by rosbags."""

    path = tmp_path / "odd.bag"
    with Writer(path) as w:
        c = w.add_connection(
            "/odd",
            "geometry_msgs/msg/Pose2D",
            msgdef="float64 x\nfloat64 y\nfloat64 theta\nfloat64 extra\n",
            md5sum="0" * 32,
        )
        for i in range(3):
            w.write(c, T0 + i, np.array([i, 2 * i, 0.5, 99.0]).tobytes())
    with caplog.at_level(logging.INFO, logger="ertools"):
        s = read_poses(path, "/odd")
    assert "standard layout" in caplog.text
    np.testing.assert_array_equal(s.xyz[:, :2], [[0, 0], [1, 2], [2, 4]])
    np.testing.assert_array_equal(s.t_ns, T0 + np.arange(3))
