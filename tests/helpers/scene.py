"""The reader tests' known scene (what was written, which the readers must give back exactly);
its fixtures are in conftest.py. A module of its own: a test imports it by this name, while
every test folder's conftest is a module named ``conftest``."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from tests.helpers.bagmaker import Spec

T0 = 1_445_609_740_000_000_000  # 2015-10-23, like the real bag
DT = 8_333_333  # 120 Hz


@dataclass
class Scene:
    """What was written: the ground truth the readers must give back exactly."""

    spec: Spec
    n: int
    t_rec: np.ndarray
    t_hdr: np.ndarray
    xyz: np.ndarray
    quat: np.ndarray
    yaw: np.ndarray


def make_scene(n: int = 50, seed: int = 1) -> Scene:
    rng = np.random.default_rng(seed)
    t_rec = T0 + np.arange(n, dtype=np.int64) * DT + 3_000_000
    t_hdr = t_rec - 2_500_000 - rng.integers(0, 1000, n)
    xyz = rng.normal(size=(n, 3))
    yaw = rng.uniform(-np.pi, np.pi, n)
    quat = np.stack([np.zeros(n), np.zeros(n), np.sin(yaw / 2), np.cos(yaw / 2)], axis=1)
    s = Spec()
    pose = s.conn("/fbm3w/robot_at_work/pose", "geometry_msgs/PoseStamped")
    pose2d = s.conn("/fbm3w/robot_at_work/pose2d", "geometry_msgs/Pose2D")
    tf_a = s.conn("/tf", "tf2_msgs/TFMessage", "/mocap")
    tf_b = s.conn("/tf", "tf2_msgs/TFMessage", "/static_pub")
    bm = s.conn("/fbm3w/bmbox_state", "rockin_scoring/BmBoxState")
    ref = s.conn("/fbm3w/refbox_state", "rockin_scoring/RefBoxState")
    tfs = s.conn("/fbm3w/tfs", "geometry_msgs/TransformStamped")
    odom = s.conn("/odom", "nav_msgs/Odometry")
    s.conn("/chatter", "std_msgs/String")
    for i in range(n):
        tr, th, p, q = int(t_rec[i]), int(t_hdr[i]), xyz[i], quat[i]
        s.add(pose, tr, stamp=th, frame="world", xyz=p, q=q)
        s.add(pose2d, tr + 100, x=p[0], y=p[1], theta=yaw[i])
        s.add(
            tf_a, tr, transforms=[dict(stamp=th, frame="world", child="robot_at_work", xyz=p, q=q)]
        )
        s.add(tfs, tr, stamp=th, frame="world", child="robot_at_work", xyz=p, q=q)
        s.add(odom, tr, stamp=th, frame="odom", child="base_link", xyz=p, q=q)
        if i % 12 == 0:
            s.add(
                tf_b,
                tr,
                transforms=[
                    dict(stamp=tr, frame="world", child="map", xyz=(1, 2, 0), q=(0, 0, 0, 1))
                ],
            )
            s.add(bm, tr, state=i // 12, payload=f"payload {i}")
            s.add(ref, tr + 1, state=2, payload="")
    return Scene(s, n, t_rec, t_hdr, xyz, quat, yaw)
