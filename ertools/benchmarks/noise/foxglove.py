"""Foxglove content of a noise result:

- ``/noise/distances``: JSON per differing pair of consecutive measurements (thinned): the
  distance in the plane, at the second measurement's time (a plot of the noise over time);
- ``/ertools/log``: epsilon, the percentiles and the suggested d_min, and the notes.
"""

from __future__ import annotations

from ertools.benchmarks.common.epsilon import NoiseResult
from ertools.views.foxglove import INFO, Collected, JsonSchema, every, log, result_notes

DISTANCE_SCHEMA = JsonSchema("ertools.NoisePair", (("pair", "integer"), ("distance", "number")))


def content(out: Collected, r: NoiseResult, *, limit: int) -> None:
    for k in every(len(r.times_ns), limit).tolist():
        data = {"pair": k, "distance": float(r.distances[k])}
        out.json("/noise/distances", int(r.times_ns[k]), DISTANCE_SCHEMA, data)
    if len(r.times_ns):
        mm = 1000.0
        p95 = r.percentiles["95"] * mm
        text = (
            f"epsilon {r.epsilon * mm:.4f} mm, p95 {p95:.4f} mm, suggested d_min "
            f"{r.suggested_d_min * mm:.4f} mm ({r.c:g} epsilon), {r.lost} lost"
        )
        log(out, int(r.times_ns[-1]), INFO, text, r.name)
    result_notes(out, r, r.name)
