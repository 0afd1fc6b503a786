"""Synthetic FBM3@Work pose streams with known geometry, for the pure-function tests."""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt

from ertools.benchmarks.fbm3w.runs import RunWindow
from ertools.geometry import quat_from_yaw
from ertools.streams import PoseStream

F64 = npt.NDArray[np.float64]
T0 = 1_448_020_800_000_000_000
FRAME_NS = 8_333_333


def place(xy_frame: F64, origin: tuple[float, float], yaw: float) -> F64:
    """Run-frame points -> world points (rotation by yaw, then translation)."""
    c, s = math.cos(yaw), math.sin(yaw)
    x, y = xy_frame[:, 0], xy_frame[:, 1]
    return np.column_stack([origin[0] + c * x - s * y, origin[1] + s * x + c * y])


def stream_of(xy: F64, t0: int = T0) -> PoseStream:
    n = len(xy)
    t = t0 + np.arange(n, dtype=np.int64) * FRAME_NS
    xyz = np.column_stack([xy, np.full(n, 0.8)])
    return PoseStream(t, xyz, quat_from_yaw(np.zeros(n)), "world", "robot_at_work", "synthetic")


def one_run(
    path_frame: F64,
    *,
    origin: tuple[float, float] = (1.0, 2.0),
    yaw: float = 0.3,
    baseline: float = 0.05,
    still: int = 30,
    spec: str = "line",
    t0: int = T0,
    index: int = 0,
) -> tuple[PoseStream, RunWindow]:
    """Reference (still), start (still), the path, end (still); one state-like window."""
    ref_frame = np.array([[-baseline, 0.0]])
    pts = np.vstack(
        [
            np.repeat(ref_frame, still, axis=0),
            np.repeat(path_frame[:1], still, axis=0),
            path_frame,
            np.repeat(path_frame[-1:], still, axis=0),
        ]
    )
    stream = stream_of(place(pts, origin, yaw), t0)
    t = stream.t_ns
    window = RunWindow(
        index, spec, int(t[still // 2]), int(t[still]), int(t[-1]), "completed", "windows"
    )
    return stream, window
