"""The standard error of the clock offset the trajectory intervals draw (issue 28; its
derivation: :func:`offset_spread`, docs/uncertainty.md "Trajectory")."""

from __future__ import annotations

import math

import numpy as np

from ertools.arrays import F64
from ertools.benchmarks.common.clocks import OffsetEstimate
from ertools.timeutil import NS_PER_S

# Poses whose cross-correlation is taken lag by lag; a longer log's in blocks (an hour at
# 10 Hz: 36,000 poses in 7,200 blocks of 5)
MAX_BLOCKS = 8192


def _fast_length(n: int) -> int:
    """The smallest 2^a 3^b 5^c >= n: an FFT length as fast as a power of two, up to 1.6
    times shorter."""
    best = 1 << max(n - 1, 0).bit_length()
    p5 = 1
    while p5 < best:
        p35 = p5
        while p35 < best:
            p = p35
            while p < n:
                p *= 2
            best = min(best, p)
            p35 *= 3
        p5 *= 5
    return best


def offset_spread(
    r_xyz: F64, g_xyz: F64, vel: F64, audit: OffsetEstimate, offset_ns: int
) -> tuple[float, float]:
    """(sd, disagreement) in seconds: the standard error of the clock offset, and how far
    the clock audit's estimate lies from the offset applied.

    The least-squares offset is off by ``sum_i v_i . e_i / sum_i |v_i|^2`` (v the GT
    velocity at robot pose i, e the robot's error there). The poses' errors are not
    independent (a robot's estimate drifts over seconds), and how much a drift moves that sum
    depends on how it lines up with the path's velocity, which turns over a lap. The sd takes
    that from the log itself: the error series slid along the path by every lag h is as
    likely an alignment as the one logged (a stationary error, independent of where the path
    turns), so the variance of the sum is that of the cross-correlation over the lags,
    ``sum_h c(h)^2 / n`` with ``c(h) = sum_i v_i . e_(i+h)`` (e centred; all lags, no
    window: a window keeps the lags over which a lap's drift projection adds up and drops
    those over which it cancels, which is why a Newey-West sum overshoots 1.25 to 4 times).
    For independent errors it is the sandwich standard error. On the simulator
    (``bench/calibration/trajectory.py``: a bias, a 13 s drift and white noise, drawn anew per
    trial) the offset's actual error is 1.11 times it, as it is of the variance the
    simulator's own error model gives (the rest: the GT's stamping delay); the independent
    poses' sandwich error was 1.57 times too small. The clock audit's block bootstrap
    (``clock_audit``) stays the audit's warning threshold. The disagreement is the audit's
    estimate minus the offset applied (0 with ``--offset auto --apply-offset``); the
    intervals are centred on the offset applied whatever it is (they are the score's), and
    the score at the audit's offset gets its own (``*_at_fitted_offset``).
    """
    sv = float(np.sum(np.square(vel)))
    n = len(vel)
    if n < 3 or sv <= 0.0 or audit.offset_ns is None:
        return 0.0, 0.0
    e = r_xyz - g_xyz
    v = vel
    centre = (audit.offset_ns - offset_ns) / NS_PER_S
    if audit.disagrees_with(offset_ns):
        # scored at an offset the data disagrees with (``--offset 0`` on a robot 0.35 s
        # ahead), the errors hold v times that disagreement: the spread is the errors' at
        # the offset the data fits (left in, it made the sd 0.2 s there). Not done
        # otherwise: removing an offset estimated from these same errors would take out the
        # drift's projection whose variance this measures.
        e -= v * centre
    block = -(-n // MAX_BLOCKS)
    if block == 1:
        e -= e.mean(axis=0)
    else:
        # a long log in blocks of consecutive poses: v (turning over seconds) as its block
        # mean, e summed, so the blocks' correlation at lag H is c(block H); the lags in
        # between are as likely alignments, each counted by the block's multiple. Within
        # 1 % of every lag's (blocks of 9 on the hour and on bias + drift + white errors)
        starts = np.arange(0, n, block)
        count = np.diff(np.append(starts, n)).astype(np.float64)
        v = np.add.reduceat(v, starts, axis=0) / count[:, None]
        e = np.add.reduceat(e, starts, axis=0)
        # centred: each block sum less its poses' share of the mean
        e -= count[:, None] * (np.sum(e, axis=0) / n)
    k = len(v)
    # c(h) for every lag at once: zero-padded to a length >= 2k - 1, so the FFT's circular
    # correlation is the linear one; sum_h c(h)^2 = sum_f |C(f)|^2 / m (Parseval)
    m = _fast_length(2 * k - 1)
    cross = np.sum(np.conj(np.fft.rfft(v, m, axis=0)) * np.fft.rfft(e, m, axis=0), axis=1)
    power = np.abs(cross) ** 2
    # rfft keeps f = 0..m/2: every other frequency stands for its conjugate twin too
    total = block * float(power[0] + power[-1] + 2.0 * np.sum(power[1:-1])) / m
    return math.sqrt(total / n) / sv, centre
