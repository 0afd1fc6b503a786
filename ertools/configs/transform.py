"""The marker-set-to-robot transform file (seed Listings 11 and 12).

``marker_to_robot_transform`` is T_marker_robot, the pose of the robot's odometric centre in
the marker set's frame, so that ``T_world_robot = T_world_marker * T_marker_robot``. The 2015
acquirer wrote it as tf's ``lookupTransform("/robot_markerset", "/world")`` with the robot
standing on the world origin, which is that same transform. ``robot_to_marker_transform`` is
its inverse; the 2015 files also carry extra keys (``mocap``, ``robot_pose``,
``marker_to_robot_transform_2D``) that the benchmark never read and that are ignored here.
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from ertools.configs._yaml import load_yaml, number
from ertools.errors import ConfigError
from ertools.geometry import invert
from ertools.yamlout import yaml_float

log = logging.getLogger("ertools.configs.transform")

# A quaternion typed or dumped with 6+ digits has |norm - 1| < 1e-5; 1e-3 still allows hand
# edits with 4 digits, while anything further off is a wrong value, not rounding.
QUAT_NORM_TOLERANCE = 1e-3
# robot_to_marker must invert marker_to_robot; beyond this the file was edited inconsistently.
INVERSE_TOLERANCE_M = 1e-3
INVERSE_TOLERANCE_RAD = 1e-3

Vec3 = tuple[float, float, float]
Quat = tuple[float, float, float, float]


@dataclass(frozen=True)
class MarkerTransform:
    """T_marker_robot and where it came from.

    Attributes:
        robot_info: the team name (``identity`` for Listing 12).
        timestamp: the acquisition timestamp as written (``%Y-%m-%d_%H:%M:%S``, or ``0``).
        translation: (x, y, z) metres, robot origin in the marker frame.
        quat_xyzw: orientation of the robot in the marker frame (unit, scalar last).
        source: the file, or ``<identity>`` when none was given.
    """

    robot_info: str
    timestamp: str
    translation: Vec3
    quat_xyzw: Quat
    source: str = ""

    @property
    def is_identity(self) -> bool:
        t = np.asarray(self.translation)
        q = np.asarray(self.quat_xyzw)
        return bool(np.all(np.abs(t) < 1e-12) and np.all(np.abs(q[:3]) < 1e-12))

    def arrays(self) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
        """(translation (3,), quaternion (4,)) as arrays."""
        return np.asarray(self.translation, dtype=np.float64), np.asarray(
            self.quat_xyzw, dtype=np.float64
        )

    def inverse(self) -> tuple[Vec3, Quat]:
        """T_robot_marker, the Listing 11 ``robot_to_marker_transform``."""

        t, q = invert(*self.arrays())
        return _vec3(t), _quat(q)

    def as_listing(self) -> list[list[float]]:
        """[[x, y, z], [qx, qy, qz, qw]] as the 2015 score's ``marker-robot transform``."""
        return [list(self.translation), list(self.quat_xyzw)]


def _vec3(a: Any) -> Vec3:
    return (float(a[0]), float(a[1]), float(a[2]))


def _quat(a: Any) -> Quat:
    return (float(a[0]), float(a[1]), float(a[2]), float(a[3]))


def identity_transform() -> MarkerTransform:
    """Listing 12: the marker set sits on the odometric centre."""
    return MarkerTransform("identity", "0", (0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0), "<identity>")


def _numbers(value: Any, n: int, what: str, source: str) -> list[float]:
    if not isinstance(value, list | tuple) or len(value) != n:
        raise ConfigError(f"{what}: expected a list of {n} numbers, got {value!r}", path=source)
    out = []
    for v in value:
        out.append(number(v, what, source))
    return out


def _pair(data: dict[str, Any], key: str, source: str) -> tuple[Vec3, Quat]:
    value = data.get(key)
    if value is None:
        raise ConfigError(
            f"transform file: missing key {key!r} (Listing 11: [[x, y, z], [qx, qy, qz, qw]])",
            path=source,
        )
    if not isinstance(value, list | tuple) or len(value) != 2:
        raise ConfigError(
            f"{key}: expected [[x, y, z], [qx, qy, qz, qw]], got {value!r}", path=source
        )
    t = _numbers(value[0], 3, f"{key} translation", source)
    q = np.asarray(_numbers(value[1], 4, f"{key} quaternion", source))
    norm = float(np.linalg.norm(q))
    if abs(norm - 1.0) > QUAT_NORM_TOLERANCE:
        raise ConfigError(
            f"{key}: quaternion {[float(x) for x in q]} has norm {norm:.6f}, not 1 (order is "
            "qx, qy, qz, qw); fix or re-acquire the transform",
            path=source,
        )
    return _vec3(t), _quat(q / norm)


