"""Foxglove content of an HPFF result (testbed frame, on the floor):

- ``/hpff/robot``, ``/hpff/person``: ``foxglove.PoseInFrame`` per thinned marker-set sample;
- ``/hpff/samples``: JSON per sample (distance, measured, the step counted);
- ``/ertools/log``: the duration verdict, the score, the notes.
"""

from __future__ import annotations

import numpy as np

from ertools.benchmarks.hpff.result import HpffResult
from ertools.views.foxglove import (
    ERROR,
    INFO,
    Collected,
    JsonSchema,
    every,
    log,
    pose_stream,
    result_notes,
    yaw_quat,
)

SAMPLE_SCHEMA = JsonSchema(
    "ertools.HpffSample",
    (("sample", "integer"), ("measured", "boolean"), ("distance", "number"), ("step", "number")),
)


def content(out: Collected, r: HpffResult, *, limit: int) -> None:
    for topic, (t_ns, xy) in (("/hpff/robot", r.tracks[0]), ("/hpff/person", r.tracks[1])):
        i = every(len(t_ns), limit)
        xyz = np.column_stack([xy[i, 0], xy[i, 1], np.zeros(len(i))])
        pose_stream(out, topic, t_ns[i], xyz, np.tile(yaw_quat(0.0), (len(i), 1)).reshape(-1, 4))
    s = r.samples
    steps = None if r.stats is None else r.stats.steps
    for k in every(len(s.t_ns), limit).tolist():
        out.json(
            "/hpff/samples",
            int(s.t_ns[k]),
            SAMPLE_SCHEMA,
            {
                "sample": k,
                "measured": bool(s.measured[k]),
                "distance": None if not s.measured[k] else float(s.distance[k]),
                "step": None if steps is None else float(steps[k]),
            },
        )
    if len(s.t_ns):
        end = int(s.t_ns[-1])
        if r.duration_s is not None:
            level = INFO if r.passed else ERROR
            log(
                out,
                end,
                level,
                f"duration {r.duration_s:.3f} s: {'passed' if r.passed else 'failed'}",
                r.name,
            )
        log(out, end, INFO, f"score: {r.score}", r.name)
    result_notes(out, r, r.name)
