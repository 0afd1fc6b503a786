"""The mocap_optitrack rigid-body config (seed Listing 2/3): Motive rigid-body IDs to topics.

The 2015 logger (``rockin_mocap/config/all_home_mocap.yaml``) mapped each Motive rigid-body ID
(the ``UserData`` field of the body) to a ``PoseStamped`` topic, a ``Pose2D`` topic and a tf
frame::

    rigid_bodies:
      '3':
        pose: robot_at_home/pose
        pose2d: robot_at_home/pose2d
        child_frame_id: robot_at_home
        parent_frame_id: world

Topics are relative, as in ROS: the recorder puts them under a namespace (``/fbm2h``) the way
the 2015 launch files pushed the node into the benchmark's namespace. mocap_optitrack's optional
``optitrack_config`` block (``multicast_address``, ``data_port``) is read as the default
network settings.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from ertools.configs._yaml import load_yaml, parse_yaml
from ertools.errors import ConfigError
from ertools.frozen_dataclass import frozen_dataclass

DEFAULT_GROUP = "224.0.0.1"  # seed 4.1: "The correct multicast IP to use is 224.0.0.1"
DEFAULT_DATA_PORT = 1511  # NatNet's data port
DEFAULT_COMMAND_PORT = 1510


@frozen_dataclass
class RigidBodyConfig:
    """One tracked rigid body: where its pose goes.

    Attributes:
        body_id: Motive's rigid-body ID.
        pose: PoseStamped topic as written in the YAML (relative or absolute), or None.
        pose2d: Pose2D topic, or None.
        child_frame_id: tf child frame (also the PoseStamped's body name), or None.
        parent_frame_id: tf parent frame and PoseStamped ``header.frame_id``.
    """

    body_id: int
    pose: str | None
    pose2d: str | None
    child_frame_id: str | None
    parent_frame_id: str = "world"

    @property
    def name(self) -> str:
        """A human name: the child frame, else the pose topic's first part, else the ID."""
        if self.child_frame_id:
            return self.child_frame_id
        for topic in (self.pose, self.pose2d):
            if topic:
                return topic.strip("/").split("/")[0]
        return f"body{self.body_id}"

    def pose_topic(self, namespace: str = "") -> str | None:
        return resolve_topic(self.pose, namespace)

    def pose2d_topic(self, namespace: str = "") -> str | None:
        return resolve_topic(self.pose2d, namespace)


@frozen_dataclass
class MocapConfig:
    """The whole config: bodies by ID plus the optional network defaults."""

    bodies: tuple[RigidBodyConfig, ...]
    group: str = DEFAULT_GROUP
    data_port: int = DEFAULT_DATA_PORT
    source: str = ""

    def by_id(self) -> dict[int, RigidBodyConfig]:
        return {b.body_id: b for b in self.bodies}

    def topics(self, namespace: str = "") -> list[str]:
        """Every topic the recorder may write (``/tf`` included when any body has frames)."""
        out: list[str] = []
        for b in self.bodies:
            out += [t for t in (b.pose_topic(namespace), b.pose2d_topic(namespace)) if t]
        if any(b.child_frame_id and b.parent_frame_id for b in self.bodies):
            out.append("/tf")
        return out


def normalize_namespace(namespace: str | None) -> str:
    """``fbm2h``, ``/fbm2h/`` -> ``/fbm2h``; empty or ``/`` -> ``""``."""
    ns = (namespace or "").strip().strip("/")
    return f"/{ns}" if ns else ""


def resolve_topic(topic: str | None, namespace: str = "") -> str | None:
    """A relative topic under ``namespace``; absolute topics (leading ``/``) stay as they are."""
    if not topic:
        return None
    if topic.startswith("/"):
        return topic
    return f"{normalize_namespace(namespace)}/{topic}"


def _opt_str(entry: dict[str, Any], key: str, where: str, source: str) -> str | None:
    value = entry.get(key)
    if value is None:
        return None
    if not isinstance(value, str) or not value.strip() or any(c.isspace() for c in value):
        raise ConfigError(
            f"{where}: {key} must be a name without spaces, got {value!r}", path=source
        )
    return value


def mocap_config_from_data(data: Any, source: str = "<mocap config>") -> MocapConfig:
    """Validate parsed YAML into a :class:`MocapConfig`."""
    if not isinstance(data, dict) or "rigid_bodies" not in data:
        raise ConfigError(
            "mocap config: expected a mapping with key 'rigid_bodies' (seed Listing 2)", path=source
        )
    rigid = data["rigid_bodies"]
    stray = [k for k in data if k not in ("rigid_bodies", "optitrack_config")]
    if stray and not rigid:
        # Listing 2 as printed in the seed has its IDs at column 0, which YAML reads as
        # top-level keys next to an empty rigid_bodies.
        raise ConfigError(
            f"mocap config: 'rigid_bodies' is empty but top-level key(s) {stray} look like "
            "rigid bodies: indent them under rigid_bodies",
            path=source,
        )
    if not isinstance(rigid, dict) or not rigid:
        raise ConfigError(
            "mocap config: 'rigid_bodies' must map Motive IDs to topics and has no entries "
            "(are they all commented out?)",
            path=source,
        )
    bodies: list[RigidBodyConfig] = []
    for key, entry in rigid.items():
        try:
            body_id = int(str(key))
        except ValueError:
            raise ConfigError(
                f"mocap config: rigid body key {key!r} is not a Motive ID (an integer)", path=source
            ) from None
        if body_id < 0:
            raise ConfigError(f"mocap config: rigid body ID {body_id} is negative", path=source)
        where = f"rigid_bodies['{key}']"
        if not isinstance(entry, dict):
            raise ConfigError(f"mocap config: {where} must be a mapping", path=source)
        unknown = set(entry) - {"pose", "pose2d", "child_frame_id", "parent_frame_id"}
        if unknown:
            raise ConfigError(
                f"mocap config: {where} has unknown key(s) {sorted(unknown)}; expected pose, "
                "pose2d, child_frame_id, parent_frame_id",
                path=source,
            )
        body = RigidBodyConfig(
            body_id=body_id,
            pose=_opt_str(entry, "pose", where, source),
            pose2d=_opt_str(entry, "pose2d", where, source),
            child_frame_id=_opt_str(entry, "child_frame_id", where, source),
            parent_frame_id=_opt_str(entry, "parent_frame_id", where, source) or "world",
        )
        if not (body.pose or body.pose2d or body.child_frame_id):
            raise ConfigError(
                f"mocap config: {where} publishes nothing (give pose, pose2d or child_frame_id)",
                path=source,
            )
        bodies.append(body)
    if len({b.body_id for b in bodies}) != len(bodies):
        raise ConfigError("mocap config: the same rigid body ID appears twice", path=source)
    topics = [t for b in bodies for t in (b.pose, b.pose2d) if t]
    dupes = sorted({t for t in topics if topics.count(t) > 1})
    if dupes:
        raise ConfigError(f"mocap config: topic(s) {dupes} used by two bodies", path=source)

    group, port = DEFAULT_GROUP, DEFAULT_DATA_PORT
    net = data.get("optitrack_config")
    if net is not None:
        if not isinstance(net, dict):
            raise ConfigError("mocap config: 'optitrack_config' must be a mapping", path=source)
        group = str(net.get("multicast_address", group))
        try:
            port = int(net.get("data_port", port))
        except (TypeError, ValueError):
            raise ConfigError(
                "mocap config: optitrack_config.data_port is not an integer", path=source
            ) from None
    return MocapConfig(
        bodies=tuple(sorted(bodies, key=lambda b: b.body_id)),
        group=group,
        data_port=port,
        source=source,
    )


def load_mocap_config(path: str | Path) -> MocapConfig:
    """Read a mocap YAML (seed Listing 2/3) with ``yaml.safe_load`` and validate it."""
    return mocap_config_from_data(load_yaml(path, what="mocap config"), source=str(path))


def parse_mocap_config(text: str, source: str = "<string>") -> MocapConfig:
    """Parse mocap YAML text (tests, ``--simulate``)."""
    return mocap_config_from_data(parse_yaml(text, source=source, what="mocap config"), source)
