"""Epsilon, the mocap noise of a stationary marker set (seed 7.3.13, mocap_noise_statistics):
what ``ertools noise`` reports, and what every benchmark's intervals measure on its own GT.

As the 2015 tool did: the distance in (x, y) between consecutive measurements, binned in
0.15 mm quanta; two consecutive identical poses count as one *lost* sample (Motive repeats the
last pose when it loses the marker set) and stay out of the distribution. ertools adds what the
seed asks for but the tool left to the eye: epsilon = the mean distance between consecutive
measurements that differ, percentiles, and the suggested ``d_min = c * epsilon`` (seed 7.3.2).

``noise_from_stream`` works on a whole recording (the 2015 use: a marker set left still) or,
with ``stationary=True``, only on the stationary phases found in it, so that any benchmark bag
gives an estimate.
"""

from __future__ import annotations

import math
from dataclasses import field, replace
from typing import Any

import numpy as np

from ertools.arrays import F64, I64, Bool
from ertools.benchmarks.base import Rows
from ertools.benchmarks.common.hygiene import (
    identical_poses,
    impossible_samples,
    impossible_warning,
)
from ertools.benchmarks.common.inputs import DEFAULT_BIN, DEFAULT_C
from ertools.benchmarks.common.phases import (
    DEFAULT_MIN_STILL_S,
    DEFAULT_STILL_SPEED,
    phase_pairs,
    stationary_phases,
)
from ertools.benchmarks.results import ResultBase
from ertools.errors import ScoringError
from ertools.fidelity import Deviation
from ertools.frozen_dataclass import frozen_dataclass
from ertools.serialize import jsonable
from ertools.streams import PoseStream, Provenance

PERCENTILES = (50, 95, 99)
# Rows the 2015 tool printed (0 to 7.5 mm); longer tails are folded into one overflow row.
HISTOGRAM_ROWS = 50


