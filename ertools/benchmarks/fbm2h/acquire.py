"""Offline marker-set-to-robot transform acquisition (seed 7.2.7).

The 2015 ``rockin_acquire_markerset_transform`` node, with the robot standing on the testbed
origin (x = y = theta = 0), read the latest tf ``/robot_markerset -> /world`` once and dumped
it as ``marker_to_robot_transform`` (and ``/world -> /robot_markerset`` as
``robot_to_marker_transform``). With the robot frame equal to the world frame, T_marker_world
is T_marker_robot. ertools does the same from a log, but averages the marker pose over a
stationary window instead of taking one sample, and reports the spread so a referee sees
whether the robot stood still; the file carries it (``acquisition_spread``, after the listing's
keys), and FBM2H's intervals take the transform's error from it.
"""

from __future__ import annotations

import math
import re
from datetime import UTC, datetime

import numpy as np

from ertools.arrays import F64
from ertools.benchmarks.common.hygiene import drop_invalid
from ertools.benchmarks.fbm2h.config import StopParams
from ertools.benchmarks.fbm2h.runs import detect_stops
from ertools.configs.transform import MarkerTransform, TransformSpread
from ertools.errors import ConfigError, SegmentationError
from ertools.frozen_dataclass import frozen_dataclass
from ertools.geometry import (
    MeanPose,
    invert,
    mean_pose,
    quat_conjugate,
    quat_multiply,
    rotate,
    yaw_from_quat,
)
from ertools.streams import Interval, PoseStream
from ertools.timeutil import ns_to_s

TEAM_NAME = re.compile(r"^[A-Za-z0-9_.-]+$")
MIN_SAMPLES = 10
# A still marker set showed ~0.6 to 1 mm and 11 to 16 mrad RMS in the real 2015 FBM2 log
# (Motive's orientation is noisy); about three times that means the robot moved.
SPREAD_WARN_M = 0.003
SPREAD_WARN_RAD = 0.05
# The marker set is mounted on the robot: far from the origin means the robot was not on it.
ORIGIN_WARN_M = 0.5


@frozen_dataclass
class TransformAcquisition:
    """An acquired transform and how it was obtained.

    Attributes:
        transform: T_marker_robot, ready for :func:`ertools.configs.transform.transform_yaml`.
        window: the averaged time window.
        marker: the mean marker pose in the world frame and its spread.
        detected: True when the window was found automatically.
        warnings: spread too large, robot apparently not at the origin...
    """

    transform: MarkerTransform
    window: Interval
    marker: MeanPose
    detected: bool
    warnings: tuple[str, ...] = ()


def check_team_name(team: str) -> str:
    """A team name usable in ``transform-<team>.yaml`` (letters, digits, ``_ . -``)."""
    if not TEAM_NAME.match(team):
        raise ConfigError(
            f"team name {team!r}: use letters, digits, '_', '.' or '-' only (it names the file)"
        )
    return team


def _longest_stop(marker: PoseStream, params: StopParams, max_gap_ns: int) -> Interval:
    xy = marker.xyz[:, :2]
    runs = detect_stops(marker.t_ns, xy, marker.yaw, params, max_gap_ns)
    if not runs:
        raise SegmentationError(
            f"{marker.source}: the marker set never stood still for {params.min_duration_s} s "
            f"(speed < {params.speed} m/s, yaw rate < {params.yaw_rate} rad/s); "
            "give --at T --duration S"
        )
    # The robot should stand on the origin: prefer the longest stop there, else the longest.
    near = [r for r in runs if np.hypot(*xy[r[0] : r[1] + 1].mean(axis=0)) <= ORIGIN_WARN_M]
    s, e = max(near or runs, key=lambda r: int(marker.t_ns[r[1]] - marker.t_ns[r[0]]))
    return Interval(int(marker.t_ns[s]), int(marker.t_ns[e]))


