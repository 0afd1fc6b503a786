"""The marker-set-to-robot transform file (seed Listings 11 and 12).

``marker_to_robot_transform`` is T_marker_robot, the pose of the robot's odometric centre in
the marker set's frame, so that ``T_world_robot = T_world_marker * T_marker_robot``. The 2015
acquirer wrote it as tf's ``lookupTransform("/robot_markerset", "/world")`` with the robot
standing on the world origin, which is that same transform. ``robot_to_marker_transform`` is
its inverse; the 2015 files also carry extra keys (``mocap``, ``robot_pose``,
``marker_to_robot_transform_2D``) that the benchmark never read and that are ignored here.

Three layouts are read (:data:`LAYOUTS`), and the transform says which one it came from:

- ``listing-11``: the seed's Listing 11 (``robot_info``, ``marker_to_robot_transform``, ...).
- ``erl-rsbb``: the ERL 2016-19 RSBB acquirer's ``yaml.dump`` of tf's lookups:
  ``team_name``, ``markerset_to_robot_transform: !!python/tuple [[x, y, z], [qx, qy, qz, qw]]``
  (the same lookup as 2015's, ``/robot_markerset`` -> origin, so the same transform) and
  ``robot_to_markerset_transform``, its inverse.
- ``pose-dump``: a rosparam dump of a ``geometry_msgs/Pose`` under ``pose:`` (``position``
  x/y/z, ``orientation`` x/y/z/w), as some 2015 teams' files were: the marker-to-robot pose.

The ``!!python/tuple`` tag is read by a safe loader that builds a plain list: no Python
object is ever constructed from a file.
"""

from __future__ import annotations

import logging
import math
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from ertools.configs._yaml import check_radians, load_yaml, number
from ertools.errors import ConfigError
from ertools.frozen_dataclass import frozen_dataclass
from ertools.geometry import invert
from ertools.serialize import yaml_float

log = logging.getLogger("ertools.configs.transform")

# A quaternion typed or dumped with 6+ digits has |norm - 1| < 1e-5; 1e-3 still allows hand
# edits with 4 digits, while anything further off is a wrong value, not rounding.
QUAT_NORM_TOLERANCE = 1e-3
# robot_to_marker must invert marker_to_robot; beyond this the file was edited inconsistently.
INVERSE_TOLERANCE_M = 1e-3
INVERSE_TOLERANCE_RAD = 1e-3

LAYOUTS = ("listing-11", "erl-rsbb", "pose-dump", "identity")
Vec3 = tuple[float, float, float]
Quat = tuple[float, float, float, float]


#: The key ``ertools acquire transform`` writes after the Listing 11 keys: how much the
#: averaged marker poses spread (the 2015 node read the listing's keys by name, and ignores it).
SPREAD_KEY = "acquisition_spread"


@frozen_dataclass
class TransformSpread:
    """The spread of the marker poses an acquisition averaged (one standard deviation each).

    Attributes:
        position_std: (x, y, z) metres, along the axes of the mean marker frame (the frame of
            ``marker_to_robot_transform``'s translation).
        rotation_std: (x, y, z) radians, the rotation vector of each pose from the mean, about
            the same axes (x, y: tilt; z: yaw).
        samples: the number of poses averaged.
        effective_samples: as many independent poses as the averaged ones are worth (fewer
            when consecutive poses are correlated: ``samples (1 - rho) / (1 + rho)``, rho their
            lag-1 autocorrelation); the transform's error is the spread over its square root.
    """

    position_std: Vec3
    rotation_std: Vec3
    samples: int
    effective_samples: int

    def standard_errors(self) -> tuple[Vec3, Vec3]:
        """(position, rotation) standard errors of the averaged transform, per axis."""
        root = math.sqrt(max(1, self.effective_samples))
        p, r = self.position_std, self.rotation_std
        return (p[0] / root, p[1] / root, p[2] / root), (r[0] / root, r[1] / root, r[2] / root)


