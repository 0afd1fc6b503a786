"""Clock audit: estimate the constant offset between a robot's clock and the mocap clock.

The robot stamps its own pose estimates with its clock; the mocap logger with the GT clock.
When the two machines were not synchronised, every robot pose is compared with the GT pose of
another moment and the trajectory error grows with the robot's speed. This module finds the
offset ``d`` that, added to the robot stamps, best aligns the robot's positions with the GT:

1. coarse scan: the mean 3D distance between robot positions and the GT positions at
   ``t + d`` for ``d`` every 20 ms over ``[-range, +range]`` (on at most a few thousand robot
   poses, evenly spread; the GT resampled once on a 10 ms grid, so each offset is a gather);
2. fine scan: 1 ms steps around the best coarse value, with exact linear interpolation;
3. refinement: Gauss-Newton steps on the sum of squared distances (the GT velocity is the
   derivative of the GT position with respect to ``d``), to sub-millisecond resolution.

Uncertainty: a block bootstrap of the final Gauss-Newton step. The robot's estimation error is
strongly autocorrelated (a localisation bias lasts seconds), so a curvature-based standard
error that treats every pose as independent would be far too optimistic; resampling blocks of
several seconds keeps that correlation. The estimate includes any constant latency of the
robot's estimator (it cannot be told apart from a clock offset), which the docs say.

Pure NumPy: streams in, a frozen :class:`OffsetEstimate` out.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from ertools.arrays import F64, I64, IntArr
from ertools.benchmarks.common.hygiene import drop_repeats
from ertools.geometry import bracket, row_dot, row_norm
from ertools.streams import PoseStream
from ertools.timeutil import NS_PER_S

# A clock residual worth a warning must also matter for a score: 10 ms is 5 mm at a typical
# 0.5 m/s
MATTERS_NS = 10_000_000
COARSE_STEP_NS = 20_000_000  # 20 ms: at 1 m/s a 2 cm change of the cost, well resolved
FINE_STEP_NS = 1_000_000
GRID_NS = COARSE_STEP_NS // 2
GRID_MAX_POINTS = 1_000_000  # 12 MB of grid positions at most; a longer GT gets a coarser grid
GRID_CHUNK = 1 << 15  # grid points per np.interp call
COARSE_MAX_POSES = 3000
MIN_POSES = 20
MIN_RMS_SPEED = 0.02  # m/s: below this the robot stood still and no offset is observable
BOOTSTRAP_DRAWS = 500
BLOCK_NS = 5 * NS_PER_S
MAX_NS = np.iinfo(np.int64).max


@dataclass(frozen=True)
class OffsetEstimate:
    """The clock audit of a robot log against GT.

    Attributes:
        offset_ns: seconds x 1e9 to add to the robot stamps to put them on the GT clock
            (positive when the robot clock is behind), None when not observable.
        uncertainty_ns: one standard deviation (block bootstrap), None with ``offset_ns``.
        search_range_ns: the offsets searched were within +- this.
        poses_used: robot poses compared at the estimate.
        mean_error: mean 3D distance at the estimate, metres.
        mean_error_at_zero: mean 3D distance with no offset (None when no pose compares).
        note: why there is no estimate, or what to be careful about; "" when all is well.
    """

    offset_ns: int | None
    uncertainty_ns: int | None
    search_range_ns: int
    poses_used: int
    mean_error: float | None
    mean_error_at_zero: float | None
    note: str = ""
    method: str = "min mean position error over offsets, Gauss-Newton, block bootstrap"

    @property
    def offset_s(self) -> float | None:
        return None if self.offset_ns is None else self.offset_ns / NS_PER_S

    @property
    def uncertainty_s(self) -> float | None:
        return None if self.uncertainty_ns is None else self.uncertainty_ns / NS_PER_S

    def disagrees_with(self, applied_ns: int) -> bool:
        """Whether the stamps fit the GT at an offset other than ``applied_ns`` both
        significantly (3 sigma) and by enough to matter for a score (10 ms: 5 mm at a typical
        0.5 m/s): the clock audit's warning."""
        if self.offset_ns is None:
            return False
        sigma = self.uncertainty_ns or 0
        return abs(self.offset_ns - applied_ns) > max(3 * sigma, MATTERS_NS)


