"""Each robot pose paired with the GT (hold | nearest | linear), with its status: compared, in a GT
gap, while mocap tracking was lost (repeated GT poses), or outside the GT. Or evo's pairing
(:func:`associate_evo`, ``--t-max-diff``): nearest stamps within a limit, nothing else.

Also :func:`yaw_tf`, the yaw as the 2015 script computed it (tf.transformations' arithmetic).
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from ertools.arrays import F64, I64, U8
from ertools.benchmarks.common.hygiene import same_rows
from ertools.benchmarks.trajectory.inputs import BeforeGt, Gaps, GtOrder, Ties
from ertools.errors import ScoringError
from ertools.frozen_dataclass import frozen_dataclass
from ertools.geometry import (
    Association,
    interpolate_poses,
    row_norm,
    wrap_angle,
    yaw_from_quat,
)
from ertools.streams import PoseStream

# Per-pose status codes of the association.
COMPARED, GAP, TRACKING_LOST, UNCOVERED, UNPAIRED = 0, 1, 2, 3, 4
STATUS_NAMES = ("compared", "gap", "tracking_lost", "uncovered", "unpaired")


@frozen_dataclass(eq=False)
class Matched:
    """Robot poses and their GT counterparts.

    Attributes:
        t_ns: (N,) robot times on the GT clock (stamps + offset).
        status: (N,) COMPARED, GAP, TRACKING_LOST or UNCOVERED.
        gt_xyz, gt_yaw: GT at each robot time (NaN unless compared).
        position_error: (N,) 3D distance, metres (NaN unless compared).
        yaw_error: (N,) |wrap(yaw_robot - yaw_gt)|, radians (NaN unless compared).
        yaw_diff_raw: (N,) yaw_robot - yaw_gt unwrapped, both yaws by tf's arithmetic, as
            2015 used it (NaN unless compared).
        exact_ties: robot poses stamped exactly at a GT sample.
        across_gap: (N,) the robot pose lies in a GT gap longer than the max gap (compared
            or not, as the ``gaps`` setting says).
        before_gt: robot poses before the first GT pose.
        gt_quat_xyzw: (N, 4) the GT orientation of each compared row (NaN otherwise), kept
            by :func:`associate_evo`, whose pairs cannot be recomputed from the robot times
            alone (None for the other associations).
        robot_rows: with :func:`associate_evo`, the robot pose of each row (a robot pose
            that evo pairs with two GT poses is two rows); None: row i is robot pose i.
        gt_lo: (N,) with :func:`associate` over GT in time order, the last GT sample at or
            before each row's time (-1 before the first): its binary search, kept for the
            intervals (:func:`~ertools.benchmarks.trajectory.intervals.trajectory_intervals`,
            given the same GT); None: not kept.
        yaw_diff: (N,) wrap(yaw_robot - yaw_gt), signed (``yaw_error`` is its absolute
            value), kept by :func:`associate` for the intervals; None: not kept.
    """

    t_ns: I64
    status: U8
    gt_xyz: F64
    gt_yaw: F64
    position_error: F64
    yaw_error: F64
    yaw_diff_raw: F64
    exact_ties: int
    across_gap: npt.NDArray[np.bool_]
    before_gt: int
    gt_quat_xyzw: F64 | None = None
    robot_rows: npt.NDArray[np.intp] | None = None
    gt_lo: npt.NDArray[np.intp] | None = None
    yaw_diff: F64 | None = None

    def count(self, status: int) -> int:
        return int(np.count_nonzero(self.status == status))

    @property
    def gaps_compared(self) -> int:
        """Robot poses compared with a GT pose across a GT gap (``gaps`` ``compare``)."""
        return int(np.count_nonzero(self.across_gap & (self.status == COMPARED)))


def associate(
    robot: PoseStream,
    gt: PoseStream,
    method: Association,
    max_gap_ns: int,
    *,
    ties: Ties = "at",
    gaps: Gaps = "skip",
    before_gt: BeforeGt = "uncovered",
    gt_order: GtOrder = "time",
) -> Matched:
    """Pair every robot pose with the GT pose at its time.

    Rules, in this order: a robot pose after the last GT pose is UNCOVERED, and so is one
    before the first unless ``before_gt`` is ``first`` (then it is held at the first GT pose,
    as 2015 did). One whose surrounding GT poses are more than ``max_gap_ns`` apart lies in a
    GT gap: a GAP, not compared, unless ``gaps`` is ``compare`` (2015). One whose GT pair
    (the first GT pose at or after it and the one before that, the 2015 pair) has the same
    position is TRACKING_LOST; every other pose is COMPARED against the GT pose given by
    ``method``.

    The surrounding GT poses are the last at or before and the first at or after the robot
    time (one sample on an exact tie); with ``ties`` ``before`` (hold only) they are the 2015
    pair on ties too, and ``hold`` takes the first of the pair: the pose before the tie.

    ``gt_order`` ``chain`` (hold with ties before only): ``gt`` is in the order 2015 read it
    (its files chained by start time, not sorted), and the pair is the one its forward scan
    stopped at (:func:`chain_pairs`).
    """
    if len(gt) == 0:
        raise ScoringError("the GT stream is empty")
    if gt_order == "chain":
        return _associate_chain(robot, gt, max_gap_ns, gaps=gaps, before_gt=before_gt)
    n_gt = len(gt)
    q = robot.t_ns
    interp = interpolate_poses(gt, q, method)
    before = interp.hi == 0  # the first GT pose is at or after the robot time
    early = before & (q < gt.t_ns[0])
    # The 2015 pair (GT[k-1], GT[k]): k the first GT pose at or after the robot time; the
    # 2015 script started its scan at the pair (GT[0], GT[1]), so k is at least 1 there.
    second = interp.hi
    if ties == "before" or before_gt == "first":
        widen = early if ties == "at" else before
        second = np.where(widen, 1, second)
    first = second - 1
    has_pair = (first >= 0) & (second < n_gt)
    fi, si = np.clip(first, 0, n_gt - 1), np.clip(second, 0, n_gt - 1)
    inside = interp.inside | (early if before_gt == "first" else False)
    if ties == "before":
        pair_gap = gt.t_ns.take(si) - gt.t_ns.take(fi)
        gap_ns = np.where(has_pair, pair_gap, np.iinfo(np.int64).max)
        gt_xyz_at = _rows(gt.xyz, fi)
        gt_quat_at = _rows(gt.quat_xyzw, fi)
    else:
        gap_ns = interp.gap_ns
        if before_gt == "first" and n_gt > 1:
            # Held at the first GT pose: the pair around it is (GT[0], GT[1]), as in 2015.
            gap_ns = np.where(early, int(gt.t_ns[1] - gt.t_ns[0]), gap_ns)
        gt_xyz_at, gt_quat_at = interp.xyz, interp.quat_xyzw
    ties_n = int(np.count_nonzero(interp.inside & (interp.lo == interp.hi)))
    return _matched(
        robot,
        gt,
        gt_xyz_at,
        gt_quat_at,
        inside,
        gap_ns,
        has_pair,
        fi,
        si,
        early,
        ties_n,
        max_gap_ns,
        gaps,
        gt_lo=interp.lo,
    )


def chain_pairs(gt_t_ns: I64, q: I64) -> I64:
    """The second index ``j`` of the pair (``j - 1``, ``j``) 2015's scan stopped at for each
    robot time of ``q`` (increasing), over GT stamps in the order read (not sorted).

    rockin_trajectory_benchmark.py (``seek_mocap_pose_at``) starts at the pair (GT[0], GT[1])
    and moves one pose forward while the second's stamp is before the robot time, never back:
    for increasing robot times it stops at the first ``j >= 1`` with ``t[j] >= q``, whatever
    came before, so ``j`` is where the running maximum of ``t[1:]`` first reaches ``q``.
    ``len(gt_t_ns)`` means the poses ran out (2015: ``EndOfBag``).
    """
    reach = np.maximum.accumulate(gt_t_ns[1:])
    return np.searchsorted(reach, q, side="left").astype(np.int64) + 1


def _associate_chain(
    robot: PoseStream, gt: PoseStream, max_gap_ns: int, *, gaps: Gaps, before_gt: BeforeGt
) -> Matched:
    """:func:`associate` over GT poses in 2015's reading order (hold, the pose before a tie)."""
    n_gt = len(gt)
    q = robot.t_ns
    second = chain_pairs(gt.t_ns, q) if n_gt > 1 else np.full(len(q), n_gt, dtype=np.int64)
    has_pair = second < n_gt
    si = np.clip(second, 0, n_gt - 1)
    fi = np.clip(second - 1, 0, n_gt - 1)
    # Before the first pose read: 2015 printed its "should never happen" error and went on.
    early = has_pair & (second == 1) & (q < gt.t_ns[0])
    inside = has_pair & (~early if before_gt == "uncovered" else True)
    # An out-of-order pair spans a negative time: 2015 warned it out of order, not as a gap.
    # Its gap test is ``t2.to_sec() - t1.to_sec() > 0.1`` in float seconds, where a pair 0.1 s
    # apart can be 0.10000000000000003 s: the test is kept as written.
    span_s = _to_sec(gt.t_ns.take(si)) - _to_sec(gt.t_ns.take(fi))
    gap = has_pair & (span_s > max_gap_ns / 1e9)
    gap_ns = np.where(gap | ~has_pair, np.iinfo(np.int64).max, 0)
    ties_n = int(np.count_nonzero(has_pair & (gt.t_ns.take(si) == q)))
    return _matched(
        robot,
        gt,
        _rows(gt.xyz, fi),
        _rows(gt.quat_xyzw, fi),
        inside,
        gap_ns,
        has_pair,
        fi,
        si,
        early,
        ties_n,
        max_gap_ns,
        gaps,
    )


