"""The simulated mocap node: noise statistics, tracking loss, timing, what lands in the bag."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from rosbags.highlevel import AnyReader

from ertools.geometry import quat_from_yaw, yaw_from_quat
from ertools.simulator.mocap import (
    MocapNoise,
    TrackingLoss,
    frame_times,
    publish_environment,
    publish_mocap,
    quat_multiply,
    random_losses,
    simulate_mocap,
)
from ertools.simulator.writer import BagWriter

T0 = 1_448_013_600_000_000_000


def _circle(n_s: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    t = frame_times(T0, n_s)
    s = (t - T0) / 1e9
    xyz = np.column_stack([np.cos(s), np.sin(s), np.full(s.size, 0.2)])
    return t, xyz, quat_from_yaw(s + np.pi / 2)


def test_frame_times_are_120_hz() -> None:
    t = frame_times(T0, 2.0)
    assert t.size == 241
    assert t[-1] - t[0] == 2_000_000_000
    assert set(np.diff(t).tolist()) <= {8_333_333, 8_333_334}


def test_position_and_rotation_noise_statistics() -> None:
    t, xyz, quat = _circle(100.0)
    sigma, sigma_rad = 3e-4, 1e-3
    pub = simulate_mocap(
        t, xyz, quat, rng=np.random.default_rng(7), noise=MocapNoise(sigma, sigma_rad)
    )
    err = pub.xyz - pub.truth_xyz
    # (truth + noise) - truth differs from noise by float rounding at 1 m: a few 1e-16.
    assert np.allclose(err, pub.noise_xyz, rtol=0, atol=1e-15)
    # 12001 samples per axis: the sd estimate has relative standard error 1/sqrt(2n) = 0.65 %,
    # the mean sigma/sqrt(n) = 0.009 sigma; 5 % and 0.05 sigma are > 5 standard errors.
    assert np.allclose(err.std(axis=0), sigma, rtol=0.05)
    assert np.all(np.abs(err.mean(axis=0)) < 0.05 * sigma)
    # Rotation error angle of a 3D isotropic rotation vector: mean = sigma * 2*sqrt(2/pi).
    rel = quat_multiply(pub.truth_quat_xyzw * [-1, -1, -1, 1], pub.quat_xyzw)
    angle = 2 * np.arcsin(np.clip(np.linalg.norm(rel[:, :3], axis=1), 0, 1))
    assert angle.mean() == pytest.approx(sigma_rad * 2 * np.sqrt(2 / np.pi), rel=0.05)
    assert np.allclose(np.linalg.norm(pub.quat_xyzw, axis=1), 1.0, atol=1e-12)


def test_timing_header_jitter_and_latency() -> None:
    t, xyz, quat = _circle(30.0)
    noise = MocapNoise(header_jitter_ns=200_000, latency_ns=300_000, latency_jitter_ns=50_000)
    pub = simulate_mocap(t, xyz, quat, rng=np.random.default_rng(1), noise=noise)
    jitter = pub.t_header_ns - pub.t_frame_ns
    assert jitter.min() >= 0 and jitter.max() < 8_333_333 // 2
    assert np.all(np.diff(pub.t_header_ns) > 0)
    latency = pub.t_record_ns - pub.t_header_ns
    # Median latency is the configured 0.3 ms; rare spikes add 3 ms.
    assert np.median(latency) == pytest.approx(300_000, abs=10_000)
    assert latency.min() >= 75_000 and latency.max() <= 300_000 + 3_000_000 + 6 * 50_000


def test_tracking_loss_repeats_then_gap() -> None:
    t, xyz, quat = _circle(10.0)
    losses = [TrackingLoss(int(t[100]), 4, 10), TrackingLoss(int(t[500]) - 1, 2, 0)]
    pub = simulate_mocap(t, xyz, quat, rng=np.random.default_rng(3), losses=losses)
    assert len(pub) == t.size - 10 and pub.dropped == 10
    assert pub.repeated.sum() == 6
    idx = pub.frame_index.tolist()
    assert idx[100:104] == [100, 101, 102, 103]
    assert idx[104] == 114  # frames 104..113 had no message
    for k in range(100, 104):  # the repeats hold frame 99's measurement, fresh stamps
        assert np.array_equal(pub.xyz[k], pub.xyz[99])
        assert pub.t_header_ns[k] > pub.t_header_ns[k - 1]
    assert not np.array_equal(pub.xyz[104], pub.xyz[99])
    j = idx.index(500)
    assert np.array_equal(pub.xyz[j], pub.xyz[j - 1]) and np.array_equal(
        pub.xyz[j + 1], pub.xyz[j - 1]
    )


def test_random_losses_are_seeded_and_inside() -> None:
    t, _, _ = _circle(60.0)
    a = random_losses(np.random.default_rng(5), t, 4)
    assert a == random_losses(np.random.default_rng(5), t, 4)
    assert all(t[120] <= x.t_ns <= t[-121] and 2 <= x.repeat_frames <= 6 for x in a)


@pytest.mark.slow
def test_published_topics(tmp_path: Path) -> None:
    t, xyz, quat = _circle(5.0)
    pub = simulate_mocap(t, xyz, quat, rng=np.random.default_rng(2))
    path = tmp_path / "m.bag"
    end = int(pub.t_record_ns[-1])
    with BagWriter(path) as bag:
        publish_mocap(bag, "fbm2h", "robot_at_home", pub)
        publish_environment(bag, "fbm2h", T0 - 500_000_000, end, bodies=["robot_at_home"])
    pose, pose2d, tf_body, tf_map = [], [], [], []
    topics = set()
    with AnyReader([path]) as reader:
        for conn, tr, raw in reader.messages():
            topics.add(conn.topic)
            msg = reader.deserialize(raw, conn.msgtype)
            if conn.topic == "/fbm2h/robot_at_home/pose":
                st = msg.header.stamp
                pose.append((tr, st.sec * 10**9 + st.nanosec, msg.pose.position.x))
            elif conn.topic.endswith("pose2d"):
                pose2d.append((tr, msg.theta))
            elif conn.topic == "/tf":
                x = msg.transforms[0]
                st = x.header.stamp
                row = (
                    tr,
                    st.sec * 10**9 + st.nanosec,
                    x.header.frame_id,
                    x.transform.translation.x,
                )
                (tf_body if x.child_frame_id == "robot_at_home" else tf_map).append(row)
    assert topics == {
        "/fbm2h/robot_at_home/pose",
        "/fbm2h/robot_at_home/pose2d",
        "/tf",
        "/fbm2h/map",
        "/fbm2h/map_metadata",
        "/rosout",
    }
    assert [p[0] for p in pose] == pub.t_record_ns.tolist()
    assert [p[1] for p in pose] == pub.t_header_ns.tolist()
    assert [p[2] for p in pose] == pub.xyz[:, 0].tolist()
    assert np.allclose([p[1] for p in pose2d], yaw_from_quat(pub.quat_xyzw), atol=0)
    assert [r[3] for r in tf_body] == pub.xyz[:, 0].tolist()
    assert {r[2] for r in tf_body + tf_map} == {"world"}
    # Static world -> map at 10 Hz, stamped one period ahead, from start + 0.3 s to the end.
    rec = np.array([r[0] for r in tf_map])
    assert set(np.diff(rec).tolist()) == {100_000_000}
    assert rec[0] == T0 - 200_000_000 and rec[-1] > end - 100_000_000
    assert all(r[1] - r[0] == 100_000_000 for r in tf_map)
