"""The protocol's still phases of FBM3@Work's ``--runs auto``, robust to real mocap.

On real logs (0.3-1.3 mm of jitter per frame, dropouts, robots slower than 1 cm/s) the fixed
0.2 s window of :func:`ertools.benchmarks.common.phases.stationary_phases` sees the jitter as
motion. :func:`protocol_track` sizes its window to the noise measured in the log, uses
hysteresis, and places the edges of each move between still phases.
"""

from __future__ import annotations

import math

import numpy as np

from ertools.arrays import F64, I64, median
from ertools.benchmarks.common import motion
from ertools.benchmarks.common.phases import (
    DEFAULT_MIN_STILL_S,
    DEFAULT_STILL_SPEED,
    MAX_GAP_S,
    Phase,
)
from ertools.frozen_dataclass import frozen_dataclass

# A real FBM3 log has 0.3-1.3 mm of jitter from frame to frame at 120 Hz, tracking dropouts of
# a few hundred ms and robots that follow a 10 cm path at well under 1 cm/s. A 0.2 s window
# (stationary_phases') then sees the jitter as 2-6 mm/s of "speed" and chops a still phase
# into pieces. Here the speed is the displacement between the mean positions of the two halves
# of a time window whose length grows with the noise measured in the log, and still phases use
# hysteresis: a stretch below ``speed`` counts when it reaches ``speed / 2`` somewhere.

# Window half-length bounds (s) and the speed noise (fraction of the still speed) it aims at.
_MIN_HALF_S = 0.1
_MAX_HALF_S = 0.6
_SPEED_NOISE_FRACTION = 1 / 6
# A half window needs this fraction of its expected samples (a dropout leaves fewer).
_MIN_FILL = 0.25
# Smoothing (half-length, s) of the positions used to place the edges of a move.
EDGE_SMOOTH_S = 0.15
# A move is under way once the smoothed position is this many noise sigmas (and at least
# _EDGE_FLOOR_M) from the still position; its edge is where it was last within that.
_EDGE_SIGMAS = 4.0
_EDGE_FLOOR_M = 0.0005
# Longest extrapolation of an edge (ns).
_MAX_LEAD_NS = 100_000_000
# Two still phases less than this apart (and the path between them never further) are one:
# the protocol's moves are centimetres, a glitch is not (a tracking loss that repeats one
# noisy pose for 300 ms looks like a few mm/s of speed to the window). At least this many
# noise sigmas: a smoothed position wanders up to ~4 of its (smaller) sigmas, a single
# repeated pose ~4 sigmas.
MIN_MOVE_M = 0.002
_MIN_MOVE_SIGMAS = 6.0
# ... when they are at most this far apart in time (a longer gap may hide a whole run).
_JOIN_WITHIN_S = 2.0


@frozen_dataclass
class Track:
    """A position track cut into the protocol's still phases and the moves between them.

    Attributes:
        phases: still phases in time order.
        sigma: mocap noise (m, per axis) measured from second differences.
        half_s: half-length of the speed window used (s).
        rate_hz: median sample rate.
        onsets, arrivals: per move i (between phases i and i+1), the sample index where the
            robot left phase i and where it reached phase i+1.
        still_xy: (P, 2) mean position of each phase.
        onset_ns, arrival_ns: per move, when the robot set off and stopped (the edge samples
            extrapolated back and forward, see :func:`protocol_track`).
    """

    phases: tuple[Phase, ...]
    sigma: float
    half_s: float
    rate_hz: float
    onsets: tuple[int, ...]
    arrivals: tuple[int, ...]
    still_xy: F64
    onset_ns: tuple[int, ...]
    arrival_ns: tuple[int, ...]


def noise_sigma(t_ns: I64, xy: F64) -> float:
    """Per-axis white-noise sigma (m) from second differences of evenly spaced samples.

    ``x[i+1] - 2 x[i] + x[i-1]`` removes a smooth motion and keeps 6 sigma^2 of white noise;
    the median absolute value (robust to motion, glitches and frozen frames) / 0.6745 gives
    its sigma. Triples around a dropout (uneven spacing) and repeated frames are left out.
    """
    t = np.asarray(t_ns, dtype=np.int64)
    p = np.asarray(xy, dtype=np.float64)
    if len(t) < 3:
        return 0.0
    dt = np.diff(t)
    med = float(median(dt))
    even = (np.abs(dt[1:] - med) <= 0.25 * med) & (np.abs(dt[:-1] - med) <= 0.25 * med)
    step = np.diff(p, axis=0)
    moved = np.any(step != 0.0, axis=1)
    ok = even & moved[1:] & moved[:-1] & np.all(np.isfinite(p[1:-1]), axis=1)
    d2 = (p[2:] - 2.0 * p[1:-1] + p[:-2])[ok]
    if len(d2) == 0:
        return 0.0
    return float(median(np.abs(d2)) / 0.6745 / math.sqrt(6.0))