def _to_sec(t_ns: I64) -> F64:
    """rospy's ``Time.to_sec()``: float(secs) + float(nsecs) / 1e9."""
    return np.asarray((t_ns // 1_000_000_000).astype(np.float64) + (t_ns % 1_000_000_000) / 1e9)


def _matched(
    robot: PoseStream,
    gt: PoseStream,
    gt_xyz_at: F64,
    gt_quat_at: F64,
    inside: npt.NDArray[np.bool_],
    gap_ns: I64,
    has_pair: npt.NDArray[np.bool_],
    fi: npt.NDArray[np.intp],
    si: npt.NDArray[np.intp],
    early: npt.NDArray[np.bool_],
    ties_n: int,
    max_gap_ns: int,
    gaps: Gaps,
    gt_lo: npt.NDArray[np.intp] | None = None,
) -> Matched:
    """Statuses and errors from the GT pose chosen for each robot pose (``gt_lo``: kept,
    :class:`Matched`)."""
    q = robot.t_ns
    status = np.full(len(q), COMPARED, dtype=np.uint8)
    status[~inside] = UNCOVERED
    across = inside & (gap_ns > max_gap_ns)
    if gaps == "skip":
        status[across] = GAP
    # tracking lost: the pair's positions equal; x compared first (a moving body's x rarely
    # repeats), the whole rows only where it does
    # (taken from the flat array: a column's take would copy the whole strided column)
    flat = np.ravel(gt.xyz)
    maybe = np.flatnonzero(has_pair & (flat.take(3 * fi) == flat.take(3 * si)))
    if maybe.size:
        same = np.zeros(len(q), dtype=bool)
        same[maybe] = same_rows(gt.xyz, fi[maybe], si[maybe])
        status[(status == COMPARED) & same] = TRACKING_LOST
    ok = status == COMPARED
    every = bool(ok.all())

    def compared(values: F64) -> F64:
        """``values`` where compared, NaN elsewhere (as they are when every pose is)."""
        return values if every else np.where(ok, values, np.nan)

    gt_yaw_at, gt_yaw_tf = _yaws(gt_quat_at)
    robot_yaw, robot_yaw_tf = _yaws(robot.quat_xyzw)
    gt_yaw = compared(gt_yaw_at)
    pos_err = compared(row_norm(robot.xyz - gt_xyz_at))
    # gt_xyz_at is this association's own array: NaN written into it where not compared
    # rather than into a copy (megabytes of fresh memory on an hour's poses)
    gt_xyz = gt_xyz_at
    if not every:
        gt_xyz[~ok] = np.nan
    yaw_diff = wrap_angle(compared(robot_yaw - gt_yaw))
    yaw_err = np.abs(yaw_diff)
    raw = compared(robot_yaw_tf - gt_yaw_tf)
    return Matched(
        q,
        status,
        gt_xyz,
        gt_yaw,
        pos_err,
        yaw_err,
        raw,
        ties_n,
        across,
        int(early.sum()),
        gt_lo=gt_lo,
        yaw_diff=yaw_diff,
    )


def evo_matches(
    short_s: F64, long_s: F64, max_diff_s: float
) -> tuple[npt.NDArray[np.intp], npt.NDArray[np.intp]]:
    """evo's ``matching_time_indices`` for sorted ``long_s``, vectorised: for each stamp of
    ``short_s`` the nearest stamp of ``long_s`` (the later one only when strictly nearer),
    kept when at most ``max_diff_s`` away. Returns (indices into short, indices into long).

    The same float64 operations in the same order as evo, so a tie or a difference of
    exactly ``max_diff_s`` falls the same way. A long stamp can be the match of several
    short stamps, as in evo.
    """
    n_long = len(long_s)
    if n_long == 0 or len(short_s) == 0:
        empty = np.empty(0, dtype=np.intp)
        return empty, empty
    considered = ~((short_s < long_s[0] - max_diff_s) | (short_s > long_s[-1] + max_diff_s))
    idx = np.minimum(np.searchsorted(long_s, short_s, side="right"), n_long - 1)
    diff_ub = long_s[idx] - short_s
    prev = long_s[np.maximum(idx - 1, 0)]
    diff_lb = np.where(idx > 0, short_s - prev, np.inf)
    take_ub = (diff_ub <= max_diff_s) & (diff_ub < diff_lb)
    take_lb = ~take_ub & (diff_lb <= max_diff_s) & (diff_lb <= diff_ub)
    ok = considered & (take_ub | take_lb)
    best = np.where(take_ub, idx, idx - 1)
    return np.flatnonzero(ok), best[ok].astype(np.intp)


def associate_evo(
    robot: PoseStream,
    gt: PoseStream,
    robot_s: F64,
    gt_s: F64,
    max_diff_s: float,
    offset_s: float,
    offset_ns: int,
) -> Matched:
    """evo's ``associate_trajectories(gt, robot, max_diff, offset_2=offset)`` (what
    ``evo_ape`` runs with ``--t_max_diff`` and ``--t_offset``): the trajectory with fewer poses
    (the robot's on a tie) looks up the nearest stamp of the other, the offset added to the
    robot's stamps (or subtracted from the GT's, whichever is looked up, as evo does).

    Rows are robot poses, in time order; a robot pose is one row per pair it is in (evo
    counts a robot pose the nearest of two GT poses twice), or one UNPAIRED row (no GT pose
    within the limit, or, when the GT looks up, no GT pose chose it). Robot poses more than
    the limit outside the GT's span are UNCOVERED. No gap or tracking-lost rule: evo has none.
    """
    if len(gt) == 0:
        raise ScoringError("the GT stream is empty")
    n_robot = len(robot)
    if n_robot > len(gt):  # evo: second_longer, the GT looks up the robot
        gi, ri = evo_matches(gt_s, robot_s + offset_s, max_diff_s)
    else:
        ri, gi = evo_matches(robot_s, gt_s + -offset_s, max_diff_s)
    order = np.lexsort((gi, ri))
    ri, gi = ri[order], gi[order]
    per_robot = np.bincount(ri, minlength=n_robot)
    rows = np.repeat(np.arange(n_robot, dtype=np.intp), np.maximum(per_robot, 1))
    paired = np.repeat(per_robot > 0, np.maximum(per_robot, 1))
    gt_row = np.full(len(rows), -1, dtype=np.intp)
    gt_row[paired] = gi  # rows and pairs are both sorted by robot pose, then GT pose
    t_ns = robot.t_ns.take(rows) + offset_ns
    lo, hi = float(gt_s[0]), float(gt_s[-1])
    shifted_s = robot_s.take(rows) + offset_s
    outside = (shifted_s < lo - max_diff_s) | (shifted_s > hi + max_diff_s)
    status = np.full(len(rows), UNPAIRED, dtype=np.uint8)
    status[outside] = UNCOVERED
    status[paired] = COMPARED
    ok = paired
    g = np.maximum(gt_row, 0)
    nan3, nan4 = np.full((len(rows), 3), np.nan), np.full((len(rows), 4), np.nan)
    gt_xyz = np.where(ok[:, None], _rows(gt.xyz, g), nan3)
    gt_quat = np.where(ok[:, None], _rows(gt.quat_xyzw, g), nan4)
    r_xyz, r_quat = _rows(robot.xyz, rows), _rows(robot.quat_xyzw, rows)
    gt_yaw = np.where(ok, yaw_from_quat(np.where(ok[:, None], gt_quat, 0.0)), np.nan)
    pos_err = np.where(ok, row_norm(r_xyz - np.where(ok[:, None], gt_xyz, 0.0)), np.nan)
    yaw_err = np.abs(wrap_angle(np.where(ok, yaw_from_quat(r_quat) - gt_yaw, np.nan)))
    safe_q = np.where(ok[:, None], gt_quat, r_quat)
    raw = np.where(ok, yaw_tf(r_quat) - yaw_tf(safe_q), np.nan)
    early = int(np.count_nonzero(outside & (shifted_s < lo)))
    return Matched(
        t_ns,
        status,
        gt_xyz,
        gt_yaw,
        pos_err,
        yaw_err,
        raw,
        0,
        np.zeros(len(rows), dtype=bool),
        early,
        gt_quat_xyzw=gt_quat,
        robot_rows=rows,
    )


# tf.transformations' ``_EPS`` (4 machine epsilons): its gimbal-lock and zero-norm thresholds.
_TF_EPS = float(np.finfo(np.float64).eps) * 4.0


def yaw_tf(quat_xyzw: F64) -> F64:
    """Yaw as ``tf.transformations.euler_from_quaternion(q)[2]`` computes it (2015's scripts).

    tf normalises the quaternion inside its rotation matrix, so a quaternion slightly off unit
    norm gives the yaw of its unit quaternion: atan2(2(xy + zw), w^2 + x^2 - y^2 - z^2), which
    is :func:`ertools.geometry.yaw_from_quat` for a unit quaternion. At gimbal lock (pitch
    +-90 degrees) and for a zero quaternion tf returns a yaw of 0.
    """
    q = np.asarray(quat_xyzw, dtype=np.float64)
    x, y, z, w = q[..., 0], q[..., 1], q[..., 2], q[..., 3]
    with np.errstate(invalid="ignore", divide="ignore"):  # as in the arithmetic below
        return _yaw_tf(q, x * y + z * w, y * y + z * z)


def _yaws(quat_xyzw: F64) -> tuple[F64, F64]:
    """(:func:`~ertools.geometry.yaw_from_quat`, :func:`yaw_tf`) of the same quaternions, bit
    for bit, their common products computed once: yaw_from_quat's ``w * z + x * y`` is tf's
    ``x * y + z * w`` (IEEE addition and multiplication commute exactly), ``y * y + z * z``
    both's."""
    q = np.asarray(quat_xyzw, dtype=np.float64)
    x, y, z, w = q[..., 0], q[..., 1], q[..., 2], q[..., 3]
    xy_zw = x * y + z * w
    yy_zz = y * y + z * z
    yaw = np.asarray(np.arctan2(2.0 * xy_zw, 1.0 - 2.0 * yy_zz))
    return yaw, _yaw_tf(q, xy_zw, yy_zz)


def _yaw_tf(q: F64, xy_zw: F64, yy_zz: F64) -> F64:
    """:func:`yaw_tf` of ``q``, given its ``x * y + z * w`` and ``y * y + z * z``."""
    n = np.einsum("...i,...i->...", q, q)
    with np.errstate(invalid="ignore", divide="ignore"):  # a zero quaternion: set to 0 below
        s = 2.0 / n
        m00 = 1.0 - yy_zz * s
        m10 = xy_zw * s
    out = np.arctan2(m10, m00)
    # tf: identity below _EPS of squared norm; yaw 0 where cos(pitch) (the norm of the
    # matrix's first column in x, y) is at most _EPS. Squares compared: no square root.
    flat = (n < _TF_EPS) | (m00 * m00 + m10 * m10 <= _TF_EPS * _TF_EPS)
    if flat.any():
        out = np.where(flat, 0.0, out)
    return np.asarray(out, dtype=np.float64)


def _rows(a: F64, index: npt.NDArray[np.intp]) -> F64:
    """``a[index]`` for a 2D array (``take`` gathers whole rows)."""
    return np.take(a, index, axis=0)
