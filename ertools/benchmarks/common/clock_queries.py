"""GT positions at shifted robot stamps, for the clock audit (:mod:`.clocks`): exact linear
interpolation, not across GT gaps longer than the max gap, of many queries at once.

Three ways to the same numbers, bit for bit: :func:`evaluate` locates and interpolates each
query on its own; :func:`window_distances` serves a scan of closely spaced offsets from small
per-pose tables of the few GT samples its queries fall among; :func:`right_near` moves the
places of queries from those of nearby ones (Gauss-Newton steps) instead of searching afresh.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from ertools.arrays import F64, I64, IntArr
from ertools.frozen_dataclass import frozen_dataclass
from ertools.geometry import bracket, row_norm
from ertools.streams import PoseStream
from ertools.timeutil import NS_PER_S

MAX_NS = np.iinfo(np.int64).max


@frozen_dataclass(eq=False)
class Evaluation:
    """GT positions at shifted robot times, where they are usable.

    Attributes:
        valid: (N,) which queries have a usable GT position.
        gt_xyz: (valid.sum(), 3) the GT positions at the valid queries only.
        lo, hi: (valid.sum(),) the GT samples around each valid query.
        diff: (valid.sum(), 3) GT position at ``hi`` minus at ``lo``.
        span_ns: (valid.sum(),) GT time at ``hi`` minus at ``lo``.
    """

    valid: npt.NDArray[np.bool_]
    gt_xyz: F64
    lo: IntArr
    hi: IntArr
    diff: F64
    span_ns: I64


def evaluate(
    gt: PoseStream,
    query_ns: I64,
    max_gap_ns: int,
    around: tuple[IntArr, IntArr] | None = None,
) -> Evaluation:
    """GT at the queries (``around``: their :func:`~ertools.geometry.bracket`, if known)."""
    t = gt.t_ns
    n = len(t)
    lo, hi = bracket(t, query_ns) if around is None else around
    inside = (lo >= 0) & (hi < n)
    all_inside = bool(inside.all())
    lo_c = lo if all_inside else np.clip(lo, 0, n - 1)
    hi_c = hi if all_inside else np.clip(hi, 0, n - 1)
    t_lo = t.take(lo_c)
    span = t.take(hi_c) - t_lo
    valid = inside & (span <= max_gap_ns)
    q = query_ns
    if not valid.all():  # only the usable queries are worth interpolating
        keep = np.flatnonzero(valid)
        lo_c, hi_c, t_lo, span, q = lo_c[keep], hi_c[keep], t_lo[keep], span[keep], q[keep]
    with np.errstate(invalid="ignore", divide="ignore"):
        alpha = np.where(span > 0, (q - t_lo).astype(np.float64) / span, 0.0)
    # No clip to [0, 1]: a valid query lies between its two samples, and the rounded
    # quotient of 0 <= a <= b stays in [0, 1].
    x_lo = np.take(gt.xyz, lo_c, axis=0)  # take: whole rows, twice as fast as x[i]
    diff = np.take(gt.xyz, hi_c, axis=0) - x_lo
    at = diff * alpha[:, None]  # in place after: one (N, 3) temporary fewer, same sums
    at += x_lo
    return Evaluation(valid, at, lo_c, hi_c, diff, span)


def velocity(gt: PoseStream, ev: Evaluation, max_gap_ns: int) -> F64:
    """(valid.sum(), 3) GT velocity at the valid queries, m/s.

    Of the segment around the query; at an exact hit, of the segment after it. Segments
    longer than the max gap (or of no duration) give no usable velocity: 0.
    """
    n = len(gt)
    seg_lo = np.minimum(ev.lo, max(n - 2, 0))
    seg_hi = np.minimum(seg_lo + 1, n - 1)
    # Between two samples the segment is (lo, hi), already subtracted: only exact hits need
    # other samples.
    num, seg_ns = ev.diff, ev.span_ns
    other = np.flatnonzero((seg_lo != ev.lo) | (seg_hi != ev.hi))
    if other.size:
        a, b = seg_lo[other], seg_hi[other]
        num, seg_ns = num.copy(), seg_ns.copy()
        num[other] = gt.xyz[b] - gt.xyz[a]
        seg_ns[other] = gt.t_ns[b] - gt.t_ns[a]
    dt = seg_ns.astype(np.float64) / NS_PER_S
    with np.errstate(invalid="ignore", divide="ignore"):
        vel = num / dt[:, None]
    unusable = ~((dt > 0) & (seg_ns <= max_gap_ns))
    if unusable.any():
        vel[unusable] = 0.0
    return np.asarray(vel, dtype=np.float64)


def valid_rows(xyz: F64, ev: Evaluation) -> F64:
    """The rows of ``xyz`` at the evaluation's valid queries (no copy when all are valid)."""
    return xyz if len(ev.gt_xyz) == len(xyz) else xyz[ev.valid]