def parse_transform(data: Any, source: str = "<transform>") -> MarkerTransform:
    """Validate a parsed Listing 11/12 mapping."""
    if not isinstance(data, dict):
        raise ConfigError("transform file: expected a mapping (Listing 11)", path=source)
    if "marker_to_robot_transform" not in data and "pose" in data:
        raise ConfigError(
            "transform file: this is a 'pose:' dump, not the Listing 11 format "
            "(marker_to_robot_transform); re-acquire with `ertools acquire transform`",
            path=source,
        )
    t, q = _pair(data, "marker_to_robot_transform", source)
    result = MarkerTransform(
        robot_info=str(data.get("robot_info", "")),
        timestamp=str(data.get("transform_timestamp", "")),
        translation=t,
        quat_xyzw=q,
        source=source,
    )
    if "robot_to_marker_transform" in data:
        t_inv, q_inv = _pair(data, "robot_to_marker_transform", source)
        _check_inverse(result, t_inv, q_inv, source)
    for key in ("robot_info", "transform_timestamp"):
        if key not in data:
            log.warning("%s: transform file has no %r (Listing 11)", source, key)
    return result


def _check_inverse(tr: MarkerTransform, t_inv: Vec3, q_inv: Quat, source: str) -> None:
    # lazy: scipy only where its rotations/statistics are needed (~0.3 s to import)
    from scipy.spatial.transform import Rotation

    t_exp, q_exp = tr.inverse()
    dt = float(np.linalg.norm(np.subtract(t_exp, t_inv)))
    dr = float((Rotation.from_quat(q_exp).inv() * Rotation.from_quat(q_inv)).magnitude())
    if dt > INVERSE_TOLERANCE_M or dr > INVERSE_TOLERANCE_RAD:
        raise ConfigError(
            f"robot_to_marker_transform is not the inverse of marker_to_robot_transform "
            f"(off by {dt * 1000:.1f} mm, {math.degrees(dr):.2f} deg); fix or re-acquire it",
            path=source,
        )


def load_transform(path: str | Path) -> MarkerTransform:
    """Read and validate a ``transform-<team>.yaml`` file."""
    return parse_transform(load_yaml(path, "transform"), source=str(path))


def team_transform_path(directory: str | Path, team: str) -> Path:
    """``DIR/transform-<team>.yaml``, as the 2015 launch file built it from ``team_name``."""
    return Path(directory) / f"transform-{team}.yaml"


def _flow(values: tuple[float, ...]) -> str:
    return "[" + ", ".join(repr(yaml_float(float(v))) for v in values) + "]"


def transform_yaml(tr: MarkerTransform) -> str:
    """Listing 11 text: team, timestamp, both directions, with the listing's comments."""
    t_inv, q_inv = tr.inverse()
    return (
        f"robot_info: {tr.robot_info}      # team name or other team identifier\n"
        f"transform_timestamp: {tr.timestamp} # acquisition timestamp\n"
        "marker_to_robot_transform:\n"
        f"- {_flow(tr.translation)}          # translation from markerset to robot\n"
        f"- {_flow(tr.quat_xyzw)} # orientation of robot wrt markerset\n"
        "robot_to_marker_transform:\n"
        f"- {_flow(t_inv)}          # translation from robot to markerset\n"
        f"- {_flow(q_inv)} # orientation of markerset wrt robot\n"
    )


# The live FBM2H score records the transform its node used (seed Listing 13: details.marker-robot
# transform, [[x, y, z], [qx, qy, qz, qw]]); an audit given none re-scores with it.
LIVE_TRANSFORM_KEY = "marker-robot transform"


def live_transform(live: Any) -> MarkerTransform | None:
    """The marker-to-robot transform the live FBM2H score says its node used, or None when the
    payload has none (or not as ``[[x, y, z], [qx, qy, qz, qw]]``)."""
    if not isinstance(live, dict):
        return None
    details = live.get("details")
    value = details.get(LIVE_TRANSFORM_KEY) if isinstance(details, dict) else None
    if value is None:
        value = live.get(LIVE_TRANSFORM_KEY)  # an early node wrote it at the top level
    if value is None:
        return None
    try:
        return parse_transform(
            {
                "robot_info": "live score",
                "transform_timestamp": "0",
                "marker_to_robot_transform": value,
            },
            source=f"the live score (details.{LIVE_TRANSFORM_KEY})",
        )
    except ConfigError:
        return None