@frozen_dataclass(eq=False)
class NoiseResult(ResultBase):
    """Noise statistics; implements :class:`ertools.benchmarks.base.BenchmarkResult`.

    Attributes:
        samples: pose samples considered.
        pairs: consecutive pairs considered (inside phases when ``stationary``).
        lost: pairs with identical poses (tracking lost).
        distances: (M,) distances of the pairs that differ, metres.
        times_ns: (M,) the time of each such pair's second measurement.
        epsilon: mean of ``distances`` (NaN when there are none).
        percentiles: "50"/"95"/"99" -> metres.
        c: the factor of the suggested d_min.
        bin: histogram bin width, metres.
        stationary: whether only stationary phases were used; ``phases`` their (start, end) ns.
        duration_s: time covered by the pairs considered.
    """

    samples: int
    pairs: int
    lost: int
    distances: F64
    epsilon: float
    percentiles: dict[str, float]
    c: float
    bin: float
    stationary: bool = False
    phases: tuple[tuple[int, int], ...] = ()
    duration_s: float = 0.0
    name: str = "noise"
    warnings: tuple[str, ...] = ()
    deviations: tuple[Deviation, ...] = ()
    failures: tuple[str, ...] = ()
    provenance: Provenance = field(default_factory=Provenance)
    times_ns: I64 = field(default_factory=lambda: np.zeros(0, dtype=np.int64))

    @property
    def suggested_d_min(self) -> float:
        """c * epsilon (seed 7.3.2), metres."""
        return self.c * self.epsilon

    def histogram(self) -> tuple[F64, I64, int]:
        """(bin lower edges, counts, overflow count) over ``HISTOGRAM_ROWS`` bins of ``bin``."""
        idx = np.floor(self.distances / self.bin).astype(np.int64)
        counts = np.bincount(idx[idx < HISTOGRAM_ROWS], minlength=HISTOGRAM_ROWS)
        edges = np.arange(HISTOGRAM_ROWS, dtype=np.float64) * self.bin
        return edges, counts.astype(np.int64), int(np.sum(idx >= HISTOGRAM_ROWS))

    def listing(self) -> dict[Any, Any]:
        """The JSON keys of the issue: samples, lost, epsilon, percentiles, suggested_d_min."""
        return {
            "samples": self.samples,
            "lost": self.lost,
            "epsilon": _finite(self.epsilon),
            "percentiles": {k: _finite(v) for k, v in self.percentiles.items()},
            "suggested_d_min": _finite(self.suggested_d_min),
        }

    def tables(self) -> dict[str, Rows]:
        edges, counts, overflow = self.histogram()
        rows: Rows = [
            {"from_m": float(e), "to_m": float(e + self.bin), "count": int(c)}
            for e, c in zip(edges, counts, strict=True)
        ]
        rows.append({"from_m": float(HISTOGRAM_ROWS * self.bin), "to_m": None, "count": overflow})
        summary = jsonable(self.to_dict())
        pct = summary.pop("percentiles")
        summary |= {f"p{k}": v for k, v in pct.items()} | {"pairs": self.pairs}
        return {"histogram": rows, "summary": [summary]}

    def to_text(self, width: int = 60) -> str:
        """A summary and a text histogram (the 2015 tool printed one on the terminal)."""
        mm = 1000.0
        scope = (
            f"{len(self.phases)} stationary phase(s), {self.duration_s:.1f} s"
            if self.stationary
            else f"{self.duration_s:.1f} s, whole recording taken as stationary"
        )
        lines = [
            f"samples: {self.samples} ({scope})",
            f"consecutive pairs: {self.pairs}, lost (identical poses): {self.lost}",
        ]
        if self.distances.size == 0:
            lines.append("no pair of consecutive measurements differs: epsilon is undefined")
            return "\n".join(lines) + "\n"
        pct = ", ".join(f"p{k} {v * mm:.3f}" for k, v in self.percentiles.items())
        lines += [
            f"epsilon (mean distance between differing measurements): {self.epsilon * mm:.4f} mm",
            f"percentiles: {pct} mm",
            f"suggested d_min = {self.c:g} * epsilon = {self.suggested_d_min * mm:.4f} mm"
            f" ({self.suggested_d_min:.6f} m)",
            "",
            f"distance between consecutive measurements (bins of {self.bin * mm:.3f} mm):",
        ]
        edges, counts, overflow = self.histogram()
        total = self.pairs if self.pairs else 1
        peak = max(int(counts.max()), overflow, self.lost, 1)
        last = int(np.max(np.flatnonzero(counts))) if counts.any() else 0

        def bar(count: int) -> str:
            return "#" * math.ceil(width * count / peak) if count else ""

        lines.append(
            f"{'lost':>9} | {bar(self.lost):<{width}} {self.lost} ({self.lost / total:.1%})"
        )
        for e, c in zip(edges[: last + 1], counts[: last + 1], strict=True):
            lines.append(f"{e * mm:>6.2f} mm | {bar(int(c)):<{width}} {c} ({c / total:.1%})")
        if overflow:
            top = HISTOGRAM_ROWS * self.bin * mm
            lines.append(f">={top:>4.1f} mm | {bar(overflow):<{width}} {overflow}")
        return "\n".join(lines) + "\n"


def _finite(value: float) -> float | None:
    return float(value) if math.isfinite(value) else None


