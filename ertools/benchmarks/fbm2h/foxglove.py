"""Foxglove content of an FBM2@Home result.

Topics (testbed frame ``world``, the robot pose on the floor, z = 0):

- ``/fbm2h/robot``: ``foxglove.PoseInFrame`` per pose of the result's robot path (the
  marker-robot transform applied, decimated to the figures' points);
- ``/fbm2h/robot_path``: one ``foxglove.PosesInFrame``, the whole path, at the first time;
- ``/fbm2h/waypoints``: one ``foxglove.SceneUpdate`` at the first time: an arrow and a label
  per waypoint (green);
- ``/fbm2h/reached``: ``foxglove.SceneUpdate`` per reached segment at the reached moment: the
  robot pose then (blue arrow) and a line to its waypoint (red), labelled with the errors;
- ``/fbm2h/segments``: JSON per segment at its end: distance and orientation error, time;
- ``/ertools/log``: ``foxglove.Log``: each segment's start and outcome, the score, notes.
"""

from __future__ import annotations

import numpy as np

from ertools.benchmarks.fbm2h.result import Fbm2hResult
from ertools.views.foxglove import (
    BLUE,
    ERROR,
    GREEN,
    INFO,
    RED,
    WARNING,
    Collected,
    JsonSchema,
    Scene,
    every,
    log,
    pose_path,
    pose_stream,
    result_notes,
    yaw_quat,
)

SEGMENT_SCHEMA = JsonSchema(
    "ertools.Fbm2hSegment",
    (
        ("segment", "integer"),
        ("status", "string"),
        ("distance_error", "number"),
        ("orientation_error", "number"),
        ("segment_time", "number"),
        ("target_x", "number"),
        ("target_y", "number"),
        ("target_theta", "number"),
        ("robot_x", "number"),
        ("robot_y", "number"),
        ("robot_theta", "number"),
    ),
)


def content(out: Collected, r: Fbm2hResult, *, limit: int) -> None:
    known = [t for s in r.segments for t in (s.start_ns, s.end_ns) if t is not None]
    if len(r.path_t_ns):
        known.append(int(r.path_t_ns[0]))
    t0 = min(known) if known else (r.origin_ns or 0)

    i = every(len(r.path_t_ns), limit)
    xyyaw = r.path_xyyaw[i]
    xyz = np.column_stack([xyyaw[:, 0], xyyaw[:, 1], np.zeros(len(i))])
    quat = np.array([yaw_quat(y) for y in xyyaw[:, 2].tolist()]).reshape(-1, 4)
    pose_stream(out, "/fbm2h/robot", r.path_t_ns[i], xyz, quat)
    if len(i):
        pose_path(out, "/fbm2h/robot_path", t0, xyz, quat)

    scene = Scene(t0)
    for k, (x, y, th) in enumerate(r.goal.waypoints):
        e = scene.entity(f"waypoint {k}")
        Scene.arrow(e, (x, y, 0.0), th, GREEN)
        Scene.text(e, (x, y, 0.15), f"waypoint {k}")
    scene.add_to(out, "/fbm2h/waypoints")

    for s in r.segments:
        t_end = s.end_ns if s.end_ns is not None else (s.start_ns or t0)
        if s.start_ns is not None:
            log(out, s.start_ns, INFO, f"segment {s.index}: to waypoint {s.index}", r.name)
        if s.robot is not None and s.distance_error is not None:
            reached = Scene(t_end)
            e = reached.entity(f"reached {s.index}")
            Scene.arrow(e, (s.robot[0], s.robot[1], 0.0), s.robot[2], BLUE)
            Scene.line(
                e,
                [(s.robot[0], s.robot[1], 0.0), (s.target[0], s.target[1], 0.0)],
                RED,
                pairs=True,
            )
            err_o = s.orientation_error if s.orientation_error is not None else float("nan")
            Scene.text(
                e,
                (s.robot[0], s.robot[1], 0.3),
                f"segment {s.index}: {s.distance_error * 1000:.1f} mm, {err_o:.4f} rad",
            )
            reached.add_to(out, "/fbm2h/reached")
            log(
                out,
                t_end,
                INFO,
                f"segment {s.index}: reached, distance_error {s.distance_error:.4f} m, "
                f"orientation_error {err_o:.4f} rad",
                r.name,
            )
        else:
            level = ERROR if s.status != "ok" else WARNING
            log(out, t_end, level, f"segment {s.index}: {s.status}", r.name)
        out.json(
            "/fbm2h/segments",
            t_end,
            SEGMENT_SCHEMA,
            {
                "segment": s.index,
                "status": s.status,
                "distance_error": s.distance_error,
                "orientation_error": s.orientation_error,
                "segment_time": s.segment_time,
                "target_x": s.target[0],
                "target_y": s.target[1],
                "target_theta": s.target[2],
                "robot_x": None if s.robot is None else s.robot[0],
                "robot_y": None if s.robot is None else s.robot[1],
                "robot_theta": None if s.robot is None else s.robot[2],
            },
        )
    if known:
        log(
            out,
            max(known),
            INFO,
            f"position_accuracy {r.position_accuracy} m, orientation_accuracy "
            f"{r.orientation_accuracy} rad, execution_time {r.execution_time:.3f} s",
            r.name,
        )
    result_notes(out, r, r.name)