@frozen_dataclass
class MarkerTransform:
    """T_marker_robot and where it came from.

    Attributes:
        robot_info: the team name (``identity`` for Listing 12).
        timestamp: the acquisition timestamp as written (``%Y-%m-%d_%H:%M:%S``, or ``0``).
        translation: (x, y, z) metres, robot origin in the marker frame.
        quat_xyzw: orientation of the robot in the marker frame (unit, scalar last).
        source: the file, or ``<identity>`` when none was given.
        layout: which of :data:`LAYOUTS` the file was written in.
        spread: the acquisition's spread (:data:`SPREAD_KEY`), None for a file without it
            (older acquisitions, hand-written and 2015 files).
    """

    robot_info: str
    timestamp: str
    translation: Vec3
    quat_xyzw: Quat
    source: str = ""
    layout: str = "listing-11"
    spread: TransformSpread | None = None

    @property
    def described(self) -> str:
        """The source and, for a file not in the seed's Listing 11, its layout."""
        if self.layout in ("listing-11", "identity"):
            return self.source
        return f"{self.source} ({self.layout} layout)"

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
    return MarkerTransform(
        "identity", "0", (0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0), "<identity>", "identity"
    )


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


def _from_pose_dump(pose: Any, source: str) -> dict[str, Any]:
    """A rosparam ``pose:`` dump as the Listing 11 mapping it stands for."""
    if not isinstance(pose, dict):
        raise ConfigError("pose: expected position and orientation mappings", path=source)
    pos, ori = pose.get("position"), pose.get("orientation")
    if not isinstance(pos, dict) or not isinstance(ori, dict):
        raise ConfigError(
            "pose: expected 'position' (x, y, z) and 'orientation' (x, y, z, w)", path=source
        )
    missing = [f"position.{k}" for k in "xyz" if k not in pos]
    missing += [f"orientation.{k}" for k in "xyzw" if k not in ori]
    if missing:
        raise ConfigError(f"pose: missing {', '.join(missing)}", path=source)
    return {
        "marker_to_robot_transform": [[pos[k] for k in "xyz"], [ori[k] for k in "xyzw"]],
    }


def _layout(data: dict[str, Any], source: str) -> tuple[str, dict[str, Any]]:
    """(layout, the mapping in Listing 11 keys) of a parsed transform file."""
    if "marker_to_robot_transform" in data:
        return "listing-11", data
    if "markerset_to_robot_transform" in data:
        out: dict[str, Any] = {
            "robot_info": data.get("team_name", data.get("robot_info", "")),
            "transform_timestamp": data.get("transform_timestamp", ""),
            "marker_to_robot_transform": data["markerset_to_robot_transform"],
        }
        if "robot_to_markerset_transform" in data:
            out["robot_to_marker_transform"] = data["robot_to_markerset_transform"]
        return "erl-rsbb", out
    if "pose" in data:
        out = _from_pose_dump(data["pose"], source)
        out["robot_info"] = data.get("robot_info", data.get("team_name", ""))
        out["transform_timestamp"] = data.get("transform_timestamp", "")
        return "pose-dump", out
    raise ConfigError(
        "transform file: no marker_to_robot_transform (Listing 11), "
        "markerset_to_robot_transform (ERL RSBB) or pose (rosparam dump); keys found: "
        f"{', '.join(map(str, data)) or 'none'}",
        path=source,
    )


def _parse_spread(value: Any, source: str) -> TransformSpread | None:
    """The :data:`SPREAD_KEY` mapping; a malformed one is an error (never silently a default)."""
    if value is None:
        return None
    what = SPREAD_KEY
    if not isinstance(value, dict):
        raise ConfigError(
            f"{what}: expected a mapping (position_std, rotation_std, samples)", path=source
        )
    missing = [k for k in ("position_std", "rotation_std", "samples") if k not in value]
    if missing:
        raise ConfigError(f"{what}: missing {', '.join(missing)}", path=source)
    pos = _numbers(value["position_std"], 3, f"{what}.position_std", source)
    rot = _numbers(value["rotation_std"], 3, f"{what}.rotation_std", source)
    counts = []
    for key in ("samples", "effective_samples"):
        v = value.get(key, value["samples"])
        if isinstance(v, bool) or not isinstance(v, int) or v < 1:
            raise ConfigError(f"{what}.{key}: expected a whole number >= 1, got {v!r}", path=source)
        counts.append(v)
    if any(x < 0 for x in (*pos, *rot)):
        raise ConfigError(f"{what}: a standard deviation cannot be negative", path=source)
    for axis, r in zip("xyz", rot, strict=True):
        # a rotation vector is at most pi long: a larger spread is a number in degrees
        check_radians(r, f"{what}.rotation_std {axis}", source, limit=math.pi, bound="pi")
    if counts[1] > counts[0]:
        raise ConfigError(
            f"{what}: effective_samples {counts[1]} exceeds samples {counts[0]}", path=source
        )
    return TransformSpread(_vec3(pos), _vec3(rot), counts[0], counts[1])


