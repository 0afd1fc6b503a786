"""The FBM2@Home goal list (seed Listing 10).

The same YAML is both the config file (``goal:`` at the top) and the payload of the BmBox's
first TRANSMITTING_GOAL message (the 2015 node dumped the ``goal`` parameter itself, so the
payload has no ``goal:`` key). :func:`parse_goal` accepts both, and the ERL 2016-19 RSBB's
benchmark config (``benchmark_configs/HNF.yaml``: ``starting_pose``, ``waypoints`` and
``goal_timeout`` at the top level, no ``goal:``); :attr:`GoalList.layout` says which was read.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from ertools.configs._yaml import check_radians, load_yaml, number, parse_payload
from ertools.errors import ConfigError
from ertools.frozen_dataclass import frozen_dataclass

Pose2 = tuple[float, float, float]


@frozen_dataclass
class GoalList:
    """Waypoints to visit in order, as (x [m], y [m], theta [rad]) in the testbed frame.

    Attributes:
        waypoints: the waypoints, in the order the robot must reach them.
        starting_pose: where the robot should start (not used by the score), or None.
        penalty_time: seconds, passed to the RefBox only (None when absent).
        timeout_time: seconds, passed to the RefBox only (None when absent).
        source: the file or payload it came from.
        layout: ``listing-10`` (the seed's, or its payload) or ``erl-rsbb`` (a later
            season's HNF config; its ``goal_timeout`` is the per-waypoint timeout).
    """

    waypoints: tuple[Pose2, ...]
    starting_pose: Pose2 | None = None
    penalty_time: float | None = None
    timeout_time: float | None = None
    source: str = ""
    layout: str = "listing-10"

    def __len__(self) -> int:
        return len(self.waypoints)

    def as_array(self) -> npt.NDArray[np.float64]:
        """(N, 3) array of x, y, theta."""
        return np.asarray(self.waypoints, dtype=np.float64).reshape(-1, 3)


def _number(value: Any, what: str, source: str) -> float:
    return number(value, what, source)


def _pose(value: Any, what: str, source: str) -> Pose2:
    # Listing 10 writes [x, y, theta]; the earliest 2015 configs used {x, y, theta} mappings.
    if isinstance(value, dict):
        missing = [k for k in ("x", "y", "theta") if k not in value]
        if missing:
            raise ConfigError(f"{what}: missing {', '.join(missing)}", path=source)
        value = [value["x"], value["y"], value["theta"]]
    if not isinstance(value, list | tuple) or len(value) != 3:
        raise ConfigError(f"{what}: expected [x, y, theta], got {value!r}", path=source)
    x, y, theta = (_number(v, what, source) for v in value)
    return (x, y, check_radians(theta, f"{what} theta", source))


def _optional_number(data: dict[str, Any], key: str, source: str) -> float | None:
    value = data.get(key)
    return None if value is None else _number(value, f"goal.{key}", source)


def parse_goal(data: Any, source: str = "<goal>") -> GoalList:
    """Validate a parsed goal list (with or without the top-level ``goal:`` key)."""
    if isinstance(data, dict) and "goal" in data:
        data = data["goal"]
    layout = "listing-10"
    if isinstance(data, dict) and "goal_timeout" in data and "timeout_time" not in data:
        layout = "erl-rsbb"
        data = {**data, "timeout_time": data["goal_timeout"]}
    if not isinstance(data, dict):
        raise ConfigError(
            "goal list: expected a mapping with 'waypoints' (Listing 10)", path=source
        )
    raw = data.get("waypoints")
    if raw is None:
        raise ConfigError("goal list: missing key 'goal.waypoints' (Listing 10)", path=source)
    if not isinstance(raw, list) or not raw:
        raise ConfigError("goal.waypoints: expected a non-empty list of [x, y, theta]", path=source)
    waypoints = tuple(_pose(w, f"goal.waypoints[{i}]", source) for i, w in enumerate(raw))
    declared = data.get("num_waypoints")
    if declared is not None and declared != len(waypoints):
        raise ConfigError(
            f"goal.num_waypoints is {declared!r} but {len(waypoints)} waypoints are listed",
            path=source,
        )
    start = data.get("starting_pose")
    return GoalList(
        waypoints=waypoints,
        starting_pose=None if start is None else _pose(start, "goal.starting_pose", source),
        penalty_time=_optional_number(data, "penalty_time", source),
        timeout_time=_optional_number(data, "timeout_time", source),
        source=source,
        layout=layout,
    )


def load_goal(path: str | Path) -> GoalList:
    """Read and validate a Listing 10 goal list file."""
    return parse_goal(load_yaml(path, "goal list"), source=str(path))


def goal_from_payload(payload: str, source: str) -> GoalList:
    """The goal list carried by the first TRANSMITTING_GOAL payload."""
    return parse_goal(parse_payload(payload, source=source, what="goal payload"), source=source)
