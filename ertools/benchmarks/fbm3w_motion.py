"""Stationary and moving phases of a tracked point, from positions alone.

Used to find FBM3@Work runs in bags without state topics (``--runs auto``) and to measure the
mocap noise where the marker set stood still (``ertools noise --stationary auto`` and the d_min
warning of ``ertools score fbm3w``).

A sample is *still* when the speed of the smoothed position is below ``speed`` (default
4 mm/s); a stationary phase is a stretch of still samples lasting at least ``min_duration``
(default 0.5 s). Smoothing over ``window`` (0.2 s) first makes the test blind to mocap jitter:
0.1 mm of noise per sample at 120 Hz moves a 0.2 s average by ~0.03 mm, i.e. ~0.2 mm/s, far
below the threshold, while an end effector following a path moves at centimetres per second.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

F64 = npt.NDArray[np.float64]
I64 = npt.NDArray[np.int64]
Bool = npt.NDArray[np.bool_]

DEFAULT_STILL_SPEED = 0.004  # m/s
DEFAULT_MIN_STILL_S = 0.5
DEFAULT_WINDOW_S = 0.2
# A gap in the data longer than this ends a stationary phase (nothing is known inside it).
MAX_GAP_S = 0.5


@dataclass(frozen=True)
class Phase:
    """Samples ``first..last`` (inclusive indices) and their times."""

    first: int
    last: int
    start_ns: int
    end_ns: int

    @property
    def duration_s(self) -> float:
        return (self.end_ns - self.start_ns) / 1e9


def _moving_mean(xy: F64, half: int) -> F64:
    """Centred moving mean over 2*half+1 samples (shrinking at the ends)."""
    n = len(xy)
    csum = np.vstack([np.zeros((1, xy.shape[1])), np.cumsum(xy, axis=0)])
    idx = np.arange(n)
    lo = np.clip(idx - half, 0, n)
    hi = np.clip(idx + half + 1, 0, n)
    return np.asarray((csum[hi] - csum[lo]) / (hi - lo)[:, None], dtype=np.float64)


def still_mask(
    t_ns: I64, xy: F64, *, speed: float = DEFAULT_STILL_SPEED, window_s: float = DEFAULT_WINDOW_S
) -> Bool:
    """(N,) True where the smoothed speed is below ``speed`` (m/s)."""
    n = len(t_ns)
    if n < 3:
        return np.zeros(n, dtype=bool)
    dt = np.diff(t_ns)
    median_dt = float(np.median(dt)) if len(dt) else 0.0
    rate = 1e9 / median_dt if median_dt > 0 else 100.0
    half = max(1, round(window_s * rate / 2))
    smooth = _moving_mean(np.asarray(xy, dtype=np.float64), half)
    idx = np.arange(n)
    lo = np.clip(idx - half, 0, n - 1)
    hi = np.clip(idx + half, 0, n - 1)
    span_s = (t_ns[hi] - t_ns[lo]) / 1e9
    disp = np.hypot(*(smooth[hi] - smooth[lo]).T)
    with np.errstate(divide="ignore", invalid="ignore"):
        v = np.where(span_s > 0, disp / span_s, np.inf)
    return np.asarray(v < speed)


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
    if len(t) > 1:
        # a long gap breaks a phase: the sample after the gap starts a new one
        gap = np.concatenate([[False], np.diff(t) > MAX_GAP_S * 1e9])
    else:
        gap = np.zeros(len(t), dtype=bool)
    phases: list[Phase] = []
    edges = np.diff(np.concatenate([[0], still.astype(np.int8), [0]]))
    starts = np.flatnonzero(edges == 1)
    ends = np.flatnonzero(edges == -1) - 1
    for a, b in zip(starts.tolist(), ends.tolist(), strict=True):
        # split at gaps inside the still stretch
        cuts = [a, *(int(i) for i in np.flatnonzero(gap[a + 1 : b + 1]) + a + 1), b + 1]
        for lo, hi in itertools.pairwise(cuts):
            first, last = lo, hi - 1
            if last > first and (t[last] - t[first]) >= min_duration_s * 1e9:
                phases.append(Phase(first, last, int(t[first]), int(t[last])))
    return phases


def phase_pairs(phases: list[Phase], n: int) -> Bool:
    """(n-1,) True for consecutive sample pairs (i, i+1) that lie inside one phase."""
    mask = np.zeros(max(n - 1, 0), dtype=bool)
    for p in phases:
        mask[p.first : p.last] = True
    return mask
