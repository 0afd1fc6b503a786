"""Stationary and moving phases of a tracked point, from positions alone.

Used to find FBM3@Work runs in bags without state topics (``--runs auto``) and to measure the
mocap noise where the marker set stood still (``ertools noise --stationary auto`` and the d_min
warning of ``ertools score fbm3w``).

A sample is *still* when the speed of the smoothed position is below ``speed`` (default
4 mm/s); a stationary phase is a stretch of still samples lasting at least ``min_duration``
(default 0.5 s). Smoothing over ``window`` (0.2 s) first makes the test blind to mocap jitter:
0.1 mm of noise per sample at 120 Hz moves a 0.2 s average by ~0.03 mm, i.e. ~0.2 mm/s, far
below the threshold, while an end effector following a path moves at centimetres per second.
The detection itself is :mod:`ertools.benchmarks.common.motion` (its ``samples`` window);
this module keeps the FBM3 defaults and the :class:`Phase` records.

``--runs auto`` uses :func:`ertools.benchmarks.fbm3w.track.protocol_track` instead, on these
:class:`Phase` records and :data:`MAX_GAP_S`.
"""

from __future__ import annotations

import math

import numpy as np

from ertools.arrays import F64, I64, Bool
from ertools.benchmarks.common import motion
from ertools.frozen_dataclass import frozen_dataclass

DEFAULT_STILL_SPEED = 0.004  # m/s
DEFAULT_MIN_STILL_S = 0.5
DEFAULT_WINDOW_S = 0.2
# A gap in the data longer than this ends a stationary phase (nothing is known inside it).
MAX_GAP_S = 0.5


@frozen_dataclass
class Phase:
    """Samples ``first..last`` (inclusive indices) and their times."""

    first: int
    last: int
    start_ns: int
    end_ns: int

    @property
    def duration_s(self) -> float:
        return (self.end_ns - self.start_ns) / 1e9


def still_mask(
    t_ns: I64, xy: F64, *, speed: float = DEFAULT_STILL_SPEED, window_s: float = DEFAULT_WINDOW_S
) -> Bool:
    """(N,) True where the smoothed speed is below ``speed`` (m/s)."""
    if len(t_ns) < 3:
        return np.zeros(len(t_ns), dtype=bool)
    return motion.still_mask(t_ns, xy, window_s=window_s, speed=speed, kind="samples")


def stationary_phases(
    t_ns: I64,
    xy: F64,
    *,
    speed: float = DEFAULT_STILL_SPEED,
    min_duration_s: float = DEFAULT_MIN_STILL_S,
    window_s: float = DEFAULT_WINDOW_S,
) -> list[Phase]:
    """The stationary phases of a position track, in time order."""
    t = np.asarray(t_ns, dtype=np.int64)
    still = still_mask(t, xy, speed=speed, window_s=window_s)
    # float thresholds on integer times: ">= x" is ">= ceil(x)", "> x" is "> floor(x)"
    runs = motion.still_runs(
        t,
        still,
        min_duration_ns=math.ceil(min_duration_s * 1e9),
        max_gap_ns=math.floor(MAX_GAP_S * 1e9),
        min_samples=2,
    )
    return [Phase(a, b, int(t[a]), int(t[b])) for a, b in runs]


def phase_pairs(phases: list[Phase], n: int) -> Bool:
    """(n-1,) True for consecutive sample pairs (i, i+1) that lie inside one phase."""
    mask = np.zeros(max(n - 1, 0), dtype=bool)
    for p in phases:
        mask[p.first : p.last] = True
    return mask