def _half_window(sigma: float, rate_hz: float, speed: float) -> float:
    """Half-length (s) whose speed noise is about ``speed / 6`` for this noise and rate.

    The difference of two h-long means of white noise has sigma * sqrt(2 / (rate h)); over a
    distance in time of h it is a speed noise of sigma * sqrt(2 / rate) * h^-1.5 per axis.
    """
    target = speed * _SPEED_NOISE_FRACTION
    if sigma <= 0 or target <= 0:
        return _MIN_HALF_S
    h = float((sigma * math.sqrt(2.0 / rate_hz) / target) ** (2.0 / 3.0))
    return min(max(h, _MIN_HALF_S), _MAX_HALF_S)


def window_speed(t_ns: I64, xy: F64, half_s: float, rate_hz: float) -> F64:
    """(N,) speed (m/s) between the mean positions of [t - h, t) and [t, t + h]; NaN when a
    half holds too few samples (a dropout) or a position is NaN."""
    t = np.asarray(t_ns, dtype=np.int64)
    n = len(t)
    h = round(half_s * 1e9)
    ts = (t - t[0]).astype(np.float64) / 1e9
    p = np.asarray(xy, dtype=np.float64)
    finite = np.all(np.isfinite(p), axis=1)
    p = np.where(finite[:, None], p, 0.0)
    cs = np.vstack([np.zeros((1, 2)), np.cumsum(p, axis=0)])
    ct = np.concatenate([[0.0], np.cumsum(ts)])
    cf = np.concatenate([[0], np.cumsum(~finite)])
    idx = np.arange(n)
    lo = np.searchsorted(t, t - h, side="left")
    hi = np.searchsorted(t, t + h, side="right")
    n_left = idx - lo
    n_right = hi - idx
    need = max(2, round(_MIN_FILL * half_s * rate_hz))
    ok = (n_left >= need) & (n_right >= need) & (cf[hi] - cf[lo] == 0)
    with np.errstate(divide="ignore", invalid="ignore"):
        m_left = (cs[idx] - cs[lo]) / n_left[:, None]
        m_right = (cs[hi] - cs[idx]) / n_right[:, None]
        t_left = (ct[idx] - ct[lo]) / n_left
        t_right = (ct[hi] - ct[idx]) / n_right
        speed = np.linalg.norm(m_right - m_left, axis=1) / (t_right - t_left)
    return np.where(ok, speed, np.nan)


