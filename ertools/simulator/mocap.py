"""What the 2015 ``mocap_optitrack`` node published for a rigid body, given its true motion.

Two steps, kept apart so scenarios can compute their expected answers from exactly what was
published:

1. :func:`simulate_mocap` (pure): truth arrays at the mocap frame rate (120 Hz) -> the
   :class:`MocapPublished` arrays: header stamps, record times, noisy poses, which frames were
   repeats, which truth frame each message belongs to.
2. :func:`publish_mocap` writes them on ``/<ns>/<body>/pose`` (PoseStamped, frame ``world``),
   ``/<ns>/<body>/pose2d`` (Pose2D) and ``/tf`` (``world -> <body>``), like the 2015 node.

:func:`publish_environment` adds what every 2015 GT log also held: the static ``world -> map``
on ``/tf`` at 10 Hz (header stamped 100 ms ahead, as tf's static_transform_publisher did),
``/<ns>/map`` and ``/<ns>/map_metadata`` once (latched), and a few ``/rosout`` lines.

Timing model, measured on the real 2015 FBM2 bag (``../shared/real_bags``): header stamp =
receive time at the mocap node = frame time + jitter (sd ~0.2 ms); record time = header +
~0.3 ms (0.2 to 0.4 ms, rarely a few ms); /tf stamped a few microseconds after the pose.
Noise: isotropic Gaussian per axis on the position (``sigma_m``, 0.1 to 0.3 mm) and a small
random rotation (rotation vector with per-axis sd ``sigma_rad``) on the orientation.

Tracking loss (Motive's behaviour): for ``repeat_frames`` frames the node re-publishes the
last good measurement unchanged (same pose, fresh stamps), then nothing for ``gap_frames``
frames. Give losses explicitly (:class:`TrackingLoss`) so the answers know them, or draw them
with :func:`random_losses`.

Example::

    rng = np.random.default_rng(seed)
    pub = simulate_mocap(t_ns, xyz, quat, rng=rng, noise=MocapNoise(sigma_m=2e-4),
                         losses=[TrackingLoss(t_ns[600], repeat_frames=4, gap_frames=12)])
    publish_mocap(bag, "fbm3w", "robot_at_work", pub)
    publish_environment(bag, "fbm3w", pub.t_record_ns[0] - 200_000_000, pub.t_record_ns[-1])
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import numpy.typing as npt

from ertools.arrays import F64, I64, Bool
from ertools.frozen_dataclass import frozen_dataclass
from ertools.geometry import normalize_quat, yaw_from_quat
from ertools.simulator.writer import BagWriter

MOCAP_RATE_HZ = 120.0
FRAME_NS = 8_333_333  # 1/120 s, as the 2015 Motive setup streamed


@frozen_dataclass
class MocapNoise:
    """Measurement and timing noise of the simulated mocap node (SI units, ns)."""

    sigma_m: float = 2e-4
    sigma_rad: float = 5e-4
    header_jitter_ns: int = 200_000
    latency_ns: int = 300_000
    latency_jitter_ns: int = 50_000
    latency_spike_prob: float = 0.001  # a rare multi-ms delay, as in the real bag (max 3.2 ms)
    latency_spike_ns: int = 3_000_000


@frozen_dataclass
class TrackingLoss:
    """Tracking lost at the first frame with time >= ``t_ns``: repeats, then a gap."""

    t_ns: int
    repeat_frames: int = 4
    gap_frames: int = 0


@frozen_dataclass(eq=False)
class MocapPublished:
    """The messages one rigid body produced (N published frames).

    Attributes:
        frame_index: (N,) index into the truth arrays of the frame each message belongs to.
        t_frame_ns: (N,) true frame times (the truth sample times).
        t_header_ns: (N,) header stamps (frame time + receive jitter).
        t_record_ns: (N,) times the recorder stored (header + latency).
        xyz, quat_xyzw: (N,3), (N,4) published (noisy, or repeated) poses.
        truth_xyz, truth_quat_xyzw: the noiseless truth at the same frames.
        noise_xyz: (N,3) position noise of each message's measurement (repeats carry the
            noise of the measurement they repeat).
        repeated: (N,) True where the message repeats the previous measurement.
        dropped: number of truth frames with no message (gaps).
    """

    frame_index: npt.NDArray[np.intp]
    t_frame_ns: I64
    t_header_ns: I64
    t_record_ns: I64
    xyz: F64
    quat_xyzw: F64
    truth_xyz: F64
    truth_quat_xyzw: F64
    noise_xyz: F64
    repeated: Bool
    dropped: int

    def __len__(self) -> int:
        return int(self.t_header_ns.shape[0])

    @property
    def yaw(self) -> F64:
        """Published yaw (what Pose2D.theta carries)."""
        return yaw_from_quat(self.quat_xyzw)


def frame_times(start_ns: int, duration_s: float, rate_hz: float = MOCAP_RATE_HZ) -> I64:
    """Frame times from ``start_ns`` for ``duration_s`` seconds at ``rate_hz`` (exact ns grid)."""
    n = int(np.floor(duration_s * rate_hz)) + 1
    return start_ns + np.round(np.arange(n) * (1e9 / rate_hz)).astype(np.int64)


def small_rotation(rotvec: F64) -> F64:
    """Quaternions (x,y,z,w) of rotation vectors (..., 3)."""
    angle = np.linalg.norm(rotvec, axis=-1, keepdims=True)
    half = 0.5 * angle
    # sin(a/2)/a -> 1/2 for tiny angles; avoid 0/0.
    scale = np.where(angle > 1e-12, np.sin(half) / np.where(angle > 1e-12, angle, 1.0), 0.5)
    return np.concatenate([rotvec * scale, np.cos(half)], axis=-1)


def quat_multiply(q1: F64, q2: F64) -> F64:
    """Hamilton product q1 * q2 of (..., 4) quaternions (x, y, z, w)."""
    x1, y1, z1, w1 = np.moveaxis(q1, -1, 0)
    x2, y2, z2, w2 = np.moveaxis(q2, -1, 0)
    return np.stack(
        [
            w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
            w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2,
            w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2,
            w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2,
        ],
        axis=-1,
    )


def random_losses(
    rng: np.random.Generator,
    t_ns: I64,
    count: int,
    *,
    repeat_frames: tuple[int, int] = (2, 6),
    gap_frames: tuple[int, int] = (0, 24),
) -> list[TrackingLoss]:
    """``count`` losses at random frames (not in the first/last second), sorted in time."""
    margin = int(MOCAP_RATE_HZ)
    if count == 0:
        return []
    if len(t_ns) <= 2 * margin + count:
        raise ValueError(f"{len(t_ns)} frames are too few for {count} tracking losses")
    idx = np.sort(rng.choice(np.arange(margin, len(t_ns) - margin), size=count, replace=False))
    reps = rng.integers(repeat_frames[0], repeat_frames[1] + 1, size=count)
    gaps = rng.integers(gap_frames[0], gap_frames[1] + 1, size=count)
    return [
        TrackingLoss(int(t_ns[i]), int(r), int(g))
        for i, r, g in zip(idx.tolist(), reps.tolist(), gaps.tolist(), strict=True)
    ]


def simulate_mocap(
    t_ns: npt.ArrayLike,
    xyz: npt.ArrayLike,
    quat_xyzw: npt.ArrayLike,
    *,
    rng: np.random.Generator,
    noise: MocapNoise = MocapNoise(),
    losses: Sequence[TrackingLoss] = (),
) -> MocapPublished:
    """Simulate the published messages of one rigid body (see the module docstring).

    ``t_ns`` (N,) are the true frame times (use :func:`frame_times`), ``xyz`` (N,3) and
    ``quat_xyzw`` (N,4) the true poses. The random draws happen in a fixed order (position
    noise, rotation noise, header jitter, latency, spikes) so a seed fixes every value.
    """
    t = np.asarray(t_ns, dtype=np.int64)
    p = np.asarray(xyz, dtype=np.float64)
    q = normalize_quat(np.asarray(quat_xyzw, dtype=np.float64))
    n = t.shape[0]
    if p.shape != (n, 3) or q.shape != (n, 4):
        raise ValueError(f"truth shapes disagree: t {t.shape}, xyz {p.shape}, quat {q.shape}")

    noise_xyz = rng.normal(0.0, noise.sigma_m, size=(n, 3))
    rotvec = rng.normal(0.0, noise.sigma_rad, size=(n, 3))
    jitter = np.abs(rng.normal(0.0, noise.header_jitter_ns, size=n)).astype(np.int64)
    latency = np.maximum(
        rng.normal(noise.latency_ns, noise.latency_jitter_ns, size=n), noise.latency_ns / 4
    ).astype(np.int64)
    spikes = rng.random(n) < noise.latency_spike_prob
    latency[spikes] += noise.latency_spike_ns

    meas_xyz = p + noise_xyz
    meas_q = normalize_quat(quat_multiply(q, small_rotation(rotvec)))
    # A measurement index per frame: itself normally, the last good one while repeating.
    source = np.arange(n)
    keep = np.ones(n, dtype=bool)
    repeated = np.zeros(n, dtype=bool)
    for loss in losses:
        k = int(np.searchsorted(t, loss.t_ns, side="left"))
        if k <= 0 or k >= n:
            raise ValueError(f"tracking loss at {loss.t_ns} is outside the truth frames")
        last_good = int(source[k - 1])
        rep_end = min(n, k + loss.repeat_frames)
        source[k:rep_end] = last_good
        repeated[k:rep_end] = True
        keep[rep_end : min(n, rep_end + loss.gap_frames)] = False

    idx = np.flatnonzero(keep)
    src = source[idx]
    t_header = t[idx] + jitter[idx]
    # The node stamps on receipt; stamps stay strictly increasing (jitter < half a frame).
    t_record = t_header + latency[idx]
    return MocapPublished(
        frame_index=idx,
        t_frame_ns=t[idx],
        t_header_ns=t_header,
        t_record_ns=t_record,
        xyz=meas_xyz[src],
        quat_xyzw=meas_q[src],
        truth_xyz=p[idx],
        truth_quat_xyzw=q[idx],
        noise_xyz=noise_xyz[src],
        repeated=repeated[idx],
        dropped=int(n - idx.size),
    )


def pose_topic(namespace: str, body: str) -> str:
    """``/<ns>/<body>/pose``."""
    return f"/{namespace.strip('/')}/{body}/pose"


def publish_mocap(
    bag: BagWriter,
    namespace: str,
    body: str,
    pub: MocapPublished,
    *,
    pose2d: bool = True,
    tf: bool = True,
    callerid: str | None = None,
) -> None:
    """Write ``pub`` as the 2015 node did: PoseStamped, Pose2D and /tf ``world -> body``.

    Pose2D is recorded 20 us after the pose (its own publish call), the /tf message is stamped
    5 us after the pose header and recorded 40 us after the pose: fixed offsets keep the order
    of the three topics stable in the bag, as in the real logs.
    """
    ns = namespace.strip("/")
    caller = callerid or f"/{ns}/mocap_node"
    bag.write_pose_stamped(
        pose_topic(ns, body),
        pub.t_record_ns,
        pub.t_header_ns,
        "world",
        pub.xyz,
        pub.quat_xyzw,
        callerid=caller,
    )
    if pose2d:
        bag.write_pose2d(
            f"/{ns}/{body}/pose2d",
            pub.t_record_ns + 20_000,
            pub.xyz[:, 0],
            pub.xyz[:, 1],
            pub.yaw,
            callerid=caller,
        )
    if tf:
        bag.write_tf(
            pub.t_record_ns + 40_000,
            pub.t_header_ns + 5_000,
            "world",
            body,
            pub.xyz,
            pub.quat_xyzw,
            callerid=caller,
        )


def simple_map(
    width_m: float = 6.0, height_m: float = 4.0, resolution: float = 0.1
) -> npt.NDArray[np.int8]:
    """A small occupancy grid: free inside, a one-cell wall around, unknown corners."""
    w = round(width_m / resolution)
    h = round(height_m / resolution)
    grid = np.zeros((h, w), dtype=np.int8)
    grid[0, :] = grid[-1, :] = 100
    grid[:, 0] = grid[:, -1] = 100
    grid[:2, :2] = -1
    return grid


def publish_environment(
    bag: BagWriter,
    namespace: str,
    start_ns: int,
    end_ns: int,
    *,
    bag_name: str = "log.bag",
    map_grid: npt.NDArray[np.int8] | None = None,
    resolution: float = 0.1,
    map_origin_xyz: tuple[float, float, float] = (-1.0, -1.0, 0.0),
    rate_hz: float = 10.0,
    bodies: Sequence[str] = (),
) -> None:
    """Static ``world -> map`` on /tf, the map topics and start-up /rosout lines.

    ``start_ns`` is when the recorder started (its /rosout lines come first); the map is
    recorded 200 ms later, the static transform runs from 300 ms after start to ``end_ns``.
    Everything is a fixed function of the arguments (no randomness).
    """
    ns = "/" + namespace.strip("/")
    grid = simple_map() if map_grid is None else map_grid
    # Recorder start-up lines, then map_server and mocap node (timestamps before recording
    # started, as latched /rosout messages were).
    bag.write_log(
        start_ns,
        start_ns - 14_000_000,
        f"{ns}/log_mocap_fbm",
        "Subscribing to /rosout",
        file="recorder.cpp",
        function="rosbag::Recorder::subscribe",
        line=209,
    )
    bag.write_log(
        start_ns + 500_000,
        start_ns + 300_000,
        f"{ns}/log_mocap_fbm",
        f"Recording to {bag_name}.",
        file="recorder.cpp",
        function="Recorder::startWriting",
        line=387,
    )
    h, w = grid.shape
    bag.write_map(
        ns,
        start_ns + 200_000_000,
        start_ns - 220_000_000,
        grid,
        resolution=resolution,
        origin_xyz=map_origin_xyz,
    )
    bag.write_log(
        start_ns + 200_100_000,
        start_ns - 219_000_000,
        f"{ns}/map_server",
        f"Read a {w} X {h} map @ {resolution:.3f} m/cell",
        file="main.cpp",
        function="MapServer",
        line=163,
    )
    bag.write_log(
        start_ns + 200_200_000,
        start_ns - 120_000_000,
        f"{ns}/mocap_node",
        "NATNet Version : 2.7.0.0",
        file="mocap_node.cpp",
        function="processMocapData",
        line=154,
        topics=["/rosout", "/tf", *(f"{ns}/{b}/{k}" for b in bodies for k in ("pose", "pose2d"))],
    )
    period = round(1e9 / rate_hz)
    t_rec = np.arange(start_ns + 300_000_000, end_ns + 1, period, dtype=np.int64)
    if t_rec.size:
        bag.write_tf(
            t_rec,
            t_rec + period,  # static_transform_publisher stamped one period ahead
            "world",
            "map",
            (0.0, 0.0, 0.0),
            (0.0, 0.0, 0.0, 1.0),
            callerid=f"{ns}/world_map_bc",
        )