@dataclass(frozen=True, eq=False)
class _Eval:
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


def _evaluate(
    gt: PoseStream,
    query_ns: I64,
    max_gap_ns: int,
    around: tuple[IntArr, IntArr] | None = None,
) -> _Eval:
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
    return _Eval(valid, at, lo_c, hi_c, diff, span)


def _velocity(gt: PoseStream, ev: _Eval, max_gap_ns: int) -> F64:
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


def _valid_rows(xyz: F64, ev: _Eval) -> F64:
    """The rows of ``xyz`` at the evaluation's valid queries (no copy when all are valid)."""
    return xyz if len(ev.gt_xyz) == len(xyz) else xyz[ev.valid]


def _mean_error(
    robot_t: I64, robot_xyz: F64, gt: PoseStream, offset_ns: int, max_gap_ns: int
) -> tuple[float, int]:
    ev = _evaluate(gt, robot_t + offset_ns, max_gap_ns)
    used = len(ev.gt_xyz)
    if used == 0:
        return float("inf"), 0
    d = row_norm(_valid_rows(robot_xyz, ev) - ev.gt_xyz)
    return float(d.mean()), used


def _coarse_scan(
    robot_t: I64, robot_xyz: F64, gt: PoseStream, offsets: I64, max_gap_ns: int
) -> F64:
    """Mean distance at each offset, against the GT resampled on a uniform grid.

    One ``np.interp`` per axis builds the grid (step :data:`GRID_NS`, half the coarse
    step); each offset is then a gather of grid points, so the scan costs a few
    microseconds per offset instead of an interpolation over the whole GT. Grid points
    between GT samples more than ``max_gap_ns`` apart are invalid. Nearest-grid lookup errs
    by at most half a grid step of travel (5 mm at 1 m/s): the coarse scan only has to find
    the right 20 ms bin; the fine scan and Gauss-Newton use exact interpolation.
    """
    t = gt.t_ns
    span = int(t[-1] - t[0])
    step = max(GRID_NS, span // GRID_MAX_POINTS + 1)
    n_grid = span // step + 1
    base = np.rint((robot_t - t[0]) / step).astype(np.int64)
    shifts = np.rint(offsets / step).astype(np.int64)
    # Invalid points are NaN and the grid is padded with NaN beyond both ends, so every
    # shifted index is in range and one gather gives both the position and its validity.
    pad = int(max(0, -(shifts.min() + base.min()), shifts.max() + base.max() - n_grid + 1))
    grid = _grid(gt, step, n_grid, max_gap_ns, pad)
    base += pad
    pos = robot_xyz.T.astype(np.float32)
    pruned = _pruned_costs(grid, base, shifts, pos)
    if pruned is not None:
        return pruned
    costs, counts, _ = _grid_costs(grid, base, shifts, pos, np.arange(len(offsets)))
    return _enough(costs, counts, counts.max())


def _enough(costs: F64, counts: I64, most: int) -> F64:
    """The costs of offsets that compare at least half the most poses any offset compares
    (an offset leaving few poses inside the GT could win by chance); inf for the others."""
    return np.where(counts >= max(MIN_POSES, int(0.5 * most)), costs, np.inf)


def _grid_costs(
    grid: npt.NDArray[np.float32],
    base: I64,
    shifts: I64,
    pos: npt.NDArray[np.float32],
    which: IntArr,
) -> tuple[F64, I64, F64]:
    """Mean distance, poses compared and largest distance at the offsets ``which``, each
    offset's row of poses on its own (the same numbers whichever offsets are costed)."""
    costs = np.full(len(which), np.inf)
    counts = np.zeros(len(which), dtype=np.int64)
    largest = np.zeros(len(which))
    block = max(1, 200_000 // max(len(base), 1))  # ~0.8 MB of float32 per axis and block
    for lo in range(0, len(which), block):  # blocks of offsets x all poses, vectorised
        idx = shifts[which[lo : lo + block], None] + base[None, :]
        dist = _squared_distances(grid, idx, pos)
        np.sqrt(dist, out=dist)
        missing = np.isnan(dist)
        cnt = idx.shape[1] - np.count_nonzero(missing, axis=1)
        dist[missing] = 0.0
        total = dist.sum(axis=1)
        with np.errstate(invalid="ignore", divide="ignore"):
            costs[lo : lo + block] = np.where(cnt > 0, total / np.maximum(cnt, 1), np.inf)
        counts[lo : lo + block] = cnt
        largest[lo : lo + block] = dist.max(axis=1)
    return costs, counts, largest


# The coarse scan costs one offset in this many first, then only the offsets that the
# distances found can leave near the best.
COARSE_FIRST_EVERY = 4
# Relative error allowed for a cost or a distance of float32 sums: a float32 sum of the
# thousands of poses errs by ~1e-6 pairwise, 2e-4 at worst one after the other.
_COST_MARGIN = 1e-3


def _pruned_costs(
    grid: npt.NDArray[np.float32], base: I64, shifts: I64, pos: npt.NDArray[np.float32]
) -> F64 | None:
    """:func:`_coarse_scan`'s costs where an offset can be the best or fit almost as well
    (:func:`estimate_offset`: within 10 % + 1 mm of it), inf elsewhere; None: the case is
    not one of those shown below, cost every offset.

    One offset in :data:`COARSE_FIRST_EVERY` is costed first. A pose's distance changes by at
    most its grid point's move between two offsets, and no move between neighbouring grid
    points exceeds the largest step of the grid: from the costs found, each other offset's
    cost has a lower bound, and where that bound exceeds the best found by more than 10 % +
    1 mm, the offset can be neither the best nor a rival (nor make a rival's neighbour look
    lower), and is left out. Shown when every grid point the scan reads between the first
    and the last valid one is valid (no gap), the robot positions are finite and the poses
    in time order: each offset then compares the poses of one range.
    """
    n_off = len(shifts)
    if n_off < 3 * COARSE_FIRST_EVERY or len(base) < MIN_POSES:
        return None
    if not (np.all(np.diff(base) >= 0) and np.all(np.diff(shifts) > 0)):
        return None
    if not np.isfinite(pos).all():
        return None
    lo, hi = int(base[0] + shifts[0]), int(base[-1] + shifts[-1])
    used = grid[:, lo : hi + 1]
    valid = np.flatnonzero(~np.isnan(used).any(axis=0))
    if valid.size < 2 or valid[-1] - valid[0] + 1 != valid.size:
        return None
    first, last = lo + int(valid[0]), lo + int(valid[-1])
    inside = used[:, valid[0] : valid[-1] + 1]
    # the poses each offset compares: those whose shifted grid point is valid, a range
    start = np.searchsorted(base, first - shifts, side="left")
    stop = np.searchsorted(base, last - shifts, side="right")
    counts = np.maximum(stop - start, 0)
    every = np.arange(n_off)
    sampled = every[::COARSE_FIRST_EVERY]
    if sampled[-1] != n_off - 1:  # and the last (np.union1d would import numpy.ma: 10 ms)
        sampled = np.append(sampled, n_off - 1)
    got, got_counts, largest = _grid_costs(grid, base, shifts, pos, sampled)
    if not np.array_equal(got_counts, counts[sampled]):
        return None
    costs = np.full(n_off, np.inf)
    costs[sampled] = got
    costs = _enough(costs, counts, int(counts.max()))
    best = float(costs[sampled].min())
    # the largest move between neighbouring grid points (float32 differences: rounded up)
    moves = [np.diff(inside[k]) for k in range(3)]
    step = math.sqrt(sum(max(float(d.max()), -float(d.min())) ** 2 for d in moves)) * (1 + 1e-6)
    if not (np.isfinite(best) and np.isfinite(got[got_counts > 0]).all() and math.isfinite(step)):
        return None  # nothing compared, or float32 overflowed: no bound shown
    limit = (best * 1.1 + 1e-3) * (1 + 1e-9)
    bound = np.full(n_off, -np.inf)
    at = np.searchsorted(sampled, every)
    for near in (sampled[np.maximum(at - 1, 0)], sampled[np.minimum(at, len(sampled) - 1)]):
        k = np.searchsorted(sampled, near)
        both = np.maximum(np.minimum(stop, stop[near]) - np.maximum(start, start[near]), 0)
        gone = counts[near] - both  # poses the sampled offset compares and this one not
        moved = np.abs(shifts - shifts[near]).astype(np.float64) * step
        with np.errstate(invalid="ignore", divide="ignore"):
            total = got[k] * got_counts[k] * (1 - _COST_MARGIN)
            total -= gone * largest[k] * (1 + _COST_MARGIN) + both * moved
            low = total * (1 - _COST_MARGIN) / counts
        bound = np.maximum(bound, np.where((got_counts[k] > 0) & (counts > 0), low, -np.inf))
    enough = np.isfinite(_enough(np.zeros(n_off), counts, int(counts.max())))
    need = enough & (bound <= limit)
    need[sampled] = False
    if need.any():
        costs[need] = _grid_costs(grid, base, shifts, pos, np.flatnonzero(need))[0]
    return costs


def _squared_distances(
    grid: npt.NDArray[np.float32], idx: I64, pos: npt.NDArray[np.float32]
) -> npt.NDArray[np.float32]:
    """Squared distances from ``pos[:, j]`` to the grid points ``idx[i, j]``, axis by axis.

    1D gathers from contiguous rows are ~5x faster than gathering 12-byte (x, y, z) rows, and
    the squares add up in the order einsum added them: (x^2 + y^2) + z^2.
    """
    sq: npt.NDArray[np.float32] = grid[0].take(idx)
    sq -= pos[0]
    sq *= sq
    for k in (1, 2):
        d = grid[k].take(idx)
        d -= pos[k]
        d *= d
        sq += d
    return sq


def _grid(
    gt: PoseStream, step: int, n_grid: int, max_gap_ns: int, pad: int
) -> npt.NDArray[np.float32]:
    """(3, pad + n_grid + pad) GT positions every ``step`` ns from the first GT sample.

    float32: 0.1 um resolution at 10 m, and half the memory of an hour's grid. NaN in the
    padding and at grid points strictly inside a GT gap longer than ``max_gap_ns``.
    """
    t = gt.t_ns
    grid = np.empty((3, n_grid + 2 * pad), dtype=np.float32)  # every point written below
    grid[:, :pad] = np.nan
    grid[:, pad + n_grid :] = np.nan
    # Chunk by chunk, each against the GT samples around it: the temporaries stay small and
    # in cache (an hour's whole-grid np.interp allocated ~30 MB). Every grid point gets the
    # same two samples and the same arithmetic as in one call over everything.
    starts = np.arange(0, n_grid, GRID_CHUNK, dtype=np.int64)
    ends = np.minimum(starts + GRID_CHUNK, n_grid)
    first = np.searchsorted(t, t[0] + starts * step, side="right") - 1
    after = np.searchsorted(t, t[0] + (ends - 1) * step, side="right") + 1
    chunks = zip(starts.tolist(), ends.tolist(), first.tolist(), after.tolist(), strict=True)
    for g0, g1, a, b in chunks:
        rel_t = (t[a:b] - t[0]).astype(np.float64)
        rel_g = np.arange(g0, g1, dtype=np.float64) * step  # exact: whole ns below 2**53
        for k in range(3):
            grid[k, pad + g0 : pad + g1] = np.interp(rel_g, rel_t, gt.xyz[a:b, k])
    # Mark the invalid points per gap (a handful) instead of locating every grid point in
    # the GT. The first grid point is the first GT sample; it is judged by the first GT
    # interval, as it always was.
    gaps = np.flatnonzero(np.diff(t) > max_gap_ns)
    if gaps.size:
        grid_t = t[0] + np.arange(n_grid, dtype=np.int64) * step
        marks = np.zeros(n_grid + 1, dtype=np.int64)
        np.add.at(marks, np.searchsorted(grid_t, t[gaps], side="right"), 1)
        np.add.at(marks, np.searchsorted(grid_t, t[gaps + 1], side="left"), -1)
        grid_ok = np.cumsum(marks[:-1]) == 0
    else:
        grid_ok = np.ones(n_grid, dtype=bool)
    grid_ok[0] = (t[1] - t[0]) <= max_gap_ns or t[1] == t[0]
    grid[:, pad + np.flatnonzero(~grid_ok)] = np.nan
    return grid


def _scan(
    robot_t: I64, robot_xyz: F64, gt: PoseStream, offsets: I64, max_gap_ns: int
) -> tuple[F64, I64]:
    """Mean distance at each offset with exact interpolation, all offsets in one evaluation."""
    found = _window_distances(robot_t, robot_xyz, gt, offsets, max_gap_ns)
    if found is not None:
        dist, valid = found
    else:
        dist, valid = _plain_distances(robot_t, robot_xyz, gt, offsets, max_gap_ns)
    counts = valid.sum(axis=1)
    if counts.sum() == dist.size:
        costs = dist.mean(axis=1)  # each row summed as one array, as below
    else:
        costs = np.full(len(offsets), np.inf)
        for i in np.flatnonzero(counts):
            # Each offset's mean over its own compared poses, summed as one array of them.
            costs[i] = float(dist[i][valid[i]].mean())
    # An offset that leaves few poses inside the GT could win by chance: require at least
    # half of the best coverage any offset achieves.
    enough = counts >= max(MIN_POSES, int(0.5 * counts.max()))
    return np.where(enough, costs, np.inf), counts


def _plain_distances(
    robot_t: I64, robot_xyz: F64, gt: PoseStream, offsets: I64, max_gap_ns: int
) -> tuple[F64, npt.NDArray[np.bool_]]:
    """(offsets, poses) distances to the GT at the shifted stamps (NaN where there is no usable
    GT position) and where there is one: every query located and interpolated on its own."""
    shape = (len(offsets), len(robot_t))
    queries = (offsets[:, None] + robot_t[None, :]).ravel()  # offset-major
    ev = _evaluate(gt, queries, max_gap_ns, _around_window(gt.t_ns, robot_t, offsets, queries))
    if len(ev.gt_xyz) == queries.size:
        dist = row_norm(robot_xyz - ev.gt_xyz.reshape(*shape, 3))
    else:
        dist = np.full(shape, np.nan)
        pose = np.flatnonzero(ev.valid) % len(robot_t)
        dist.ravel()[ev.valid] = row_norm(np.take(robot_xyz, pose, axis=0) - ev.gt_xyz)
    return dist, ev.valid.reshape(shape)


# GT samples within one pose's span of fine offsets above which the window tables of
# _window_distances would grow past the plain evaluation's cost (40 ms at 120 Hz: 5)
WINDOW_MAX_SAMPLES = 64


def _window_distances(
    robot_t: I64, robot_xyz: F64, gt: PoseStream, offsets: I64, max_gap_ns: int
) -> tuple[F64, npt.NDArray[np.bool_]] | None:
    """:func:`_plain_distances` to the bit, from each pose's few GT samples.

    The offsets span a few tens of ms, so the queries of one pose fall among a handful of GT
    samples: those go into small per-pose tables (stamp, segment span, position, difference
    to the next sample), and each query reads its segment there instead of the whole GT. A
    query's segment is the count of window samples at or before it: each sample's first
    offset reaching it is one ``searchsorted`` over the offsets, and a cumulative sum of
    those counts gives every query's. The arithmetic per query is :func:`_evaluate`'s and
    ``row_norm``'s, operation for operation; a query exactly on a GT stamp (whose samples
    around follow another rule) is evaluated by :func:`_evaluate` itself. None: offsets not
    increasing, or a window wider than :data:`WINDOW_MAX_SAMPLES`.
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
    rows = np.take(table.reshape(-1, 8), idx, axis=0)
    shape = (n_off, n_pose)
    # the query's stamp minus its segment's start, exact in int64
    rel = rows.view(np.int64)[:, 0].reshape(shape) + offsets[:, None]
    span = rows.view(np.int64)[:, 1].reshape(shape)
    used = np.ones((n_pose, w_max + 1), dtype=bool)  # the segments some query reads
    used[:, 1:] = ~beyond
    if seg_ok[used].all():
        valid = np.ones(shape, dtype=bool)
    else:
        valid = seg_ok.ravel().take(idx).reshape(shape)
    sq = np.empty(shape)
    g = np.empty(shape)
    # invalid queries (their span 0 or beyond the GT) compute garbage, masked below
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        # span > 0 off the stamps: the quotient _evaluate takes there
        alpha = rel.astype(np.float64) / span
        for k in range(3):
            np.multiply(rows[:, 5 + k].reshape(shape), alpha, out=g)
            g += rows[:, 2 + k].reshape(shape)
            np.subtract(robot_xyz[:, k], g, out=g)
            if k == 0:
                np.multiply(g, g, out=sq)
            else:
                g *= g
                sq += g
    dist = np.sqrt(sq, out=sq)
    hit = np.flatnonzero(rel == 0)
    if hit.size:
        # On a stamp _evaluate takes that sample alone (bracket's hi is lo, span 0): valid,
        # and the distance to the sample itself; with repeated stamps there hi is the first
        # of them: _evaluate itself.
        pose = hit % n_pose
        lo = first[pose] - 1 + (idx[hit] - pose * (w_max + 1))
        again = (lo > 0) & (t.take(np.maximum(lo - 1, 0)) == t.take(lo))
        alone = ~again
        valid.ravel()[hit[alone]] = True
        x_lo = np.take(gt.xyz, lo[alone], axis=0)
        at_hit = (x_lo - x_lo) * 0.0  # _evaluate's arithmetic (NaN where x_lo is not finite)
        at_hit += x_lo
        dist.ravel()[hit[alone]] = row_norm(np.take(robot_xyz, pose[alone], axis=0) - at_hit)
        if again.any():
            hit = hit[again]
            q = offsets[hit // n_pose] + robot_t[hit % n_pose]
            ev = _evaluate(gt, q, max_gap_ns)
            valid.ravel()[hit] = ev.valid
            pose = hit[ev.valid] % n_pose
            dist.ravel()[hit[ev.valid]] = row_norm(np.take(robot_xyz, pose, axis=0) - ev.gt_xyz)
    if not valid.all():
        dist[~valid] = np.nan
    return dist, valid


def _around_window(
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


def _right_near(t: I64, query: I64, right: IntArr | None) -> IntArr:
    """``np.searchsorted(t, query, side="right")``, moved there from ``right``, that of
    nearby queries (None: a binary search).

    Every place moves by one sample per round towards its own (up while the sample there is
    at or before the query, down while the one before it is after), and a round that moves
    none proves every place right; after :data:`NEAR_STEPS` moving rounds, the binary search.
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


def estimate_offset(
    robot: PoseStream,
    gt: PoseStream,
    *,
    search_range_ns: int = 5 * NS_PER_S,
    max_gap_ns: int = NS_PER_S // 10,
    seed: int = 0,
    at_zero: tuple[float, int] | None = None,
) -> OffsetEstimate:
    """Estimate the offset to add to ``robot`` stamps to align them with ``gt``.

    Args:
        robot: the robot's own poses of its marker set (stamps on the robot clock).
        gt: the mocap poses of the same marker set (stamps on the GT clock).
        search_range_ns: search offsets within +- this.
        max_gap_ns: GT samples further apart than this are not interpolated across.
        seed: of the bootstrap's random generator (the result is deterministic).
        at_zero: the mean distance and the poses compared with no offset, where the caller
            compared them already by the same rule (``gt`` linearly interpolated, not across
            more than ``max_gap_ns``); used when no GT sample repeats the one before it.
    """
    measured = drop_repeats(gt)
    if len(measured) < 2:
        at_zero = None
    elif at_zero is None or measured is not gt:
        at_zero = _mean_error(robot.t_ns, robot.xyz, measured, 0, max_gap_ns)
    gt = measured
    zero = None if at_zero is None or at_zero[1] == 0 else at_zero[0]

    def none(note: str, used: int = 0) -> OffsetEstimate:
        return OffsetEstimate(None, None, search_range_ns, used, None, zero, note)

    if len(gt) < 2 or len(robot) < MIN_POSES:
        return none(f"too few poses to estimate a clock offset (robot {len(robot)}, GT {len(gt)})")

    # 1. coarse scan on a subsample
    step = max(1, len(robot) // COARSE_MAX_POSES)
    sub_t, sub_xyz = robot.t_ns[::step], robot.xyz[::step]
    n_coarse = int(search_range_ns // COARSE_STEP_NS)
    coarse = np.arange(-n_coarse, n_coarse + 1, dtype=np.int64) * COARSE_STEP_NS
    costs = _coarse_scan(sub_t, sub_xyz, gt, coarse, max_gap_ns)
    if not np.isfinite(costs).any():
        return none("the robot poses do not overlap the GT at any offset searched")
    best = int(np.argmin(costs))
    notes: list[str] = []
    if best in (0, len(coarse) - 1):
        notes.append("best offset at the edge of the search range: widen --offset-range")
    # Another deep minimum far away means the motion repeats itself: say so.
    far = np.abs(np.arange(len(coarse)) - best) > 10
    local_min = np.zeros(len(coarse), dtype=bool)
    local_min[1:-1] = (costs[1:-1] <= costs[:-2]) & (costs[1:-1] <= costs[2:])
    rival = far & local_min & (costs <= costs[best] * 1.1 + 1e-3)
    if rival.any():
        other = coarse[np.flatnonzero(rival)[0]] / NS_PER_S
        notes.append(f"ambiguous: another offset ({other:+.2f} s) fits almost as well")

    # 2. fine scan, exact interpolation, on the subsample (Gauss-Newton then uses every pose)
    fine = coarse[best] + np.arange(-COARSE_STEP_NS, COARSE_STEP_NS + 1, FINE_STEP_NS)
    fine_costs, _ = _scan(sub_t, sub_xyz, gt, fine, max_gap_ns)
    if not np.isfinite(fine_costs).any():
        return none("the robot poses do not overlap the GT near the best coarse offset")
    offset = float(fine[int(np.argmin(fine_costs))])

    # 3. Gauss-Newton on the squared distances; each step moves the queries by less than a
    # millisecond, so each search starts from the previous one's places
    right = None
    for _ in range(5):
        query = robot.t_ns + round(offset)
        right = _right_near(gt.t_ns, query, right)
        ev = _evaluate(gt, query, max_gap_ns, bracket(gt.t_ns, query, right))
        v = _velocity(gt, ev, max_gap_ns)
        r = _valid_rows(robot.xyz, ev) - ev.gt_xyz
        vv = float(np.sum(v * v))
        if vv <= 0:
            break
        step_s = float(np.sum(r * v)) / vv
        offset += step_s * NS_PER_S
        if abs(step_s) < 1e-6:
            break
    offset_ns = round(offset)
    query = robot.t_ns + offset_ns
    ev = _evaluate(
        gt, query, max_gap_ns, bracket(gt.t_ns, query, _right_near(gt.t_ns, query, right))
    )
    used = len(ev.gt_xyz)
    if used < MIN_POSES:
        return none("too few robot poses overlap the GT at the estimated offset", used)
    v = _velocity(gt, ev, max_gap_ns)
    r = _valid_rows(robot.xyz, ev) - ev.gt_xyz
    t_used = robot.t_ns[ev.valid]
    rms_speed = _rms_speed(t_used, ev.gt_xyz)
    if rms_speed < MIN_RMS_SPEED:
        return none(
            f"the robot barely moved (RMS speed {rms_speed * 100:.1f} cm/s): "
            "no clock offset is observable",
            used,
        )
    mean_err = float(np.mean(row_norm(r)))
    sigma = _bootstrap_sigma(t_used, r, v, seed)
    if not np.isfinite(sigma):
        # Too few blocks for the bootstrap (a short log, or stamps 1 s apart as KITTI's rows).
        return none("too few poses for the offset's uncertainty", used)
    return OffsetEstimate(
        offset_ns, round(sigma * NS_PER_S), search_range_ns, used, mean_err, zero, "; ".join(notes)
    )


def _rms_speed(t_ns: I64, xyz: F64) -> float:
    """RMS speed of the GT between consecutive robot poses.

    Measured over the robot's sampling interval (~0.1 s), not between 120 Hz GT samples:
    there a standing body's 0.2 mm noise alone reads as 3 cm/s.
    """
    if len(t_ns) < 2:
        return 0.0
    dt = np.diff(t_ns).astype(np.float64) / NS_PER_S
    step = row_norm(np.diff(xyz, axis=0))
    ok = dt > 0
    return float(np.sqrt(np.mean((step[ok] / dt[ok]) ** 2))) if ok.any() else 0.0


def _bootstrap_sigma(t_ns: I64, r: F64, v: F64, seed: int) -> float:
    """Standard deviation (s) of the Gauss-Newton offset under a block bootstrap.

    Near the optimum the offset is ``d + sum(r.v)/sum(|v|^2)``; resampling blocks of poses
    (5 s, or a twentieth of the log when that is longer) with replacement and recomputing that
    step gives the spread of the estimate including the autocorrelation of the robot's error.
    """
    span = int(t_ns[-1] - t_ns[0])
    block_ns = max(BLOCK_NS, span // 20)
    block = ((t_ns - t_ns[0]) // max(block_ns, 1)).astype(np.intp)
    nb = int(block.max()) + 1
    a = np.bincount(block, weights=row_dot(r, v), minlength=nb)
    b = np.bincount(block, weights=row_dot(v, v), minlength=nb)
    if nb < 5:
        # Too few blocks to resample: the independent-errors standard error, which the
        # autocorrelation makes optimistic; inflate it by the poses per block.
        dof = max(3 * len(r) - 1, 1)
        per_block = len(r) / max(nb, 1)
        return float(np.sqrt(np.sum(r * r) / dof / np.sum(v * v) * per_block))
    rng = np.random.default_rng(seed)
    draws = rng.integers(0, nb, size=(BOOTSTRAP_DRAWS, nb))
    num, den = a[draws].sum(axis=1), b[draws].sum(axis=1)
    ok = den > 0
    if not ok.any():
        return float("nan")  # no draw with any speed: the caller reports no estimate
    return float(np.std(num[ok] / den[ok]))