def parse_transform(data: Any, source: str = "<transform>") -> MarkerTransform:
    """Validate a parsed transform mapping: Listing 11/12, ERL RSBB or a ``pose:`` dump."""
    if not isinstance(data, dict):
        raise ConfigError("transform file: expected a mapping (Listing 11)", path=source)
    layout, data = _layout(data, source)
    t, q = _pair(data, "marker_to_robot_transform", source)
    result = MarkerTransform(
        robot_info=str(data.get("robot_info", "")),
        timestamp=str(data.get("transform_timestamp", "")),
        translation=t,
        quat_xyzw=q,
        source=source,
        layout=layout,
        spread=_parse_spread(data.get(SPREAD_KEY), source),
    )
    if "robot_to_marker_transform" in data:
        t_inv, q_inv = _pair(data, "robot_to_marker_transform", source)
        _check_inverse(result, t_inv, q_inv, source)
    if layout == "listing-11":
        for key in ("robot_info", "transform_timestamp"):
            if key not in data:
                log.warning("%s: transform file has no %r (Listing 11)", source, key)
    else:
        log.info("%s: transform read in the %s layout", source, layout)
    return result


def _check_inverse(tr: MarkerTransform, t_inv: Vec3, q_inv: Quat, source: str) -> None:
    from scipy.spatial.transform import Rotation  # lazy: scipy, 300 ms

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
    """Read and validate a ``transform-<team>.yaml`` file (any of :data:`LAYOUTS`)."""
    # every file read with the tuple tag (built as a list), so that the common limits apply
    # whatever the text says (a comment naming the tag once chose another loader)
    return parse_transform(load_yaml(path, "transform", tags="tuples"), source=str(path))


def team_transform_path(directory: str | Path, team: str) -> Path:
    """``DIR/transform-<team>.yaml``, as the 2015 launch file built it from ``team_name``."""
    return Path(directory) / f"transform-{team}.yaml"


def _flow(values: tuple[float, ...]) -> str:
    return "[" + ", ".join(repr(yaml_float(float(v))) for v in values) + "]"


def transform_yaml(tr: MarkerTransform) -> str:
    """Listing 11 text: team, timestamp, both directions, with the listing's comments; then,
    for an acquisition that measured it, its spread (:data:`SPREAD_KEY`, an extra key after
    the listing's)."""
    t_inv, q_inv = tr.inverse()
    text = (
        f"robot_info: {tr.robot_info}      # team name or other team identifier\n"
        f"transform_timestamp: {tr.timestamp} # acquisition timestamp\n"
        "marker_to_robot_transform:\n"
        f"- {_flow(tr.translation)}          # translation from markerset to robot\n"
        f"- {_flow(tr.quat_xyzw)} # orientation of robot wrt markerset\n"
        "robot_to_marker_transform:\n"
        f"- {_flow(t_inv)}          # translation from robot to markerset\n"
        f"- {_flow(q_inv)} # orientation of markerset wrt robot\n"
    )
    s = tr.spread
    if s is not None:
        text += (
            f"{SPREAD_KEY}:            # ertools: the averaged marker poses' spread (1 std)\n"
            f"  position_std: {_flow(s.position_std)}  # m, marker frame x y z\n"
            f"  rotation_std: {_flow(s.rotation_std)}  # rad, about marker x y z\n"
            f"  samples: {s.samples}  # poses averaged\n"
            f"  effective_samples: {s.effective_samples}  # independent poses they are worth\n"
        )
    return text


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