def pose_spread(xyz: F64, quat_xyzw: F64, mean: MeanPose) -> TransformSpread:
    """How much the averaged marker poses spread around their ``mean``, per axis of the mean
    marker frame (the frame of the transform's translation): position and rotation-vector
    standard deviations (ddof 1), and the effective number of independent poses.

    The effective count is the AR(1) one, ``n (1 - rho) / (1 + rho)``: rho is the lag-1
    autocorrelation of the six deviation series pooled (their mean), clipped at 0 (white noise
    keeps all n). A marker set swaying slowly on a standing robot makes consecutive poses
    alike, and the mean of n of them is then worth fewer than n.
    """
    n = len(xyz)
    q_inv = np.broadcast_to(quat_conjugate(mean.quat_xyzw[None, :]), (n, 4))
    dp = rotate(q_inv, xyz - mean.xyz)
    rel = quat_multiply(q_inv, quat_xyzw)
    rel = rel * np.where(rel[:, 3:] < 0, -1.0, 1.0)  # the short way round
    vec = np.linalg.norm(rel[:, :3], axis=1)
    angle = 2.0 * np.arctan2(vec, rel[:, 3])
    with np.errstate(invalid="ignore", divide="ignore"):
        scale = np.where(vec > 0, angle / vec, 2.0)
    dr = rel[:, :3] * scale[:, None]
    dev = np.concatenate([dp, dr], axis=1)
    ddof = 1 if n > 1 else 0
    std = dev.std(axis=0, ddof=ddof)
    centred = dev - dev.mean(axis=0)
    power = np.sum(centred**2, axis=0)
    lagged = np.sum(centred[1:] * centred[:-1], axis=0)
    live = power > 0
    rho = float(np.mean(lagged[live] / power[live])) if live.any() and n > 2 else 0.0
    rho = min(max(rho, 0.0), 1.0)
    effective = int(max(1, min(n, math.floor(n * (1.0 - rho) / (1.0 + rho)))))
    return TransformSpread(
        (float(std[0]), float(std[1]), float(std[2])),
        (float(std[3]), float(std[4]), float(std[5])),
        n,
        effective,
    )


def acquire_transform(
    marker: PoseStream,
    team: str,
    *,
    window: Interval | None = None,
    params: StopParams | None = None,
    max_gap_ns: int = 100_000_000,
    origin_ns: int | None = None,
) -> TransformAcquisition:
    """T_marker_robot from the marker poses of a robot standing on the testbed origin.

    ``origin_ns`` is time zero of the messages (the log's first message, as ``--at`` counts);
    the first pose when None. Poses with NaN values or a zero quaternion are left out (a NaN
    must never reach the transform file); a window holding some is warned about.
    """

    check_team_name(team)
    if len(marker) == 0:
        raise SegmentationError(f"{marker.source}: no marker set poses")
    total = len(marker)
    t_first = marker.start_ns if origin_ns is None else origin_ns
    since = "the first pose" if origin_ns is None else "the log's first message"
    marker, invalid = drop_invalid(marker)
    if len(marker) == 0:
        raise SegmentationError(
            f"{marker.source}: all {total} marker set poses are NaN, have a zero quaternion or "
            "are physically impossible (was the marker set tracked?)"
        )
    detected = window is None
    win = (
        window if window is not None else _longest_stop(marker, params or StopParams(), max_gap_ns)
    )
    part = marker.window(win.start_ns, win.end_ns)
    where = (
        f"{ns_to_s(win.start_ns - t_first):.3f} s to {ns_to_s(win.end_ns - t_first):.3f} s "
        f"after {since}"
    )
    if len(part) < MIN_SAMPLES:
        raise SegmentationError(
            f"{marker.source}: only {len(part)} marker poses from {where}; need at least "
            f"{MIN_SAMPLES} (is the window inside the log?"
            + (
                f" {invalid} NaN, zero-quaternion or impossible poses were left out"
                if invalid
                else ""
            )
            + ")"
        )
    mean = mean_pose(part.xyz, part.quat_xyzw)
    t_mr, q_mr = invert(mean.xyz, mean.quat_xyzw)
    stamp = datetime.fromtimestamp((win.start_ns + win.end_ns) / 2e9, tz=UTC)
    transform = MarkerTransform(
        robot_info=team,
        timestamp=stamp.strftime("%Y-%m-%d_%H:%M:%S"),
        translation=(float(t_mr[0]), float(t_mr[1]), float(t_mr[2])),
        quat_xyzw=(float(q_mr[0]), float(q_mr[1]), float(q_mr[2]), float(q_mr[3])),
        source=marker.source,
        spread=pose_spread(part.xyz, part.quat_xyzw, mean),
    )
    warnings = []
    if invalid:
        warnings.append(
            f"{invalid} marker set pose(s) with NaN, zero-quaternion or physically impossible "
            "values left out "
            f"({marker.source})"
        )
    if mean.position_std > SPREAD_WARN_M or mean.angle_std > SPREAD_WARN_RAD:
        warnings.append(
            f"the marker set moved during the window ({where}): spread "
            f"{mean.position_std * 1000:.1f} mm, {np.degrees(mean.angle_std):.2f} deg; "
            "the robot must stand still"
        )
    horizontal = float(np.hypot(mean.xyz[0], mean.xyz[1]))
    if horizontal > ORIGIN_WARN_M:
        yaw = float(yaw_from_quat(mean.quat_xyzw))
        warnings.append(
            f"the marker set is {horizontal:.2f} m from the testbed origin (yaw {yaw:.2f} rad): "
            "was the robot standing at (0, 0, 0)?"
        )
    return TransformAcquisition(transform, win, mean, detected, tuple(warnings))
