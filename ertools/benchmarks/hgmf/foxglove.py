"""Foxglove content of an HGMF result (the table's frame; the object in it).

- ``/hgmf/object``: ``foxglove.PoseInFrame`` per sample of the object (decimated);
- ``/hgmf/targets``: one ``foxglove.SceneUpdate`` at the start: each goal's target (green);
- ``/hgmf/placed``: ``foxglove.SceneUpdate`` per measured goal at its final lookup: the object
  then (blue) and a line to its target (red), labelled with the distance;
- ``/hgmf/goals``: JSON per goal at its end: outcome, grasp, distance, rise;
- ``/ertools/log``: ``foxglove.Log``: each goal's start and outcome, the score, notes.
"""

from __future__ import annotations

import numpy as np

from ertools.benchmarks.hgmf.result import HgmfResult
from ertools.views.foxglove import (
    BLUE,
    GREEN,
    INFO,
    RED,
    WARNING,
    Collected,
    JsonSchema,
    Scene,
    every,
    log,
    pose_stream,
    result_notes,
)

GOAL_SCHEMA = JsonSchema(
    "ertools.HgmfGoal",
    (
        ("goal", "integer"),
        ("status", "string"),
        ("grasped", "boolean"),
        ("max_rise", "number"),
        ("distance_error", "number"),
        ("segment_time", "number"),
        ("target_x", "number"),
        ("target_y", "number"),
        ("object_x", "number"),
        ("object_y", "number"),
    ),
)


def content(out: Collected, r: HgmfResult, *, limit: int) -> None:
    t, xyz = r.track
    i = every(len(t), limit)
    pose_stream(out, "/hgmf/object", t[i], xyz[i], np.tile([0.0, 0.0, 0.0, 1.0], (len(i), 1)))
    targets = Scene(r.t_start_ns)
    for g in r.goals:
        a = g.attempt
        if a.target is not None:
            e = targets.entity(f"target goal_{a.index}")
            Scene.line(
                e, [(a.target[0], a.target[1], 0.0), (a.target[0], a.target[1], 0.05)], GREEN
            )
            Scene.text(e, (a.target[0], a.target[1], 0.1), f"goal_{a.index}")
    targets.add_to(out, "/hgmf/targets")
    for g in r.goals:
        a = g.attempt
        log(out, a.times.start_ns, INFO, f"goal_{a.index}: {g.description}", r.name)
        if g.position is not None and a.target is not None and a.final_ns is not None:
            placed = Scene(a.final_ns)
            e = placed.entity(f"placed goal_{a.index}")
            x, y = g.position
            Scene.line(e, [(x, y, 0.0), (a.target[0], a.target[1], 0.0)], RED, pairs=True)
            Scene.line(e, [(x, y, 0.0), (x, y, 0.05)], BLUE)
            if g.distance_error is not None:
                Scene.text(e, (x, y, 0.1), f"goal_{a.index}: {g.distance_error * 1000:.1f} mm")
            placed.add_to(out, "/hgmf/placed")
        level = INFO if g.status == "measured" else WARNING
        log(out, a.times.end_ns, level, f"goal_{a.index}: {g.status}", r.name)
        out.json(
            "/hgmf/goals",
            a.times.end_ns,
            GOAL_SCHEMA,
            {
                "goal": a.index,
                "status": g.status,
                "grasped": g.grasped,
                "max_rise": g.max_rise,
                "distance_error": g.distance_error,
                "segment_time": a.times.segment_ns / 1e9,
                "target_x": None if a.target is None else a.target[0],
                "target_y": None if a.target is None else a.target[1],
                "object_x": None if g.position is None else g.position[0],
                "object_y": None if g.position is None else g.position[1],
            },
        )
    log(
        out,
        r.goals[-1].attempt.times.end_ns if r.goals else r.t_start_ns,
        INFO,
        f"Objects grasped {r.score.get('Objects grasped')}, Avg distance error {r.average}",
        r.name,
    )
    result_notes(out, r, r.name)
