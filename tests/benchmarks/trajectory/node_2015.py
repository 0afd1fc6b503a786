"""The arithmetic of the 2015 offline trajectory benchmark, re-implemented for the tests.

From ``rockin_trajectory_benchmark.py`` (rockin_offline_trajectory_benchmark, seed footnote 15;
read in the public copy Enri2077/rockin_offline_trajectory_benchmark), written again here as
plain per-pose Python loops over lists so the tests can check ertools' ``--2015`` against it
without using any of ertools' code:

- the GT files (sorted by their start time) are chained into one message sequence in record
  order; a "dual iterator" walks it as pairs (p1, p2) starting at (GT[0], GT[1]);
- for each robot pose, in the robot bag's record order, with time t (its header stamp):
  advance the pair while ``p2.t < t`` (rospy Time comparison: exact); running out of GT poses
  is the ``EndOfBagError`` error (exit 6: no score at all);
- ``t1 <= t <= t2`` false (float seconds) prints "[ERROR] ... This should never happen" and goes
  on (the robot pose lies before the first GT pose);
- ``t2.to_sec() - t1.to_sec() > 0.1`` prints a warning and goes on (a GT gap);
- p1 and p2 with exactly equal positions: tracking lost, the robot pose is skipped;
- otherwise compared with p1: 3D distance, and ``|r_theta - m_theta|`` with both yaws from
  ``tf.transformations.euler_from_quaternion`` (axes ``sxyz``), not wrapped;
- position error = sum of distances / n; orientation error = atan2(sum sin|d|, sum cos|d|),
  the sums accumulated one pose at a time.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

NS = 1_000_000_000
# tf.transformations._EPS
TF_EPS = 2.220446049250313e-16 * 4.0

Pose = tuple[int, Sequence[float], Sequence[float]]  # (stamp ns, (x, y, z), (qx, qy, qz, qw))


class EndOfBagError(Exception):
    """The GT ran out before a robot pose (2015: '[ERROR] mocap bags are missing', exit 6)."""


@dataclass(frozen=True)
class Result2015:
    position_error: float | None
    orientation_error: float | None
    n: int
    tracking_lost: int  # '[INFO] ignoring pose ... (tracking was lost)' lines
    gap_warnings: int  # 'consecutive mocap poses very distant in time, used to calculate...'
    gap_compared: int  # of those, the robot poses then compared (not tracking lost)
    never_happen: int  # '[ERROR] ... This should never happen' lines (before the first GT)


def to_sec(t_ns: int) -> float:
    """rospy ``Time.to_sec()``: float(secs) + float(nsecs) / 1e9."""
    return float(t_ns // NS) + float(t_ns % NS) / 1e9


def tf_yaw(q: Sequence[float]) -> float:
    """``tf.transformations.euler_from_quaternion(q)[2]``: quaternion_matrix, then sxyz."""
    x, y, z, w = (float(v) for v in q)
    nq = x * x + y * y + z * z + w * w
    if nq < TF_EPS:
        return 0.0  # quaternion_matrix returns the identity
    s = math.sqrt(2.0 / nq)
    x, y, z, w = x * s, y * s, z * s, w * s
    m00 = 1.0 - y * y - z * z  # 1 - q[1,1] - q[2,2] of outer(q, q)
    m10 = x * y + z * w  # q[0,1] + q[2,3]
    cy = math.sqrt(m00 * m00 + m10 * m10)
    if cy > TF_EPS:
        return math.atan2(m10, m00)
    return 0.0


def score_2015(robot: Sequence[Pose], gt_files: Sequence[Sequence[Pose]]) -> Result2015:
    """The trajectory part of the 2015 script (raises :class:`EndOfBagError` like its exit 6).

    ``gt_files`` are already in the order the script opened them (by bag start time), each in
    record order.
    """
    chain = [p for f in gt_files for p in f]
    if len(chain) < 2:
        raise EndOfBagError  # DualIterator's constructor calls next() twice
    i = 0  # the pair is (chain[i], chain[i + 1])
    n = 0
    sum_d = 0.0
    sum_sin = 0.0
    sum_cos = 0.0
    lost = warn = warn_compared = never = 0
    for t, rxyz, rq in robot:
        while chain[i + 1][0] < t:
            if i + 2 >= len(chain):
                raise EndOfBagError
            i += 1
        (t1, m1, q1), (t2, m2, _q2) = chain[i], chain[i + 1]
        if not (to_sec(t1) <= to_sec(t) <= to_sec(t2)):
            never += 1
        gap = to_sec(t2) - to_sec(t1) > 0.1
        warn += gap
        if m1[0] == m2[0] and m1[1] == m2[1] and m1[2] == m2[2]:
            lost += 1
            continue
        warn_compared += gap
        n += 1
        sum_d += math.sqrt((rxyz[0] - m1[0]) ** 2 + (rxyz[1] - m1[1]) ** 2 + (rxyz[2] - m1[2]) ** 2)
        d = math.fabs(tf_yaw(rq) - tf_yaw(q1))
        sum_sin += math.sin(d)
        sum_cos += math.cos(d)
    return Result2015(
        position_error=sum_d / n if n else None,
        orientation_error=math.atan2(sum_sin, sum_cos) if n else None,
        n=n,
        tracking_lost=lost,
        gap_warnings=warn,
        gap_compared=warn_compared,
        never_happen=never,
    )
