"""HNF's score in the result file's form (docs/hnf.md, "Score"), as the script at each commit
wrote it: per segment its times, outcome, poses and errors; then the totals.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import yaml

from ertools.benchmarks.hnf.config import HnfOptions
from ertools.benchmarks.hnf.flow import HnfFlow
from ertools.benchmarks.hnf.result import HnfSegment
from ertools.rsbb.py2 import to_sec

POSE2D_TAG = "tag:yaml.org,2002:python/object/new:geometry_msgs.msg._Pose2D.Pose2D"


class _Pose2D:
    """A genpy ``geometry_msgs/Pose2D`` as PyYAML saw it: its slots as a ``state`` list."""

    def __init__(self, x: Any, y: Any, theta: Any) -> None:
        self.state = [x, y, theta]


class _ScriptDumper(yaml.Dumper):
    """Python 2 PyYAML's ``yaml.dump`` (its default dumper) for the pose objects."""


def _represent(dumper: yaml.Dumper, pose: _Pose2D) -> yaml.Node:
    return dumper.represent_mapping(POSE2D_TAG, {"state": pose.state})


_ScriptDumper.add_representer(_Pose2D, _represent)


def pose_dump(pose: tuple[Any, Any, Any] | None) -> str:
    """``yaml.dump(pose)`` as the script wrote it (PyYAML 3's default flow style: the state
    list inline), or ``yaml.dump(None)``."""
    value = None if pose is None else _Pose2D(*pose)
    return str(yaml.dump(value, Dumper=_ScriptDumper, default_flow_style=None))


def _pose_map(pose: tuple[Any, Any, Any] | None) -> dict[str, float] | None:
    if pose is None:
        return None
    return {"x": float(pose[0]), "y": float(pose[1]), "theta": float(pose[2])}


def score_listing(
    segments: Sequence[HnfSegment],
    flow: HnfFlow,
    options: HnfOptions,
    totals: bool,
    position: float | None,
    orientation: float | None,
) -> dict[str, Any]:
    """The score mapping (``segment_<k>`` then the totals when the script reached them)."""
    score: dict[str, Any] = {}
    elapsed = 0
    for s in segments:
        f = s.flow
        seg: dict[str, Any] = {
            "start_segment_time[s]": to_sec(f.start_ns - flow.t_start_ns),
            "end_segment_time[s]": to_sec(f.end_ns - flow.t_start_ns),
            "segment_time[s]": to_sec(f.end_ns - f.start_ns),
            "timeout": f.timeout,
            "completed": f.completed,
        }
        elapsed += f.end_ns - f.start_ns
        if f.completed:
            seg["result"] = f.result
        if options.script == "00e3106" and f.answers:
            last = f.answers[-1]
            seg["manual_operation"] = "not executed" if last is None else last
        if f.poses_written:
            robot = s.robot if s.measured else None
            if options.score_format_2019:
                seg["target_pose"] = pose_dump(s.waypoint)
                seg["robot_pose"] = pose_dump(robot)
            else:
                seg["target_pose"] = _pose_map(s.waypoint)
                seg["robot_pose"] = _pose_map(robot)
        if s.measured:
            seg["distance_error"] = s.distance_error
            seg["orientation_error"] = s.orientation_error
        score[f"segment_{s.index + 1}"] = seg
    if totals:
        score["reached_waypoints"] = sum(s.flow.completed for s in segments)
        score["timed_out_waypoints"] = sum(s.flow.timeout is True for s in segments)
        score["execution_time[s]"] = to_sec(elapsed)
        score["position_accuracy[m]"] = position
        score["orientation_accuracy[rad]"] = orientation
    return score
