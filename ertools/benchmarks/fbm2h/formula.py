"""FBM2@Home scoring on arrays: robot poses at the reached moments and their errors.

Pure computation: a ground-truth :class:`~ertools.streams.PoseStream` of the marker set, a
marker-to-robot transform, the waypoints and the moments in, numbers out.
"""

from __future__ import annotations

import numpy as np

from ertools.arrays import F64, I64, Bool
from ertools.frozen_dataclass import frozen_dataclass
from ertools.geometry import angle_error, compose, interpolate_poses, yaw_from_quat
from ertools.streams import PoseStream


@frozen_dataclass(eq=False)
class PosesAt:
    """Robot poses evaluated at query moments.

    Attributes:
        xyyaw: (M, 3) robot x, y, yaw (NaN where no GT lies within the allowed gap).
        ok: (M,) True where a GT sample lies within ``max_gap`` of the moment.
        nearest_ns: (M,) time from the moment to the nearest GT sample.
        interpolated: (M,) True where both neighbours were close enough to interpolate.
    """

    xyyaw: F64
    ok: Bool
    nearest_ns: I64
    interpolated: Bool


def robot_poses_at(
    marker: PoseStream,
    t_marker_robot: tuple[F64, F64],
    query_ns: I64,
    max_gap_ns: int,
) -> PosesAt:
    """T_world_robot = T_world_marker(t) * T_marker_robot at each moment, reduced to 2D.

    The marker pose is interpolated (linear position, SLERP orientation) between the samples
    around the moment when both lie within ``max_gap_ns`` of it; when only one does, that
    sample is used as is; when neither does, tracking was lost and the moment is not ``ok``.
    """
    q = np.asarray(query_ns, dtype=np.int64)
    m = len(q)
    if len(marker) == 0:
        nan = np.full((m, 3), np.nan)
        far = np.full(m, np.iinfo(np.int64).max, dtype=np.int64)
        return PosesAt(nan, np.zeros(m, bool), far, np.zeros(m, bool))
    lin = interpolate_poses(marker, q, "linear")
    t = marker.t_ns
    n = len(t)
    big = np.iinfo(np.int64).max
    d_lo = np.where(lin.lo >= 0, q - t[np.clip(lin.lo, 0, n - 1)], big)
    d_hi = np.where(lin.hi < n, t[np.clip(lin.hi, 0, n - 1)] - q, big)
    near_lo = d_lo <= max_gap_ns
    near_hi = d_hi <= max_gap_ns
    both = near_lo & near_hi
    ok = near_lo | near_hi
    pick = np.where(d_lo <= d_hi, np.clip(lin.lo, 0, n - 1), np.clip(lin.hi, 0, n - 1))
    xyz = np.where(both[:, None], lin.xyz, marker.xyz[pick])
    quat = np.where(both[:, None], lin.quat_xyzw, marker.quat_xyzw[pick])
    t_mr, q_mr = t_marker_robot
    rob_t, rob_q = compose(
        xyz, quat, np.broadcast_to(t_mr, xyz.shape).copy(), np.broadcast_to(q_mr, quat.shape).copy()
    )
    xyyaw = np.column_stack([rob_t[:, 0], rob_t[:, 1], yaw_from_quat(rob_q)])
    # A NaN sample (or a NaN transform) must never become a score: such a moment has no GT.
    ok = ok & np.all(np.isfinite(xyyaw), axis=1)
    xyyaw[~ok] = np.nan
    return PosesAt(xyyaw, ok, np.minimum(d_lo, d_hi).astype(np.int64), both)


@frozen_dataclass(eq=False)
class Errors:
    """Per-segment errors and their aggregates.

    Attributes:
        distance: (K,) metres.
        dtheta: (K,) robot yaw minus target theta, unwrapped (as 2015 subtracted them).
        orientation: (K,) the reported orientation error: wrapped to [0, pi], or with
            ``orientation_2015`` atan2(sin|dtheta|, cos|dtheta|) as the 2015 node wrote it
            (negative when |dtheta| > pi).
        position_accuracy: mean distance error.
        orientation_accuracy: atan2(sum sin, sum cos) of the angles the errors came from.
    """

    distance: F64
    dtheta: F64
    orientation: F64
    position_accuracy: float
    orientation_accuracy: float


def segment_errors(robot: F64, target: F64, *, orientation_2015: bool = False) -> Errors:
    """Errors of robot poses (K, 3) against target poses (K, 3)."""
    robot = np.asarray(robot, dtype=np.float64).reshape(-1, 3)
    target = np.asarray(target, dtype=np.float64).reshape(-1, 3)
    distance = np.hypot(robot[:, 0] - target[:, 0], robot[:, 1] - target[:, 1])
    dtheta = robot[:, 2] - target[:, 2]
    # 2015 summed sin and cos of |dtheta| without wrapping; wrapping first gives the true
    # angle between the headings, in [0, pi].
    angle = np.abs(dtheta) if orientation_2015 else angle_error(robot[:, 2], target[:, 2])
    s, c = np.sin(angle), np.cos(angle)
    orientation = np.arctan2(s, c)
    k = len(distance)
    return Errors(
        distance=distance,
        dtheta=dtheta,
        orientation=orientation,
        position_accuracy=float(distance.mean()) if k else float("nan"),
        orientation_accuracy=float(np.arctan2(s.sum(), c.sum())) if k else float("nan"),
    )
