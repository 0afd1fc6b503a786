"""Foxglove content of an FBM3@Work result.

Topics (world frame, the plane z = 0: the 2015 scorer worked on Pose2D x, y):

- ``/fbm3w/runs``: ``foxglove.SceneUpdate`` per scored run at its path start: the target
  shape placed in the run frame (green), the measured path (blue), a line from each kept
  point to the target point it was compared with (red), the run frame's x axis (an arrow at
  the starting position) and a label; it stays until the next run starts;
- ``/fbm3w/errors``: JSON per kept point, at that sample's time: ``l_norm``, ``error`` (Eq. 1
  averages these: the start point counts with error 0);
- ``/fbm3w/scores``: JSON per run at its end: status, distance_error, execution_time;
- ``/ertools/log``: ``foxglove.Log``: each run's start and outcome, warnings, deviations.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ertools.benchmarks.fbm3w.result import Fbm3wResult, RunResult
from ertools.views.foxglove import (
    BLUE,
    ERROR,
    GREEN,
    GREY,
    INFO,
    RED,
    WARNING,
    Collected,
    JsonSchema,
    Scene,
    log,
    result_notes,
    xyz0,
)

POINT_SCHEMA = JsonSchema(
    "ertools.Fbm3wPointError",
    (
        ("run", "integer"),
        ("point", "integer"),
        ("l_norm", "number"),
        ("error", "number"),
        ("x", "number"),
        ("y", "number"),
        ("target_x", "number"),
        ("target_y", "number"),
    ),
)
RUN_SCHEMA = JsonSchema(
    "ertools.Fbm3wRun",
    (
        ("run", "integer"),
        ("spec", "string"),
        ("status", "string"),
        ("distance_error", "number"),
        ("execution_time", "number"),
        ("kept_samples", "integer"),
        ("path_length", "number"),
        ("target_length", "number"),
    ),
)


def _times(run: RunResult) -> list[int]:
    w = run.window
    return [t for t in (w.ref_ns, w.start_ns, w.end_ns) if t is not None]


def content(out: Collected, r: Fbm3wResult, *, limit: int) -> None:
    known = [t for run in r.runs for t in _times(run)]
    t_first = min(known) if known else 0
    starts = [run.window.start_ns for run in r.runs]
    for k, run in enumerate(r.runs):
        times = _times(run)
        t_start = (
            run.window.start_ns if run.window.start_ns is not None else (times or [t_first])[0]
        )
        t_end = run.window.end_ns if run.window.end_ns is not None else (times or [t_first])[-1]
        later = [t for t in starts[k + 1 :] if t is not None]
        _scene(out, run, t_start, (later[0] - t_start) if later else None)
        _point_errors(out, run)
        err = run.distance_error
        out.json(
            "/fbm3w/scores",
            t_end,
            RUN_SCHEMA,
            {
                "run": run.index,
                "spec": run.spec,
                "status": run.status,
                "distance_error": err,
                "execution_time": run.execution_time,
                "kept_samples": None if run.score is None else len(run.score.kept),
                "path_length": None if run.score is None else run.score.path_length,
                "target_length": run.target_length,
            },
        )
        log(out, t_start, INFO, f"run {run.index} ({run.spec}): path starts", r.name)
        if err is not None:
            text, level = f"run {run.index} ({run.spec}): distance_error {err * 1000:.4f} mm", INFO
        elif run.error is not None:
            text, level = f"run {run.index} ({run.spec}): not scored: {run.error}", ERROR
        else:
            text, level = f"run {run.index} ({run.spec}): {run.status}, not scored", WARNING
        log(out, t_end, level, text, r.name)
    best = r.best_distance_error
    if best is not None and known:
        log(
            out,
            max(known),
            INFO,
            f"best run {r.best_run}: distance_error {best * 1000:.4f} mm; execution_time "
            f"{r.execution_time:.3f} s",
            r.name,
        )
    result_notes(out, r, r.name)


def _scene(out: Collected, run: RunResult, t_ns: int, lifetime_ns: int | None) -> None:
    s = run.score
    if s is None:
        return
    to_world = s.frame.to_world
    scene = Scene(t_ns)
    e = scene.entity(f"run {run.index}", lifetime_ns)
    if run.target_dense is not None:
        Scene.line(e, xyz0(to_world(np.asarray(run.target_dense))).tolist(), GREEN)
    if run.frame_xy is not None:
        Scene.line(e, xyz0(to_world(np.asarray(run.frame_xy))).tolist(), BLUE, thickness=2.0)
    pairs = np.empty((2 * len(s.kept), 3))
    pairs[0::2] = xyz0(to_world(s.kept_frame))
    pairs[1::2] = xyz0(to_world(s.target))
    Scene.line(e, pairs.tolist(), RED, pairs=True, thickness=1.0)
    origin = (s.frame.origin[0], s.frame.origin[1], 0.0)
    Scene.arrow(e, origin, s.frame.yaw, GREY, length=0.05)
    label = f"run {run.index} {run.spec}: {s.distance_error * 1000:.3f} mm"
    Scene.text(e, (origin[0], origin[1], 0.02), label)
    scene.add_to(out, "/fbm3w/runs")


def _point_errors(out: Collected, run: RunResult) -> None:
    s = run.score
    t: Any = run.sample_t_ns
    if s is None or t is None:
        return
    # Every kept point, not decimated: a run is seconds long, a few hundred kept points.
    kept_t = np.asarray(t, dtype=np.int64)[s.kept]
    for i, (tt, ln, e, p, q) in enumerate(
        zip(
            kept_t.tolist(),
            s.l_norm.tolist(),
            s.errors.tolist(),
            s.kept_frame.tolist(),
            s.target.tolist(),
            strict=True,
        )
    ):
        out.json(
            "/fbm3w/errors",
            tt,
            POINT_SCHEMA,
            {
                "run": run.index,
                "point": i,
                "l_norm": ln,
                "error": e,
                "x": p[0],
                "y": p[1],
                "target_x": q[0],
                "target_y": q[1],
            },
        )
