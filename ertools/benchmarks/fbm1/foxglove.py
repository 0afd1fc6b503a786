"""Foxglove content of an FBM1@Home / FBM1@Work result.

Topics (the table frame ``table``, where the item's ground truth and the answers are given):

- ``/<fbm1h|fbm1w>/items``: ``foxglove.SceneUpdate`` per run at its result (else goal)
  time: the item's ground truth (green arrow at its height), the robot's answer (blue arrow
  on the table), a line between them (red) and a label; it stays until the next run's;
- ``/<name>/runs``: JSON per run: class/instance right, translation and angle errors, pose score;
- ``/ertools/log``: ``foxglove.Log``: each run's item and outcome, the totals, notes.
"""

from __future__ import annotations

import math

from ertools.benchmarks.fbm1.result import Fbm1Result, Fbm1RunResult
from ertools.views.foxglove import (
    BLUE,
    ERROR,
    GREEN,
    INFO,
    RED,
    Collected,
    JsonSchema,
    Scene,
    log,
    result_notes,
)

TABLE = "table"

RUN_SCHEMA = JsonSchema(
    "ertools.Fbm1Run",
    (
        ("run", "integer"),
        ("status", "string"),
        ("item", "string"),
        ("answer", "string"),
        ("class_correct", "boolean"),
        ("instance_correct", "boolean"),
        ("translation_error", "number"),
        ("theta_error_deg", "number"),
        ("pose_score", "number"),
        ("execution_time", "number"),
    ),
)


def _t(run: Fbm1RunResult) -> int | None:
    for t in (run.result_ns, run.goal_ns, None if run.gt is None else run.gt.end_ns):
        if t is not None:
            return t
    return None


def content(out: Collected, r: Fbm1Result, *, limit: int) -> None:
    known = [_t(run) for run in r.runs]
    fallback = next((t for t in known if t is not None), r.t0_ns)
    times = [fallback if t is None else t for t in known]
    for k, run in enumerate(r.runs):
        t = times[k]
        later = [x for x in known[k + 1 :] if x is not None]
        _scene(out, run, t, (later[0] - t) if later else None, r.name)
        e = run.errors
        item = "" if run.item is None else f"{run.item.id}:{run.item.instance}"
        answer = "" if run.answer is None else run.answer.item_instance
        out.json(
            f"/{r.name}/runs",
            t,
            RUN_SCHEMA,
            {
                "run": run.index,
                "status": run.status,
                "item": item or run.item_text,
                "answer": answer,
                "class_correct": run.class_ok,
                "instance_correct": run.instance_ok,
                "translation_error": None if e is None else e.trans_error_m,
                "theta_error_deg": None if e is None else e.theta_error_deg,
                "pose_score": run.pose_score,
                "execution_time": run.execution_time_s,
            },
        )
        if e is not None:
            text = (
                f"run {run.index}: item {item or run.item_text}, answer {answer or '-'}: "
                f"{e.trans_error_m * 1000:.1f} mm, {e.theta_error_deg:.2f} deg, pose score "
                f"{e.pose_score:.4f}"
            )
            log(out, t, INFO, text, r.name)
        else:
            level = ERROR if run.status == "failed" else INFO
            reason = f": {run.error}" if run.error else ""
            log(out, t, level, f"run {run.index}: {run.status}{reason}", r.name)
    tt = r.totals
    last = max(times, default=r.t0_ns)
    log(
        out,
        last,
        INFO,
        f"class_accuracy {tt.class_accuracy}, instance_accuracy {tt.instance_accuracy}, "
        f"pose_score {tt.pose_score}, execution_time {tt.execution_time}",
        r.name,
    )
    result_notes(out, r, r.name)


def _scene(out: Collected, run: Fbm1RunResult, t: int, lifetime_ns: int | None, name: str) -> None:
    g, a = run.gt, run.answer
    if g is None and a is None:
        return
    scene = Scene(t, TABLE)
    e = scene.entity(f"run {run.index}", lifetime_ns)
    if g is not None:
        Scene.arrow(e, (g.x, g.y, g.z), g.yaw, GREEN, length=0.1)
    if a is not None:
        Scene.arrow(e, (a.x, a.y, 0.0), math.radians(a.theta_deg), BLUE, length=0.1)
    if g is not None and a is not None:
        Scene.line(e, [(g.x, g.y, g.z), (a.x, a.y, 0.0)], RED, pairs=True)
    where = (g.x, g.y, g.z + 0.05) if g is not None else (a.x, a.y, 0.05)  # type: ignore[union-attr]
    item = run.item.instance if run.item is not None else run.item_text
    score = "" if run.pose_score is None else f", pose score {run.pose_score:.3f}"
    Scene.text(e, where, f"run {run.index}: {item}{score}")
    scene.add_to(out, f"/{name}/items")