def plain_distances(
    robot_t: I64, robot_xyz: F64, gt: PoseStream, offsets: I64, max_gap_ns: int
) -> tuple[F64, npt.NDArray[np.bool_]]:
    """(offsets, poses) distances to the GT at the shifted stamps (NaN where there is no usable
    GT position) and where there is one: every query located and interpolated on its own."""
    shape = (len(offsets), len(robot_t))
    queries = (offsets[:, None] + robot_t[None, :]).ravel()  # offset-major
    ev = evaluate(gt, queries, max_gap_ns, around_window(gt.t_ns, robot_t, offsets, queries))
    if len(ev.gt_xyz) == queries.size:
        dist = row_norm(robot_xyz - ev.gt_xyz.reshape(*shape, 3))
    else:
        dist = np.full(shape, np.nan)
        pose = np.flatnonzero(ev.valid) % len(robot_t)
        dist.ravel()[ev.valid] = row_norm(np.take(robot_xyz, pose, axis=0) - ev.gt_xyz)
    return dist, ev.valid.reshape(shape)


# Table rows window_distances gathers at once (64 bytes each: 0.5 MB)
BLOCK_ROWS = 8192

# GT samples within one pose's span of fine offsets above which the window tables of
# window_distances would grow past the plain evaluation's cost (40 ms at 120 Hz: 5)
WINDOW_MAX_SAMPLES = 64


