"""Monte Carlo draws the intervals share (issue 39): the order statistics of perturbed
distances drawn on only the values that can move them.

Pure NumPy; every draw in float32 where the precision suffices (said at each function), in
operations that give the same bits on every CPU (NumPy's float additions, products and square
roots; not its complex products or absolute values, whose SIMD code differs in the last bit).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from ertools.arrays import F64, IntArr, distinct
from ertools.frozen_dataclass import frozen_dataclass

CHUNK_ELEMENTS = 4_000_000  # draws x values per chunk of the order statistics' draws


@frozen_dataclass(eq=False)
class Distances:
    """The values whose order statistics are drawn: errors e (n, 3) between two ends, the
    noise of one end (sigma per axis, (n,)), its velocity (n, 3) and frame period (n,) for
    a lag; ``distance``, |e| (n,), when the caller has it (None: computed here)."""

    error: F64
    sigma: F64
    velocity: F64
    period: F64
    distance: F64 | None = None


# Noise of more than this many sigma (chi with 3 degrees of freedom: P = 1e-10) is taken as
# never drawn when choosing the poses that can move an order statistic.
BAND_SIGMAS = 7.0


def order_band(values: F64, bound: F64, ranks: IntArr) -> tuple[IntArr, IntArr]:
    """The poses whose perturbation can move the order statistics of ``ranks`` (0-based
    ranks of ``values``' ascending order), and those ranks among them.

    Each value moves by at most its ``bound`` in any draw, so an order statistic moves by at
    most B = max(bound). A value whose upper bound stays below the lowest rank's statistic
    minus B is below every wanted statistic in every draw: it only shifts the ranks by one.
    One whose lower bound stays above the highest rank's statistic plus B never reaches
    them. Returns (indices of the other values, ``ranks`` minus the count of values always
    below).
    """
    v = np.asarray(values, dtype=np.float64)
    b = np.asarray(bound, dtype=np.float64)
    order = np.sort(v)
    reach = float(np.max(b)) if b.size else 0.0
    lo = order[int(np.min(ranks))] - reach
    hi = order[int(np.max(ranks))] + reach
    below = v + b < lo
    keep = np.flatnonzero(~below & (v - b <= hi))
    return keep, np.asarray(ranks, dtype=np.intp) - int(np.count_nonzero(below))


def percentile_rows(values: F64, count: IntArr, percent: float) -> F64:
    """Each row's percentile (NumPy's linear method) of its first ``count`` values, the
    rows sorted ascending."""
    rows = np.arange(len(values))
    h = np.maximum(count - 1, 0) * (percent / 100.0)
    lo = np.floor(h).astype(np.intp)
    hi = np.minimum(lo + 1, np.maximum(count - 1, 0))
    a, b = values[rows, lo], values[rows, hi]
    return np.asarray(a + (h - lo) * (b - a), dtype=np.float64)


@frozen_dataclass
class OrderStat:
    """One order statistic to draw: its columns (in the caller's scores: one statistic may
    be two, the median and p50), the values that can move it (indices) and its ranks among
    them, interpolated by ``fraction`` (NumPy's linear percentile)."""

    columns: tuple[int, ...]
    poses: IntArr
    low: int
    high: int
    fraction: float


def order_stats(
    d: F64, thinned: IntArr, bounds: F64, wanted: Sequence[tuple[int, float]]
) -> tuple[list[OrderStat], F64]:
    """The order statistics ``wanted`` ((column, percent) pairs) to draw from the values
    ``d`` that move by at most ``bounds`` (the max, percent 100, over all values; the
    percentiles over the ``thinned`` ones) and their unperturbed values."""
    out: list[OrderStat] = []
    base = []
    percents = sorted({p for _, p in wanted})
    for percent in percents:
        columns = tuple(c for c, p in wanted if p == percent)
        if percent == 100.0:
            # the max: the values that can reach it, as order_band keeps them, unsorted
            top = float(np.max(d))
            reach = float(np.max(bounds))
            keep = np.flatnonzero(d + bounds >= top - reach)
            out.append(OrderStat(columns, keep, len(keep) - 1, len(keep) - 1, 0.0))
            base.append(top)
            continue
        pool = thinned
        values = d[pool]
        n = len(values)
        h = (n - 1) * percent / 100.0
        lo = math.floor(h)
        hi = min(lo + 1, n - 1)
        frac = h - lo
        ranked = np.sort(values)
        base.append(ranked[lo] + frac * (ranked[hi] - ranked[lo]))
        keep, ranks = order_band(values, bounds[pool], np.array([lo, hi]))
        out.append(OrderStat(columns, pool[keep], int(ranks[0]), int(ranks[1]), frac))
    return out, np.asarray(base, dtype=np.float64)


def draw_order_stats(
    stats: list[OrderStat],
    terms: Distances,
    rng: np.random.Generator,
    draws: int,
    *,
    noise: bool,
    lag: tuple[float, float] | None,
) -> F64:
    """(draws, len(stats)) values of the order statistics with the values that can move
    them perturbed (``noise``: by each one's sigma per axis; ``lag``: uniform over (low,
    high) periods along its velocity), in float32: an error of at most metres resolved to a
    tenth of a micrometre, against noise of tenths of a millimetre, and additions, products
    and square roots give the same bits on every CPU.

    A perturbed distance is drawn from two numbers, not three: with the noise s z split
    along the error e (s r, r standard normal) and across it (its squared length s^2
    |z_perp|^2, chi-square with 2 degrees of freedom: 2 s^2 E, E standard exponential),
    |e + s z|^2 = (|e| + s r)^2 + 2 s^2 E, the same distribution. A lag l moves the other end
    by l v: |e - l v|^2 = |e|^2 - 2 l e.v + l^2 |v|^2.
    """
    union = distinct(np.concatenate([s.poses for s in stats]))
    cols = [np.searchsorted(union, s.poses) for s in stats]
    e, v = terms.error[union], terms.velocity[union]
    # sums of three written out: one order of additions on every CPU
    if terms.distance is None:
        d = np.sqrt(e[:, 0] ** 2 + e[:, 1] ** 2 + e[:, 2] ** 2).astype(np.float32)
    else:
        d = terms.distance[union].astype(np.float32)
    s = terms.sigma[union].astype(np.float32)
    ev = (e[:, 0] * v[:, 0] + e[:, 1] * v[:, 1] + e[:, 2] * v[:, 2]).astype(np.float32)
    vv = (v[:, 0] ** 2 + v[:, 1] ** 2 + v[:, 2] ** 2).astype(np.float32)
    period = terms.period[union].astype(np.float32)
    out = np.empty((draws, len(stats)))
    width = max(len(union), 1)
    chunk = max(1, CHUNK_ELEMENTS // width)
    for start in range(0, draws, chunk):
        m = min(chunk, draws - start)
        dist = np.broadcast_to(d, (m, len(union)))
        if lag is not None:
            lo, hi = lag
            shift = rng.uniform(lo, hi, (m, len(union))).astype(np.float32) * period
            sq = d * d - 2.0 * shift * ev + shift * shift * vv
            dist = np.sqrt(np.maximum(sq, 0.0))
        if noise:
            along = dist + rng.standard_normal((m, len(union)), dtype=np.float32) * s
            across = rng.standard_exponential((m, len(union)), dtype=np.float32)
            across *= 2.0 * s * s
            dist = np.sqrt(along * along + across)
        for k, (st, c) in enumerate(zip(stats, cols, strict=True)):
            # a sort is faster than a partition at these widths (a few hundred poses)
            part = np.sort(dist[:, c], axis=1)
            a, b = part[:, st.low].astype(np.float64), part[:, st.high].astype(np.float64)
            out[start : start + m, k] = a + st.fraction * (b - a)
    return out
