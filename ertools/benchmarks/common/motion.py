"""Where a tracked body stood still: one detector for every benchmark.

Two steps, both vectorised:

1. :func:`still_mask` marks each sample *still* when the body moved little over a time window
   around it: a speed limit (m/s) or a displacement limit (m) on the position, optionally a
   yaw-rate limit (rad/s, from a yaw track) and a rotation limit (rad, from quaternions).
2. :func:`still_runs` joins consecutive still samples into phases, splits them where the
   samples have a gap longer than ``max_gap_ns`` (nothing is known about the body inside a
   gap), and keeps those lasting at least ``min_duration_ns``. :func:`still_intervals` gives
   them as :class:`~ertools.streams.Interval`.

The callers differ in how they look at the window, so it is a parameter (``kind``):

- ``"centred"``: from the first sample at or after ``t - window/2`` to the last one at or
  before ``t + window/2`` (FBM2 stops: raw 120 Hz mocap over 0.5 s).
- ``"samples"``: ``half`` samples either side, ``half`` from the median sample rate, with the
  positions first smoothed by a moving mean over the same samples (FBM3 phases, noise: blind
  to jitter, cheap on long streams).
- ``"ahead"``: from the sample to the first one at or after ``t + window``; samples with none
  are not still (FBM1 board placements: "has not moved 0.25 s later").

Thresholds are strict (``<``) unless ``inclusive``; a NaN position is never still.
"""

from __future__ import annotations

from typing import Literal

import numpy as np

from ertools.arrays import F64, I64, Bool, median
from ertools.geometry import row_norm, wrap_angle
from ertools.streams import Interval

WindowKind = Literal["centred", "samples", "ahead"]
Run = tuple[int, int]

# Rate assumed by the ``samples`` window when the times do not tell (all equal).
_FALLBACK_RATE_HZ = 100.0


def moving_mean(values: F64, half: int) -> F64:
    """(N, D) centred moving mean over ``2 * half + 1`` samples, shrinking at the ends."""
    n = len(values)
    csum = np.vstack([np.zeros((1, values.shape[1])), np.cumsum(values, axis=0)])
    idx = np.arange(n)
    lo = np.clip(idx - half, 0, n)
    hi = np.clip(idx + half + 1, 0, n)
    return np.asarray((csum[hi] - csum[lo]) / (hi - lo)[:, None], dtype=np.float64)


def sample_half_window(t_ns: I64, window_s: float) -> int:
    """Samples either side of a ``window_s`` window at the median rate (at least 1)."""
    dt = np.diff(t_ns)
    median_dt = float(median(dt)) if len(dt) else 0.0
    rate = 1e9 / median_dt if median_dt > 0 else _FALLBACK_RATE_HZ
    return max(1, round(window_s * rate / 2))


def window_ends(t_ns: I64, window_s: float, kind: WindowKind = "centred") -> tuple[I64, I64, Bool]:
    """(lo, hi, valid): the first and last sample index of each sample's window.

    ``valid`` is False where the window cannot measure a motion (it spans no time, or, for
    ``ahead``, it runs past the last sample).
    """
    t = np.asarray(t_ns, dtype=np.int64)
    n = len(t)
    idx = np.arange(n)
    if kind == "samples":
        half = sample_half_window(t, window_s)
        lo = np.clip(idx - half, 0, n - 1)
        hi = np.clip(idx + half, 0, n - 1)
    elif kind == "centred":
        h = int(window_s * 5e8)
        lo = np.searchsorted(t, t - h, side="left")
        hi = np.clip(np.searchsorted(t, t + h, side="right") - 1, 0, n - 1)
    else:
        ahead = np.searchsorted(t, t + round(window_s * 1e9), side="left")
        lo = idx
        hi = np.minimum(ahead, n - 1)
        # a window cut by the end of the data may hide a motion: not still
        return lo, hi, np.asarray(ahead < n)
    return lo, hi, np.asarray(t[hi] > t[lo])


def rotation_angle(q_a: F64, q_b: F64) -> F64:
    """(N,) angle (rad, in [0, pi]) of the rotation from each ``q_a`` to ``q_b`` (x, y, z, w)."""
    a = q_a / np.linalg.norm(q_a, axis=1, keepdims=True)
    b = q_b / np.linalg.norm(q_b, axis=1, keepdims=True)
    av, aw = a[:, :3], a[:, 3]
    bv, bw = b[:, :3], b[:, 3]
    # conj(a) * b, Hamilton product
    w = aw * bw + np.sum(av * bv, axis=1)
    v = aw[:, None] * bv - bw[:, None] * av - np.cross(av, bv)
    return np.asarray(2.0 * np.arctan2(np.linalg.norm(v, axis=1), np.abs(w)), dtype=np.float64)


