"""Foxglove content of an HPPF result.

Topics (the testbed frame ``testbed_origin``):

- ``/hppf/people``: ``foxglove.SceneUpdate`` per pass at its ground-truth lookup: the cap
  (green), the answer (blue), a line between them (red) and a label;
- ``/hppf/goals``: JSON per pass: person, status, name recognised, position error;
- ``/ertools/log``: ``foxglove.Log``: each pass's outcome, the totals, notes.
"""

from __future__ import annotations

from ertools.benchmarks.hppf.goals import PassRecord
from ertools.benchmarks.hppf.result import HppfResult
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

TESTBED = "testbed_origin"

PASS_SCHEMA = JsonSchema(
    "ertools.HppfGoal",
    (
        ("goal", "integer"),
        ("person", "string"),
        ("status", "string"),
        ("recognized", "boolean"),
        ("position_error", "number"),
        ("segment_time", "number"),
    ),
)


def _t(p: PassRecord, fallback: int) -> int:
    it = p.iteration
    for t in (it.truth_ns, None if it.times is None else it.times.end_ns, it.enter.t_done_ns):
        if t is not None:
            return t
    return fallback


def content(out: Collected, r: HppfResult, *, limit: int) -> None:
    del limit
    origin = r.origin_ns or 0
    times = [_t(p, origin) for p in r.passes]
    for p, t in zip(r.passes, times, strict=True):
        _scene(out, p, t, r.name)
        it = p.iteration
        out.json(
            f"/{r.name}/goals",
            t,
            PASS_SCHEMA,
            {
                "goal": p.index,
                "person": p.person,
                "status": p.status,
                "recognized": p.recognized,
                "position_error": p.position_error,
                "segment_time": None if it.times is None else it.times.segment_ns / 1e9,
            },
        )
        err = "" if p.position_error is None else f", {p.position_error:.3f} m"
        log(out, t, INFO, f"goal {p.index}: {p.person}, {p.status}{err}", r.name)
    s = r.score
    log(
        out,
        max(times, default=origin),
        INFO,
        f"Recognized persons {s.get('Recognized persons')} "
        f"({s.get('% Recognized persons')}), Distance error {s.get('Distance error')}, "
        f"execution_time {s.get('execution_time')}",
        r.name,
    )
    result_notes(out, r, r.name)


def _scene(out: Collected, p: PassRecord, t: int, name: str) -> None:
    truth = p.truth.xy if p.truth is not None else None
    a = p.answer.xy if p.answer is not None else None
    if truth is None and a is None:
        return
    scene = Scene(t, TESTBED)
    e = scene.entity(f"goal {p.index}")
    if truth is not None:
        Scene.line(e, [(truth[0], truth[1], 0.0), (truth[0], truth[1], 1.7)], GREEN)
    if a is not None:
        Scene.line(e, [(a[0], a[1], 0.0), (a[0], a[1], 1.7)], BLUE)
    if truth is not None and a is not None:
        Scene.line(e, [(truth[0], truth[1], 1.0), (a[0], a[1], 1.0)], RED, pairs=True)
    where = truth or a or (0.0, 0.0)
    Scene.text(e, (where[0], where[1], 1.9), f"goal {p.index}: {p.person}")
    scene.add_to(out, f"/{name}/people")