def window_distances(
    robot_t: I64, robot_xyz: F64, gt: PoseStream, offsets: I64, max_gap_ns: int
) -> tuple[F64, npt.NDArray[np.bool_]] | None:
    """:func:`plain_distances` to the bit, from each pose's few GT samples.

    The offsets span a few tens of ms, so the queries of one pose fall among a handful of GT
    samples: those go into small per-pose tables (stamp, segment span, position, difference
    to the next sample), and each query reads its segment there instead of the whole GT. A
    query's segment is the count of window samples at or before it: each sample's first
    offset reaching it is one ``searchsorted`` over the offsets, and a cumulative sum of
    those counts gives every query's. The arithmetic per query is :func:`evaluate`'s and
    ``row_norm``'s, operation for operation. A query exactly on a GT stamp takes that sample
    alone, as :func:`evaluate` does (its bracket's two samples are the one); on a repeated
    GT stamp :func:`evaluate` itself computes it. None: offsets not increasing, or a window
    wider than :data:`WINDOW_MAX_SAMPLES`.
    """
    n_off, n_pose = len(offsets), len(robot_t)
    t = gt.t_ns
    n = len(t)
    if n_off == 0 or n_pose == 0 or not np.all(np.diff(offsets) > 0):
        return None
    first = np.searchsorted(t, robot_t + offsets[0], side="right")
    width = np.searchsorted(t, robot_t + offsets[-1], side="right") - first
    w_max = int(width.max())
    if w_max > WINDOW_MAX_SAMPLES:
        return None
    # Table column c holds sample first - 1 + c; segment c runs from column c to c + 1.
    sample = first[:, None] + np.arange(-1, w_max + 1)
    at = np.clip(sample, 0, n - 1)
    stamp = t.take(at)
    # One row of 8 numbers per segment (its stamp before the query's robot stamp, its span,
    # the position at its start and the difference to its end), so each query gathers one
    # 64-byte row: NumPy's take costs ~13 instructions per element, about a row's.
    table = np.empty((n_pose, w_max + 1, 8))
    ints = table.view(np.int64)
    np.subtract(robot_t[:, None], stamp[:, :-1], out=ints[:, :, 0])
    np.subtract(stamp[:, 1:], stamp[:, :-1], out=ints[:, :, 1])
    np.take(gt.xyz, at[:, :-1], axis=0, out=table[:, :, 2:5])
    np.subtract(np.take(gt.xyz, at[:, 1:], axis=0), table[:, :, 2:5], out=table[:, :, 5:8])
    seg_ok = (sample[:, :-1] >= 0) & (sample[:, 1:] < n) & (ints[:, :, 1] <= max_gap_ns)
    # The first offset at or after which each window sample is at or before the query
    # (samples beyond a pose's window: after every query), and one more mark per pose past
    # the last offset: every pose then has w_max + 1 marks, and one cumulative sum over all
    # of them gives each query's table row at once.
    beyond = np.arange(w_max) >= width[:, None]
    reach = np.full((n_pose, w_max + 1), n_off)
    reach[:, :-1] = np.searchsorted(offsets, stamp[:, 1:-1] - robot_t[:, None], side="left")
    reach[:, :-1][beyond] = n_off
    reach += np.arange(0, n_pose * (n_off + 1), n_off + 1)[:, None]
    marks = np.bincount(reach.ravel(), minlength=n_pose * (n_off + 1))
    seg = np.cumsum(marks).reshape(n_pose, n_off + 1)[:, :n_off]
    # offset-major, C order: the means below sum each row as before
    idx = np.ascontiguousarray(seg.T).ravel()
    shape = (n_off, n_pose)
    used = np.ones((n_pose, w_max + 1), dtype=bool)  # the segments some query reads
    used[:, 1:] = ~beyond
    if seg_ok[used].all():
        valid = np.ones(shape, dtype=bool)
    else:
        valid = seg_ok.ravel().take(idx).reshape(shape)
    rel = np.empty(shape, dtype=np.int64)
    sq = np.empty(shape)
    rows_table = table.reshape(-1, 8)
    # A few offsets at a time: their gathered rows (~0.5 MB) stay in cache for the seven
    # strided passes over them below (all of an hour's at once, 8 MB, were read from memory
    # seven times: ~40 % slower). Element by element the same arithmetic.
    block = max(1, BLOCK_ROWS // n_pose)
    for o0 in range(0, n_off, block):
        o1 = min(o0 + block, n_off)
        rows = np.take(rows_table, idx[o0 * n_pose : o1 * n_pose], axis=0)
        part = (o1 - o0, n_pose)
        # the query's stamp minus its segment's start, exact in int64
        np.add(rows.view(np.int64)[:, 0].reshape(part), offsets[o0:o1, None], out=rel[o0:o1])
        span = rows.view(np.int64)[:, 1].reshape(part)
        out = sq[o0:o1]
        g = np.empty(part)
        # invalid queries (their span 0 or beyond the GT) compute garbage, masked below
        with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
            # span > 0 off the stamps: the quotient evaluate takes there
            alpha = rel[o0:o1].astype(np.float64) / span
            for k in range(3):
                np.multiply(rows[:, 5 + k].reshape(part), alpha, out=g)
                g += rows[:, 2 + k].reshape(part)
                np.subtract(robot_xyz[:, k], g, out=g)
                if k == 0:
                    np.multiply(g, g, out=out)
                else:
                    g *= g
                    out += g
    dist = np.sqrt(sq, out=sq)
    hit = np.flatnonzero(rel == 0)
    if hit.size:
        # On a stamp evaluate takes that sample alone (bracket's hi is lo, span 0): valid,
        # and the distance to the sample itself; with repeated stamps there hi is the first
        # of them: evaluate itself.
        pose = hit % n_pose
        lo = first[pose] - 1 + (idx[hit] - pose * (w_max + 1))
        again = (lo > 0) & (t.take(np.maximum(lo - 1, 0)) == t.take(lo))
        alone = ~again
        valid.ravel()[hit[alone]] = True
        x_lo = np.take(gt.xyz, lo[alone], axis=0)
        at_hit = (x_lo - x_lo) * 0.0  # evaluate's arithmetic (NaN where x_lo is not finite)
        at_hit += x_lo
        dist.ravel()[hit[alone]] = row_norm(np.take(robot_xyz, pose[alone], axis=0) - at_hit)
        if again.any():
            hit = hit[again]
            q = offsets[hit // n_pose] + robot_t[hit % n_pose]
            ev = evaluate(gt, q, max_gap_ns)
            valid.ravel()[hit] = ev.valid
            pose = hit[ev.valid] % n_pose
            dist.ravel()[hit[ev.valid]] = row_norm(np.take(robot_xyz, pose, axis=0) - ev.gt_xyz)
    if not valid.all():
        dist[~valid] = np.nan
    return dist, valid


def around_window(
    t: I64, robot_t: I64, offsets: I64, queries: I64 | None = None
) -> tuple[IntArr, IntArr] | None:
    """:func:`~ertools.geometry.bracket` of ``offsets[:, None] + robot_t[None, :]``, flattened
    (``queries``, if the caller has them already).

    The offsets span a few tens of ms, so each pose's queries fall among a handful of GT
    samples: counting the ones at or before each query there is ~5x cheaper than a binary
    search per query. None when a window holds too many samples for that to pay.
    """
    first = np.searchsorted(t, robot_t + offsets.min(), side="right")
    width = np.searchsorted(t, robot_t + offsets.max(), side="right") - first
    if width.max() > 16:
        return None
    shape = (len(offsets), len(robot_t))
    if queries is None:
        queries = (offsets[:, None] + robot_t[None, :]).ravel()
    queries = queries.reshape(shape)
    right = np.broadcast_to(first, shape).copy()
    for w in range(int(width.max())):
        # Beyond its window a pose counts nothing (those samples lie after every query).
        cand = np.where(w < width, t.take(np.minimum(first + w, len(t) - 1)), MAX_NS)
        right += cand <= queries
    return bracket(t, queries.ravel(), right.ravel())


# Moves by one sample of each query's place before a binary search is cheaper (a move costs
# ~1/3 of a search of an hour's GT)
NEAR_STEPS = 3


def right_near(t: I64, query: I64, right: IntArr | None) -> IntArr:
    """``np.searchsorted(t, query, side="right")``, moved there from ``right``, that of
    nearby queries (None: a binary search).

    Every place moves by one sample per round towards its own (up while the sample there is
    at or before the query, down while the one before it is after), and a round that moves
    none proves every place right; when :data:`NEAR_STEPS` + 1 rounds all moved some place,
    the binary search.
    """
    if right is None or len(right) != len(query):
        return np.searchsorted(t, query, side="right")
    n = len(t)
    right = right.copy()
    for _ in range(NEAR_STEPS + 1):
        up = t.take(np.minimum(right, n - 1)) <= query
        up &= right < n
        down = t.take(np.maximum(right - 1, 0)) > query
        down &= right > 0
        if not (up.any() or down.any()):
            return right
        right += up
        right -= down
    return np.searchsorted(t, query, side="right")
