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
from dataclasses import replace

import numpy as np
import numpy.typing as npt

from ertools.arrays import F64, I64, IntArr
from ertools.benchmarks.common.clock_queries import (
    evaluate,
    plain_distances,
    right_near,
    valid_rows,
    velocity,
    window_distances,
)
from ertools.benchmarks.common.hygiene import drop_repeats
from ertools.frozen_dataclass import frozen_dataclass
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
# Grid points per np.interp call (and GT stamps per gap search): 64 KB arrays. With 32768
# points each call's temporaries came fresh from the system: ~1000 more page faults an hour.
GRID_CHUNK = 1 << 13
COARSE_MAX_POSES = 3000
MIN_POSES = 20
MIN_RMS_SPEED = 0.02  # m/s: below this the robot stood still and no offset is observable
BOOTSTRAP_DRAWS = 500
BLOCK_NS = 5 * NS_PER_S


@frozen_dataclass
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


def _mean_error(
    robot_t: I64, robot_xyz: F64, gt: PoseStream, offset_ns: int, max_gap_ns: int
) -> tuple[float, int]:
    ev = evaluate(gt, robot_t + offset_ns, max_gap_ns)
    used = len(ev.gt_xyz)
    if used == 0:
        return float("inf"), 0
    d = row_norm(valid_rows(robot_xyz, ev) - ev.gt_xyz)
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
# distances found can leave near the best. Sparser means fewer first and more after: on the
# hour 1 in 4 costs 126 + 11 offsets, 1 in 10 costs 51 + 14 (the most of 1 in 4 to 16).
COARSE_FIRST_EVERY = 10
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
    # the first and the last valid point, and none invalid between (no index array: an
    # hour's is 3 MB of fresh memory)
    invalid = np.isnan(used[0])
    invalid |= np.isnan(used[1])
    invalid |= np.isnan(used[2])
    v0 = int(np.argmin(invalid))
    v1 = len(invalid) - 1 - int(np.argmin(invalid[::-1]))
    if invalid[v0] or v1 - v0 < 1 or invalid[v0 : v1 + 1].any():
        return None
    first, last = lo + v0, lo + v1
    inside = used[:, v0 : v1 + 1]
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
    # the largest move between neighbouring grid points (float32 differences: rounded up),
    # the three axes' differences in one buffer (an hour's three were 4.3 MB of fresh memory)
    moves: list[float] = []
    d = np.empty(inside.shape[1] - 1, dtype=np.float32)
    for axis in range(3):
        np.subtract(inside[axis, 1:], inside[axis, :-1], out=d)  # np.diff
        moves.append(max(float(d.max()), -float(d.min())))
    step = math.sqrt(sum(m**2 for m in moves)) * (1 + 1e-6)
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
    # in blocks: an hour's whole np.diff was 3.5 MB of fresh memory (~1000 page faults)
    gaps = np.concatenate(
        [
            np.flatnonzero(np.diff(t[i : i + GRID_CHUNK + 1]) > max_gap_ns) + i
            for i in range(0, len(t) - 1, GRID_CHUNK)
        ]
    )
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
    found = window_distances(robot_t, robot_xyz, gt, offsets, max_gap_ns)
    if found is not None:
        dist, valid = found
    else:
        dist, valid = plain_distances(robot_t, robot_xyz, gt, offsets, max_gap_ns)
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
    found, pending = search_offset(
        robot,
        gt,
        search_range_ns=search_range_ns,
        max_gap_ns=max_gap_ns,
        seed=seed,
        zero_given=at_zero is not None,
    )
    return with_zero(found, at_zero) if pending and at_zero is not None else found


def with_zero(found: OffsetEstimate, at_zero: tuple[float, int]) -> OffsetEstimate:
    """``found`` (from :func:`search_offset`, which said the mean distance with no offset was
    pending) with that distance taken from ``at_zero``: the mean and the poses compared."""
    return replace(found, mean_error_at_zero=None if at_zero[1] == 0 else at_zero[0])


def search_offset(
    robot: PoseStream,
    gt: PoseStream,
    *,
    search_range_ns: int = 5 * NS_PER_S,
    max_gap_ns: int = NS_PER_S // 10,
    seed: int = 0,
    zero_given: bool = False,
) -> tuple[OffsetEstimate, bool]:
    """:func:`estimate_offset`, its mean distance with no offset left to the caller where the
    caller compares the poses at no offset by the same rule (``zero_given``; it may do so at
    the same time, on another thread): the estimate, and whether that distance is pending
    (then :func:`with_zero` fills it in; when a GT sample repeats the one before it, the
    audit measures it on the GT without the repeats itself).
    """
    measured = drop_repeats(gt)
    pending = zero_given and len(measured) >= 2 and measured is gt
    at_zero = None
    if len(measured) >= 2 and not pending:
        at_zero = _mean_error(robot.t_ns, robot.xyz, measured, 0, max_gap_ns)
    gt = measured
    zero = None if at_zero is None or at_zero[1] == 0 else at_zero[0]

    def none(note: str, used: int = 0) -> tuple[OffsetEstimate, bool]:
        return OffsetEstimate(None, None, search_range_ns, used, None, zero, note), pending

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
        right = right_near(gt.t_ns, query, right)
        ev = evaluate(gt, query, max_gap_ns, bracket(gt.t_ns, query, right))
        v = velocity(gt, ev, max_gap_ns)
        r = valid_rows(robot.xyz, ev) - ev.gt_xyz
        vv = float(np.sum(v * v))
        if vv <= 0:
            break
        step_s = float(np.sum(r * v)) / vv
        offset += step_s * NS_PER_S
        if abs(step_s) < 1e-6:
            break
    offset_ns = round(offset)
    query = robot.t_ns + offset_ns
    ev = evaluate(gt, query, max_gap_ns, bracket(gt.t_ns, query, right_near(gt.t_ns, query, right)))
    used = len(ev.gt_xyz)
    if used < MIN_POSES:
        return none("too few robot poses overlap the GT at the estimated offset", used)
    v = velocity(gt, ev, max_gap_ns)
    r = valid_rows(robot.xyz, ev) - ev.gt_xyz
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
    estimate = OffsetEstimate(
        offset_ns, round(sigma * NS_PER_S), search_range_ns, used, mean_err, zero, "; ".join(notes)
    )
    return estimate, pending


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
