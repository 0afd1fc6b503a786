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

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import numpy.typing as npt

from ertools.streams import PoseStream
from ertools.timeutil import NS_PER_S

F64 = npt.NDArray[np.float64]
I64 = npt.NDArray[np.int64]

COARSE_STEP_NS = 20_000_000  # 20 ms: at 1 m/s a 2 cm change of the cost, well resolved
FINE_STEP_NS = 1_000_000
GRID_NS = COARSE_STEP_NS // 2
GRID_MAX_POINTS = 1_000_000  # 12 MB of grid positions at most; a longer GT gets a coarser grid
COARSE_MAX_POSES = 3000
MIN_POSES = 20
MIN_RMS_SPEED = 0.02  # m/s: below this the robot stood still and no offset is observable
BOOTSTRAP_DRAWS = 500
BLOCK_NS = 5 * NS_PER_S


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


@dataclass(frozen=True, eq=False)
class _Eval:
    """GT positions and velocities at shifted robot times, and which of them are usable."""

    valid: npt.NDArray[np.bool_]
    gt_xyz: F64
    gt_vel: F64


def drop_repeats(gt: PoseStream) -> PoseStream:
    """GT without the samples that repeat the previous position (mocap tracking lost).

    Motive repeats the last pose while it has lost the rigid body; interpolating across the
    repeated samples would pretend the body stood still. Dropping them turns the loss into a
    gap, which the max-gap rule then excludes.
    """
    if len(gt) < 2:
        return gt
    keep = np.ones(len(gt), dtype=bool)
    keep[1:] = np.any(gt.xyz[1:] != gt.xyz[:-1], axis=1)
    return gt if keep.all() else gt.take(keep)


def _evaluate(gt: PoseStream, query_ns: I64, max_gap_ns: int) -> _Eval:
    t = gt.t_ns
    n = len(t)
    hi = np.searchsorted(t, query_ns, side="left")
    lo = np.searchsorted(t, query_ns, side="right") - 1
    inside = (lo >= 0) & (hi < n)
    lo_c = np.clip(lo, 0, n - 1)
    hi_c = np.clip(hi, 0, n - 1)
    # Velocity of the segment around the query; at an exact hit, of the segment after it.
    seg_lo = np.clip(lo_c, 0, max(n - 2, 0))
    seg_hi = np.minimum(seg_lo + 1, n - 1)
    span = t[hi_c] - t[lo_c]
    valid = inside & (span <= max_gap_ns)
    dt = (t[seg_hi] - t[seg_lo]).astype(np.float64) / NS_PER_S
    with np.errstate(invalid="ignore", divide="ignore"):
        vel = np.where(dt[:, None] > 0, (gt.xyz[seg_hi] - gt.xyz[seg_lo]) / dt[:, None], 0.0)
        alpha = np.where(span > 0, (query_ns - t[lo_c]).astype(np.float64) / span, 0.0)
    alpha = np.clip(alpha, 0.0, 1.0)
    xyz = gt.xyz[lo_c] + alpha[:, None] * (gt.xyz[hi_c] - gt.xyz[lo_c])
    # Segments longer than the max gap give no usable velocity either.
    seg_ok = (t[seg_hi] - t[seg_lo]) <= max_gap_ns
    return _Eval(valid, xyz, np.where(seg_ok[:, None], vel, 0.0))