def protocol_track(
    t_ns: I64,
    xy: F64,
    *,
    speed: float = DEFAULT_STILL_SPEED,
    min_duration_s: float = DEFAULT_MIN_STILL_S,
) -> Track:
    """Still phases (hysteresis on a noise-sized window) and the edges of the moves between.

    A sample belongs to a still phase when it lies in a stretch of window speeds below
    ``speed`` (or unknown, inside a dropout) that somewhere drops below ``speed / 2`` and lasts
    ``min_duration_s``; a data gap over :data:`MAX_GAP_S` ends a stretch. Neighbouring phases
    closer than max(:data:`MIN_MOVE_M`, 6 sigma) (with nothing further between) are joined.
    Each move's edges are placed on positions smoothed over ±:data:`EDGE_SMOOTH_S`: the last
    sample within 4 sigmas of that smoothing (at least 0.5 mm) of the still position before
    the robot goes as far as a move must, extrapolated by the time it then took to double
    that distance (at most 0.1 s); the arrival likewise.
    """
    t = np.asarray(t_ns, dtype=np.int64)
    p = np.asarray(xy, dtype=np.float64)
    n = len(t)
    dt = np.diff(t)
    rate = 1e9 / float(median(dt)) if n > 1 and median(dt) > 0 else 120.0
    sigma = noise_sigma(t, p)
    half = _half_window(sigma, rate, speed)
    empty = np.empty((0, 2))
    if n < 3:
        return Track((), sigma, half, rate, (), (), empty, (), ())
    v = window_speed(t, p, half, rate)
    below = ~(v >= speed)  # NaN (unknown) continues a stretch
    gap = np.zeros(n, dtype=bool)
    gap[1:] = dt > MAX_GAP_S * 1e9
    # stretch ids: a new stretch at each change of `below` and after each gap
    change = np.ones(n, dtype=bool)
    change[1:] = (below[1:] != below[:-1]) | gap[1:]
    ids = np.cumsum(change) - 1
    firsts = np.flatnonzero(change)
    lasts = np.concatenate([firsts[1:] - 1, [n - 1]])
    deep = np.zeros(len(firsts), dtype=bool)
    np.logical_or.at(deep, ids, v < speed / 2)
    keep = below[firsts] & deep & (t[lasts] - t[firsts] >= math.ceil(min_duration_s * 1e9))
    runs = [(int(a), int(b)) for a, b in zip(firsts[keep], lasts[keep], strict=True)]
    smooth = motion.moving_mean(p, max(1, round(EDGE_SMOOTH_S * rate)))
    min_move = max(MIN_MOVE_M, _MIN_MOVE_SIGMAS * sigma)
    runs = _join_small_moves(runs, p, smooth, t, min_move)
    still_xy = np.array([np.nanmean(p[a : b + 1], axis=0) for a, b in runs]) if runs else empty
    # noise of a smoothed position (per axis) sets the edge radius
    n_smooth = 2 * max(1, round(EDGE_SMOOTH_S * rate)) + 1
    radius = max(_EDGE_FLOOR_M, _EDGE_SIGMAS * sigma * math.sqrt(2.0 / n_smooth))
    onsets: list[int] = []
    arrivals: list[int] = []
    onset_ns: list[int] = []
    arrival_ns: list[int] = []
    for i in range(len(runs) - 1):
        (a0, b0), (a1, b1) = runs[i], runs[i + 1]
        mid0, mid1 = (a0 + b0) // 2, (a1 + b1) // 2
        seg = smooth[mid0 : mid1 + 1]
        d0 = np.hypot(*(seg - still_xy[i]).T)
        d1 = np.hypot(*(seg - still_xy[i + 1]).T)
        near0 = np.flatnonzero(d0 <= radius)
        near1 = np.flatnonzero(d1 <= radius)
        # "away" is as far as a move must go: a glitch inside a (joined) phase is not
        far0 = np.flatnonzero(d0 > max(2 * radius, min_move))
        first_far = int(far0[0]) if far0.size else len(seg) - 1
        before = near0[near0 < first_far]
        onset = mid0 + (int(before[-1]) if before.size else 0)
        far1 = np.flatnonzero(d1 > max(2 * radius, min_move))
        last_far = int(far1[-1]) if far1.size else 0
        after = near1[near1 > last_far]
        arrival = max(mid0 + (int(after[0]) if after.size else len(seg) - 1), onset)
        onsets.append(onset)
        arrivals.append(arrival)
        # the robot set off before it was `radius` away: back by the time it took from
        # radius to 2 radius (exact at constant speed, short while it accelerates)
        out0 = np.flatnonzero(d0[onset - mid0 :] > 2 * radius)
        out1 = np.flatnonzero(d1[: arrival - mid0 + 1] > 2 * radius)
        lead = int(t[onset + int(out0[0])]) - int(t[onset]) if out0.size else 0
        lag = int(t[arrival]) - int(t[mid0 + int(out1[-1])]) if out1.size else 0
        onset_ns.append(int(t[onset]) - min(max(lead, 0), _MAX_LEAD_NS))
        arrival_ns.append(int(t[arrival]) + min(max(lag, 0), _MAX_LEAD_NS))
    phases = tuple(Phase(a, b, int(t[a]), int(t[b])) for a, b in runs)
    return Track(
        phases,
        sigma,
        half,
        rate,
        tuple(onsets),
        tuple(arrivals),
        still_xy,
        tuple(onset_ns),
        tuple(arrival_ns),
    )


def _join_small_moves(
    runs: list[tuple[int, int]], p: F64, smooth: F64, t: I64, min_move: float
) -> list[tuple[int, int]]:
    """Join neighbouring phases when the body never went ``min_move`` from the first
    (a glitch or a wobble of the noise window, not one of the protocol's moves)."""
    out: list[tuple[int, int]] = []
    for a, b in runs:
        if out:
            a0, b0 = out[-1]
            if t[a] - t[b0] <= _JOIN_WITHIN_S * 1e9:
                centre = np.nanmean(p[a0 : b0 + 1], axis=0)
                between = smooth[b0 : a + 1]
                far = np.nanmax(np.hypot(*(between - centre).T)) if len(between) else 0.0
                end = np.nanmean(p[a : b + 1], axis=0)
                if far < min_move and float(np.hypot(*(end - centre))) < min_move:
                    out[-1] = (a0, b)
                    continue
        out.append((a, b))
    return out