def still_mask(
    t_ns: I64,
    pos: F64,
    *,
    window_s: float,
    speed: float | None = None,
    max_move: float | None = None,
    yaw: F64 | None = None,
    yaw_rate: float | None = None,
    quat_xyzw: F64 | None = None,
    max_turn: float | None = None,
    kind: WindowKind = "centred",
    inclusive: bool = False,
) -> Bool:
    """(N,) True where the body stood still over the window around each sample.

    Args:
        t_ns: (N,) sorted sample times.
        pos: (N, D) positions (metres; D = 2 or 3).
        window_s: window length (seconds), read as ``kind`` says (see the module doc).
        speed: limit on the displacement across the window divided by its span (m/s).
        max_move: limit on the displacement across the window (m); give this or ``speed``.
        yaw, yaw_rate: (N,) yaw (rad) and a limit on its wrapped change per second (rad/s), so
            a body turning on the spot is not still.
        quat_xyzw, max_turn: (N, 4) orientations and a limit on the rotation angle across the
            window (rad).
        kind: ``centred``, ``samples`` (positions smoothed first) or ``ahead``.
        inclusive: a value equal to its limit is still (``<=`` instead of ``<``).
    """
    if (speed is None) == (max_move is None):
        raise ValueError("still_mask: give exactly one of speed and max_move")
    t = np.asarray(t_ns, dtype=np.int64)
    n = len(t)
    if n < 2:
        return np.zeros(n, dtype=bool)
    p = np.asarray(pos, dtype=np.float64)
    lo, hi, valid = window_ends(t, window_s, kind)
    if kind == "samples":
        p = moving_mean(p, sample_half_window(t, window_s))
    below = np.less_equal if inclusive else np.less
    span_s = (t[hi] - t[lo]).astype(np.float64) / 1e9
    move = row_norm(p[hi] - p[lo])  # np.linalg.norm(..., axis=1) bit for bit, 4x faster
    still = valid.copy()
    with np.errstate(divide="ignore", invalid="ignore"):
        if speed is not None:
            still &= below(move / span_s, speed)
        elif max_move is not None:
            still &= below(move, max_move)
        if yaw_rate is not None:
            if yaw is None:
                raise ValueError("still_mask: yaw_rate needs yaw")

            y = np.asarray(yaw, dtype=np.float64)
            still &= below(np.abs(wrap_angle(y[hi] - y[lo])) / span_s, yaw_rate)
    if max_turn is not None:
        if quat_xyzw is None:
            raise ValueError("still_mask: max_turn needs quat_xyzw")
        q = np.asarray(quat_xyzw, dtype=np.float64)
        still &= below(rotation_angle(q[lo], q[hi]), max_turn)
    return np.asarray(still, dtype=bool)


def still_runs(
    t_ns: I64,
    still: Bool,
    *,
    min_duration_ns: int = 0,
    max_gap_ns: int | None = None,
    min_samples: int = 1,
    reach: I64 | None = None,
) -> list[Run]:
    """(first, last) sample indices (inclusive) of the still phases, in time order.

    Args:
        t_ns: (N,) sorted sample times.
        still: (N,) from :func:`still_mask` (or any per-sample test).
        min_duration_ns: a phase lasts at least this long (end time minus start time).
        max_gap_ns: two samples further apart than this end one phase and start the next.
        min_samples: a phase holds at least this many samples.
        reach: (N,) index of the last sample each still sample vouches for (``hi`` of an
            ``ahead`` window); a phase's end time is then ``t[reach[last]]``, else ``t[last]``.
    """
    t = np.asarray(t_ns, dtype=np.int64)
    s = np.asarray(still, dtype=bool)
    if len(t) == 0:
        return []
    split = np.zeros(len(t), dtype=bool)  # True: a phase ends after this sample
    if max_gap_ns is not None:
        split[:-1] = np.diff(t) > max_gap_ns
    edges = np.diff(np.concatenate([[0], s.astype(np.int8), [0]]))
    # a still sample starts a phase after a moving sample or after a gap
    starts = np.flatnonzero((edges[:-1] == 1) | (s & np.concatenate([[False], split[:-1]])))
    ends = np.flatnonzero((edges[1:] == -1) | (s & split))
    end_t = t[ends] if reach is None else t[np.asarray(reach)[ends]]
    keep = (end_t - t[starts] >= min_duration_ns) & (ends - starts + 1 >= min_samples)
    return [(int(a), int(b)) for a, b in zip(starts[keep], ends[keep], strict=True)]


def runs_mask(runs: list[Run], n: int) -> Bool:
    """(n,) True for the samples inside the runs."""
    mask = np.zeros(n, dtype=bool)
    for first, last in runs:
        mask[first : last + 1] = True
    return mask


def still_intervals(t_ns: I64, runs: list[Run]) -> list[Interval]:
    """The runs as closed time intervals [t[first], t[last]]."""
    return [Interval(int(t_ns[a]), int(t_ns[b])) for a, b in runs]