def noise_statistics(
    t_ns: I64,
    xy: F64,
    *,
    pair_mask: Bool | None = None,
    identical: Bool | None = None,
    bin: float = DEFAULT_BIN,
    c: float = DEFAULT_C,
    stationary: bool = False,
    phases: tuple[tuple[int, int], ...] = (),
) -> NoiseResult:
    """Noise statistics of positions ``xy`` (N, 2) sampled at ``t_ns``.

    Args:
        pair_mask: (N-1,) which consecutive pairs to use (default all).
        identical: (N-1,) which pairs are identical poses (default: equal x and y).
        bin: histogram bin, metres; c: suggested d_min factor.

    Raises:
        ScoringError: fewer than 2 samples or no usable pair.
    """
    if not bin > 0 or not math.isfinite(bin):
        raise ScoringError(f"--bin must be a positive number of metres, got {bin}")
    if not c > 0 or not math.isfinite(c):
        raise ScoringError(f"--c must be a positive number, got {c}")
    pts = np.asarray(xy, dtype=np.float64)
    n = len(pts)
    if n < 2:
        raise ScoringError(f"{n} pose sample(s): at least 2 are needed for noise statistics")
    step = np.hypot(*np.diff(pts, axis=0).T)
    same = (step == 0.0) if identical is None else np.asarray(identical, dtype=bool)
    use = np.ones(n - 1, dtype=bool) if pair_mask is None else np.asarray(pair_mask, dtype=bool)
    use = use & np.isfinite(step)  # a NaN pose (no measurement) says nothing about the noise
    if not use.any():
        raise ScoringError("no stationary phase found: nothing to measure the noise on")
    lost = int(np.sum(use & same))
    distances = step[use & ~same]
    times = np.asarray(t_ns, dtype=np.int64)[1:][use & ~same]
    eps = float(distances.mean()) if distances.size else math.nan
    values = np.percentile(distances, PERCENTILES) if distances.size else [math.nan] * 3
    pct = {str(p): float(v) for p, v in zip(PERCENTILES, values, strict=True)}
    dt = np.diff(np.asarray(t_ns, dtype=np.int64))
    duration = float(np.sum(dt[use])) / 1e9
    samples = int(np.sum(np.concatenate([[False], use]) | np.concatenate([use, [False]])))
    return NoiseResult(
        samples=samples,
        pairs=int(use.sum()),
        lost=lost,
        distances=distances,
        epsilon=eps,
        percentiles=pct,
        c=c,
        bin=bin,
        stationary=stationary,
        phases=phases,
        duration_s=duration,
        times_ns=times,
    )


def noise_from_stream(
    poses: PoseStream,
    *,
    stationary: bool = False,
    bin: float = DEFAULT_BIN,
    c: float = DEFAULT_C,
    still_speed: float | None = None,
    min_still_s: float | None = None,
) -> NoiseResult:
    """Noise statistics of a pose stream, optionally restricted to its stationary phases.

    Raises:
        ScoringError: every pose is NaN (named with the stream's source), or as
            :func:`noise_statistics`.
    """
    impossible = impossible_samples(poses.t_ns, poses.xyz)
    said = impossible_warning(poses) if impossible.count else None
    if impossible.count:
        # no measurement: left out as a frame the mocap never sent (a gap of one frame)
        poses = poses.take(~(impossible.far | impossible.jump))
    xy = poses.xyz[:, :2]
    # (bounded: every position was shown finite already)
    if len(poses) and not impossible.bounded and not np.isfinite(xy).all(axis=1).any():
        # Said here, where the file and topic are known: noise_statistics would only find
        # "no usable pair" without saying why.
        where = poses.source or "the pose stream"
        raise ScoringError(
            f"{where}: all {len(poses)} poses are NaN (the mocap logged no measurement): "
            "nothing to measure the noise on; check the marker set was tracked, or give --topic"
        )
    mask = None
    spans: tuple[tuple[int, int], ...] = ()
    if stationary:
        phases = stationary_phases(
            poses.t_ns,
            xy,
            speed=DEFAULT_STILL_SPEED if still_speed is None else still_speed,
            min_duration_s=DEFAULT_MIN_STILL_S if min_still_s is None else min_still_s,
        )
        mask = phase_pairs(phases, len(poses))
        spans = tuple((p.start_ns, p.end_ns) for p in phases)
    result = noise_statistics(
        poses.t_ns,
        xy,
        pair_mask=mask,
        identical=identical_poses(poses),
        bin=bin,
        c=c,
        stationary=stationary,
        phases=spans,
    )
    warnings: list[str] = [said] if said else []
    if result.distances.size == 0:
        warnings.append("no two consecutive measurements differ: epsilon is undefined")
    elif not stationary:
        still = stationary_phases(poses.t_ns, xy)
        covered = sum(p.last - p.first for p in still) / max(len(poses) - 1, 1)
        if covered < 0.9:
            warnings.append(
                f"the marker set moved during {1 - covered:.0%} of the recording (speed above "
                f"{DEFAULT_STILL_SPEED * 1000:g} mm/s): the statistics include motion; use "
                "--stationary auto to keep only the still phases"
            )
    return replace(
        result,
        warnings=tuple(warnings),
        provenance=Provenance(
            inputs=(poses.source,),
            parameters=(("bin", repr(bin)), ("c", repr(c)), ("stationary", repr(stationary))),
        ),
    )
