"""Foxglove content of an HNF result (testbed frame ``testbed_origin``, poses on the floor):

- ``/hnf/marker_set``: ``foxglove.PoseInFrame`` per thinned marker-set sample;
- ``/hnf/waypoints``: one ``foxglove.SceneUpdate`` at the start: an arrow and a label per
  waypoint (green);
- ``/hnf/measured``: ``foxglove.SceneUpdate`` at each lookup: the robot pose (blue arrow) and
  a line to its waypoint (red), labelled with the errors;
- ``/hnf/segments``: JSON per segment at its end;
- ``/ertools/log``: each segment's outcome, the totals, the notes.
"""

from __future__ import annotations

import numpy as np

from ertools.benchmarks.hnf.result import HnfResult
from ertools.views.foxglove import (
    BLUE,
    ERROR,
    GREEN,
    INFO,
    RED,
    Collected,
    JsonSchema,
    Scene,
    every,
    log,
    pose_stream,
    result_notes,
    yaw_quat,
)

SEGMENT_SCHEMA = JsonSchema(
    "ertools.HnfSegment",
    (
        ("segment", "integer"),
        ("status", "string"),
        ("completed", "boolean"),
        ("distance_error", "number"),
        ("orientation_error", "number"),
        ("segment_time", "number"),
    ),
)


def content(out: Collected, r: HnfResult, *, limit: int) -> None:
    t_ns, xy = r.track
    i = every(len(t_ns), limit)
    xyz = np.column_stack([xy[i, 0], xy[i, 1], np.zeros(len(i))])
    quat = np.tile(yaw_quat(0.0), (len(i), 1)).reshape(-1, 4)
    pose_stream(out, "/hnf/marker_set", t_ns[i], xyz, quat)
    t0 = r.t_start_ns
    scene = Scene(t0)
    for k, w in enumerate(r.waypoints):
        x, y, th = (float(v) for v in w)
        e = scene.entity(f"waypoint {k + 1}")
        Scene.arrow(e, (x, y, 0.0), th, GREEN)
        Scene.text(e, (x, y, 0.15), f"waypoint {k + 1}")
    scene.add_to(out, "/hnf/waypoints")
    for s in r.segments:
        f = s.flow
        if s.robot is not None and s.distance_error is not None and f.lookup_ns is not None:
            x, y, th = s.robot
            shown = Scene(f.lookup_ns)
            e = shown.entity(f"measured {s.index + 1}")
            Scene.arrow(e, (x, y, 0.0), th, BLUE)
            tx, ty = float(s.waypoint[0]), float(s.waypoint[1])
            Scene.line(e, [(x, y, 0.0), (tx, ty, 0.0)], RED, pairs=True)
            err = s.orientation_error or 0.0
            label = f"segment {s.index + 1}: {s.distance_error * 1000:.1f} mm, {err:.4f} rad"
            Scene.text(e, (x, y, 0.3), label)
            shown.add_to(out, "/hnf/measured")
        level = INFO if s.measured else ERROR
        log(
            out,
            f.end_ns,
            level,
            f"segment {s.index + 1}: {'completed' if f.completed else 'not completed'}, {s.status}",
            r.name,
        )
        out.json(
            "/hnf/segments",
            f.end_ns,
            SEGMENT_SCHEMA,
            {
                "segment": s.index + 1,
                "status": s.status,
                "completed": f.completed,
                "distance_error": s.distance_error,
                "orientation_error": s.orientation_error,
                "segment_time": (f.end_ns - f.start_ns) / 1e9,
            },
        )
    if r.segments:
        totals = (
            f"position_accuracy {r.position_accuracy} m, "
            f"orientation_accuracy {r.orientation_accuracy} rad"
        )
        log(out, r.segments[-1].flow.end_ns, INFO, totals, r.name)
    result_notes(out, r, r.name)
