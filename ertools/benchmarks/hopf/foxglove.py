"""Foxglove content of a HOPF result.

Topics (the table frame ``table_origin``, where the ground truth and the answers are given):

- ``/hopf/items``: ``foxglove.SceneUpdate`` per goal at its lookup: the item's ground truth
  (green arrow), the answer (blue arrow, at the goal's end), a line between them (red) and a
  label; it stays until the next goal's;
- ``/hopf/goals``: JSON per goal: status, class/instance right, errors, pose score;
- ``/ertools/log``: ``foxglove.Log``: each goal's item and outcome, the totals, notes.
"""

from __future__ import annotations

import math

from ertools.benchmarks.hopf.goals import GoalRecord
from ertools.benchmarks.hopf.result import HopfResult
from ertools.views.foxglove import (
    BLUE,
    GREEN,
    INFO,
    RED,
    Collected,
    JsonSchema,
    Scene,
    log,
    result_notes,
)

TABLE = "table_origin"

GOAL_SCHEMA = JsonSchema(
    "ertools.HopfGoal",
    (
        ("goal", "integer"),
        ("status", "string"),
        ("item", "string"),
        ("class_correct", "boolean"),
        ("instance_correct", "boolean"),
        ("translation_error", "number"),
        ("theta_error", "number"),
        ("pose_score", "number"),
        ("segment_time", "number"),
    ),
)


def _t(goal: GoalRecord, fallback: int) -> int:
    if goal.truth is not None and goal.truth.moment_ns is not None:
        return goal.truth.moment_ns
    if goal.times is not None:
        return goal.times.start_ns
    return fallback


def content(out: Collected, r: HopfResult, *, limit: int) -> None:
    del limit
    origin = r.origin_ns or 0
    times = [_t(g, origin) for g in r.goals]
    for k, g in enumerate(r.goals):
        t = times[k]
        later = times[k + 1] - t if k + 1 < len(times) else None
        _scene(out, g, t, later, r.name)
        terms = g.terms
        item = "" if g.item is None else f"{g.item.id}:{g.item.instance}"
        out.json(
            f"/{r.name}/goals",
            t,
            GOAL_SCHEMA,
            {
                "goal": g.index,
                "status": g.status,
                "item": item,
                "class_correct": g.class_ok,
                "instance_correct": g.instance_ok,
                "translation_error": None if terms is None else math.hypot(terms[0], terms[1]),
                "theta_error": None if terms is None else terms[2],
                "pose_score": None if terms is None else terms[5],
                "segment_time": None if g.segment_ns is None else g.segment_ns / 1e9,
            },
        )
        score = "" if terms is None else f", pose score {terms[5]:.4f}"
        log(out, t, INFO, f"goal {g.index}: item {item or '?'}, {g.status}{score}", r.name)
    s = r.score
    log(
        out,
        max(times, default=origin),
        INFO,
        f"class_accuracy {s.get('class_accuracy')}, instance_accuracy "
        f"{s.get('instance_accuracy')}, pose_score {s.get('pose_score')}, execution_time "
        f"{s.get('execution_time')}",
        r.name,
    )
    result_notes(out, r, r.name)


def _scene(out: Collected, g: GoalRecord, t: int, lifetime_ns: int | None, name: str) -> None:
    truth = g.truth.pose if g.truth is not None else None
    a = g.answer.pose if g.answer is not None else None
    if a is not None and not all(math.isfinite(v) for v in a):
        a = None
    if truth is None and a is None:
        return
    scene = Scene(t, TABLE)
    e = scene.entity(f"goal {g.index}", lifetime_ns)
    if truth is not None:
        Scene.arrow(e, (truth[0], truth[1], 0.0), truth[2], GREEN, length=0.1)
    if a is not None:
        Scene.arrow(e, (a[0], a[1], 0.0), a[2], BLUE, length=0.1)
    if truth is not None and a is not None:
        Scene.line(e, [(truth[0], truth[1], 0.0), (a[0], a[1], 0.0)], RED, pairs=True)
    where = (truth or a or (0.0, 0.0, 0.0))[:2]
    item = "?" if g.item is None else str(g.item.instance)
    score = "" if g.terms is None else f", pose score {g.terms[5]:.3f}"
    Scene.text(e, (where[0], where[1], 0.05), f"goal {g.index}: {item}{score}")
    scene.add_to(out, f"/{name}/items")