def _mean_error(
    robot_t: I64, robot_xyz: F64, gt: PoseStream, offset_ns: int, max_gap_ns: int
) -> tuple[float, int]:
    ev = _evaluate(gt, robot_t + offset_ns, max_gap_ns)
    if not ev.valid.any():
        return float("inf"), 0
    d = np.linalg.norm(robot_xyz[ev.valid] - ev.gt_xyz[ev.valid], axis=1)
    return float(d.mean()), int(ev.valid.sum())


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
    grid_t = t[0] + np.arange(span // step + 1, dtype=np.int64) * step
    rel_t = (t - t[0]).astype(np.float64)
    rel_g = (grid_t - t[0]).astype(np.float64)
    # float32 grid: 0.1 um resolution at 10 m, and half the memory of an hour's grid.
    grid_xyz = np.empty((len(grid_t), 3), dtype=np.float32)
    for k in range(3):
        grid_xyz[:, k] = np.interp(rel_g, rel_t, gt.xyz[:, k])
    del rel_t, rel_g
    # Grid points strictly inside a GT gap longer than max_gap_ns are invalid: mark them per
    # gap (a handful) instead of locating every grid point in the GT. The first grid point
    # is the first GT sample; it is judged by the first GT interval, as it always was.
    gaps = np.flatnonzero(np.diff(t) > max_gap_ns)
    marks = np.zeros(len(grid_t) + 1, dtype=np.int64)
    np.add.at(marks, np.searchsorted(grid_t, t[gaps], side="right"), 1)
    np.add.at(marks, np.searchsorted(grid_t, t[gaps + 1], side="left"), -1)
    grid_ok = np.cumsum(marks[:-1]) == 0
    grid_ok[0] = (t[1] - t[0]) <= max_gap_ns or t[1] == t[0]
    del marks, gaps
    base = np.rint((robot_t - t[0]) / step).astype(np.int64)
    shifts = np.rint(offsets / step).astype(np.int64)
    # Invalid points become NaN and the grid is padded with NaN beyond both ends, so every
    # shifted index is in range and one gather gives both the position and its validity.
    pad = int(max(0, -(shifts.min() + base.min()), shifts.max() + base.max() - len(grid_t) + 1))
    padded = np.full((len(grid_t) + 2 * pad, 3), np.nan, dtype=np.float32)
    padded[pad : pad + len(grid_t)] = np.where(grid_ok[:, None], grid_xyz, np.nan)
    del grid_xyz, grid_ok, grid_t
    base += pad
    pos = robot_xyz.astype(np.float32)
    costs = np.full(len(offsets), np.inf)
    counts = np.zeros(len(offsets), dtype=np.int64)
    block = max(1, 200_000 // max(len(base), 1))  # ~2.4 MB of float32 per block
    for lo in range(0, len(offsets), block):  # blocks of offsets x all poses, vectorised
        d = padded[shifts[lo : lo + block, None] + base[None, :]] - pos[None, :, :]
        dist = np.sqrt(np.einsum("bij,bij->bi", d, d))
        ok = ~np.isnan(dist)
        cnt = ok.sum(axis=1)
        total = np.where(ok, dist, 0.0).sum(axis=1)
        with np.errstate(invalid="ignore", divide="ignore"):
            costs[lo : lo + block] = np.where(cnt > 0, total / np.maximum(cnt, 1), np.inf)
        counts[lo : lo + block] = cnt
    enough = counts >= max(MIN_POSES, int(0.5 * counts.max()))
    return np.where(enough, costs, np.inf)


def _scan(
    robot_t: I64, robot_xyz: F64, gt: PoseStream, offsets: I64, max_gap_ns: int
) -> tuple[F64, I64]:
    costs = np.empty(len(offsets))
    counts = np.empty(len(offsets), dtype=np.int64)
    for i, off in enumerate(offsets):  # a loop over offsets, each vectorised over poses
        costs[i], counts[i] = _mean_error(robot_t, robot_xyz, gt, int(off), max_gap_ns)
    # An offset that leaves few poses inside the GT could win by chance: require at least
    # half of the best coverage any offset achieves.
    enough = counts >= max(MIN_POSES, int(0.5 * counts.max()))
    costs = np.where(enough, costs, np.inf)
    return costs, counts


def estimate_offset(
    robot: PoseStream,
    gt: PoseStream,
    *,
    search_range_ns: int = 5 * NS_PER_S,
    max_gap_ns: int = NS_PER_S // 10,
    seed: int = 0,
) -> OffsetEstimate:
    """Estimate the offset to add to ``robot`` stamps to align them with ``gt``.

    Args:
        robot: the robot's own poses of its marker set (stamps on the robot clock).
        gt: the mocap poses of the same marker set (stamps on the GT clock).
        search_range_ns: search offsets within +- this.
        max_gap_ns: GT samples further apart than this are not interpolated across.
        seed: of the bootstrap's random generator (the result is deterministic).
    """
    gt = drop_repeats(gt)
    at_zero = _mean_error(robot.t_ns, robot.xyz, gt, 0, max_gap_ns) if len(gt) >= 2 else None
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

    # 3. Gauss-Newton on the squared distances
    for _ in range(5):
        ev = _evaluate(gt, robot.t_ns + round(offset), max_gap_ns)
        v = ev.gt_vel[ev.valid]
        r = robot.xyz[ev.valid] - ev.gt_xyz[ev.valid]
        vv = float(np.sum(v * v))
        if vv <= 0:
            break
        step_s = float(np.sum(r * v)) / vv
        offset += step_s * NS_PER_S
        if abs(step_s) < 1e-6:
            break
    offset_ns = round(offset)
    ev = _evaluate(gt, robot.t_ns + offset_ns, max_gap_ns)
    used = int(ev.valid.sum())
    if used < MIN_POSES:
        return none("too few robot poses overlap the GT at the estimated offset", used)
    v = ev.gt_vel[ev.valid]
    r = robot.xyz[ev.valid] - ev.gt_xyz[ev.valid]
    rms_speed = _rms_speed(robot.t_ns[ev.valid], ev.gt_xyz[ev.valid])
    if rms_speed < MIN_RMS_SPEED:
        return none(
            f"the robot barely moved (RMS speed {rms_speed * 100:.1f} cm/s): "
            "no clock offset is observable",
            used,
        )
    mean_err = float(np.mean(np.linalg.norm(r, axis=1)))
    sigma = _bootstrap_sigma(robot.t_ns[ev.valid], r, v, seed)
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
    step = np.linalg.norm(np.diff(xyz, axis=0), axis=1)
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
    a = np.bincount(block, weights=np.sum(r * v, axis=1), minlength=nb)
    b = np.bincount(block, weights=np.sum(v * v, axis=1), minlength=nb)
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
    return float(np.std(num[ok] / den[ok]))


# Record time minus header stamp of mocap poses is a few ms on one machine (0.3 ms in the real
# 2015 log); a quarter second means two clocks disagree, enough to move a robot at 0.5 m/s by
# 12 cm between the moment the states name and the pose taken for it.
HEADER_CLOCK_TOLERANCE_NS = NS_PER_S // 4


def check_header_clock(
    paths: Sequence[str | Path],
    poses: PoseStream,
    states_what: str,
    tolerance_ns: int = HEADER_CLOCK_TOLERANCE_NS,
) -> None:
    """Refuse poses timed by header stamps that disagree with the bag's record times.

    Benchmark states (and timing files) are timed by record time; poses by default by their
    header stamp. When the two clocks differ by more than ``tolerance_ns``, every pose taken
    "at" a state moment is another moment's pose: a wrong score that looks right.

    Raises:
        ClockError: naming the file, the topic, the offset and the way out.
    """
    from ertools.errors import ClockError
    from ertools.io import summary
    from ertools.timeline_scan import clock_check

    cut = poses.source.rfind(":/")
    topic = poses.source[cut + 1 :] if cut >= 0 else ""
    if not topic or topic in ("/tf", "/tf_static"):
        return  # tf mixes publishers (static transforms are stamped otherwise): not checked
    for path in paths:
        check = clock_check(summary(path), topic_name=topic)
        if check is None or check.error or not check.samples:
            continue
        if abs(check.offset_ns) > tolerance_ns:
            ahead = -check.offset_ns / NS_PER_S
            raise ClockError(
                f"{path}:{topic}: header stamps are {ahead:+.3f} s off the record times "
                f"(median of {check.samples} messages), but the {states_what} are timed by "
                "record time: the mocap and logger clocks disagree; re-run with "
                "--time-source record"
            )
