"""The clock offset's effect on the statistics where no shift moves a pose across a loss
(issue 39): the GT moves along its velocity, no re-association.

Shifting the offset by ``delta`` moves each compared robot pose's GT point along the GT's
path: the error becomes ``e - delta v`` and the yaw difference ``theta - delta omega`` (v,
omega the GT's velocity and yaw rate around the pose). Where, within the offset grid's reach,
no pose can change status (every robot pose near the GT compared, at most one GT sample
crossed either side, the neighbouring GT pairs neither repeated nor a gap) and the
association is ``linear``, the statistics at every shift follow from per-pose sums, on every
compared pose: the mean square exactly (a quadratic in ``delta``), the mean distance and the
circular means by Taylor series (the few poses near a fold of ``|x|``, or whose error is small
against the reach, computed exactly), the max and percentiles on the poses that can move
them (:func:`~ertools.benchmarks.common.draws.order_stats`). Otherwise (:func:`effects`
returns None) the score's own association re-scores a subsample at every shift.
"""

from __future__ import annotations

import math
from typing import Protocol

import numpy as np
import numpy.typing as npt

from ertools.arrays import F64, IntArr
from ertools.benchmarks.common.draws import order_stats
from ertools.benchmarks.trajectory.association import COMPARED

# A pose whose error is within this many times its reach (the shift's displacement) is
# evaluated exactly: the series of sqrt(1 + x) then has |x| <= 0.21, and its 5th order term
# stays below 2e-5 of the distance.
MARGIN = 10.0
# The largest turn (rad) within reach for the yaw's series, whose 9th order term is then
# below 3e-9 of a term.
MAX_TURN = 0.5
TRIG_ORDER = 8


def _taylor_sqrt(d: F64, a: F64, b: F64, shifts: F64) -> F64:
    """sum_i sqrt(d_i^2 - 2 s a_i + s^2 b_i) for each shift s, to 4th order in s: with
    p = a / d^2 and r = b / d^2, d (1 - s p + s^2 (r - p^2) / 2 + s^3 p (r - p^2) / 2
    + s^4 (-r^2 / 8 + 3 p^2 r / 4 - 5 p^4 / 8))."""
    inv = 1.0 / (d * d)
    p, r = a * inv, b * inv
    p2 = p * p
    half = 0.5 * (r - p2)
    dp = d * p
    c4 = r * (-0.125 * r + 0.75 * p2) - 0.625 * p2 * p2
    coef = (np.sum(d), -np.sum(dp), np.sum(d * half), np.sum(dp * half), np.sum(d * c4))
    return np.asarray(sum(float(c) * shifts**k for k, c in enumerate(coef)), dtype=np.float64)


def _trig_sums(pairs: list[tuple[F64, F64]], rate: F64, shifts: F64) -> list[F64]:
    """For each (first, second) of ``pairs``: sum_i first_i cos(s rate_i) + second_i
    sin(s rate_i) at each shift s, by the series to the order where the next term is below
    1e-12 of a term (|s rate| <= MAX_TURN); the powers of the rate shared."""
    x = float(np.max(np.abs(shifts))) * float(np.max(np.abs(rate), initial=0.0))
    order = 1
    while order < TRIG_ORDER and x ** (order + 1) / math.factorial(order + 1) > 1e-12:
        order += 1
    out = [np.zeros(len(shifts)) for _ in pairs]
    power = np.ones_like(rate)
    for k in range(order + 1):
        sign = -1.0 if (k // 2) % 2 else 1.0
        scale = sign / math.factorial(k) * shifts**k
        for total, (first, second) in zip(out, pairs, strict=True):
            total += float(np.sum((first if k % 2 == 0 else second) * power)) * scale
        if k < order:
            power = power * rate
    return out


def clear_of_losses(
    q: npt.NDArray[np.int64],
    status: npt.NDArray[np.uint8],
    t_robot: npt.NDArray[np.int64],
    gt_t: npt.NDArray[np.int64],
    gt_xyz: F64,
    k: IntArr,
    reach_ns: int,
    max_gap_ns: int,
) -> bool:
    """Whether no shift within ``reach_ns`` changes a robot pose's status (module doc):
    ``q`` the compared poses' GT times, ``k`` their GT samples at or before (the pair k, k+1),
    ``status``/``t_robot`` every robot pose's."""
    n = len(gt_t)
    near = (t_robot >= gt_t[0] - reach_ns) & (t_robot <= gt_t[-1] + reach_ns)
    if np.any(near & (status != COMPARED)) or np.any(k < 1) or np.any(k + 2 > n - 1):
        return False
    # the samples k-1 .. k+2 of every pose, in one gather
    rows = (k[:, None] + np.arange(-1, 3)).reshape(-1)
    tt = np.take(gt_t, rows).reshape(-1, 4)
    # at most one GT sample crossed either side
    if np.any(q - tt[:, 0] <= reach_ns) or np.any(tt[:, 3] - q <= reach_ns):
        return False
    # the pairs (k-1, k) and (k+1, k+2) only: (k, k+1) is the pose's own, checked already
    if np.any(tt[:, 1] - tt[:, 0] > max_gap_ns) or np.any(tt[:, 3] - tt[:, 2] > max_gap_ns):
        return False
    # tracking lost: a pair of equal positions, as the association finds them; the pairs
    # whose x repeat first (a column gathered, not rows), their whole rows then
    x = np.take(np.ravel(gt_xyz), 3 * rows).reshape(-1, 4)
    sus = np.concatenate([k[x[:, 1] == x[:, 0]] - 1, k[x[:, 3] == x[:, 2]] + 1])
    return not np.any(np.all(gt_xyz[sus + 1] == gt_xyz[sus], axis=1))


class Moving(Protocol):
    """Per compared pose: the error (n, 3), the GT's velocity (n, 3) and yaw rate (n,),
    the wrapped and 2015 yaw differences (n,), and the error's norms (n,)."""

    @property
    def error(self) -> F64: ...
    @property
    def velocity(self) -> F64: ...
    @property
    def yaw_rate(self) -> F64: ...
    @property
    def theta(self) -> F64: ...
    @property
    def raw(self) -> F64: ...
    def norms(self) -> F64: ...


def effects(
    poses: Moving,
    thinned: IntArr,
    shifts: F64,
    wanted: tuple[tuple[int, float], ...],
    columns: int,
    mean_cols: tuple[int, int, int, int],
) -> F64 | None:
    """(shifts, columns) change of each statistic at each shift (s) under the GT's motion;
    None where the yaw turns too far within reach for its series. ``mean_cols``: the
    columns of the mean distance, orientation error, RMSE and 2015 orientation error;
    ``wanted`` the order statistics as :func:`order_stats` takes them."""
    error, velocity, yaw_rate = poses.error, poses.velocity, poses.yaw_rate
    theta, raw = poses.theta, poses.raw
    reach = float(np.max(np.abs(shifts)))
    if reach * float(np.max(np.abs(yaw_rate), initial=0.0)) > MAX_TURN:
        return None
    s = np.concatenate([[0.0], shifts])
    n = len(error)
    a = error[:, 0] * velocity[:, 0] + error[:, 1] * velocity[:, 1] + error[:, 2] * velocity[:, 2]
    b = velocity[:, 0] ** 2 + velocity[:, 1] ** 2 + velocity[:, 2] ** 2
    d = poses.norms()
    move = reach * np.sqrt(b)

    def exact(rows: IntArr) -> F64:
        sq = d[rows] ** 2 - 2.0 * s[:, None] * a[rows] + s[:, None] ** 2 * b[rows]
        return np.asarray(np.sqrt(np.maximum(sq, 0.0)), dtype=np.float64)

    out = np.zeros((len(s), columns))
    close = d <= MARGIN * move
    far = np.flatnonzero(~close)
    dist_sum = _taylor_sqrt(d[far], a[far], b[far], s) + exact(np.flatnonzero(close)).sum(axis=1)
    mean_d, orient, rmse, o2015 = mean_cols
    out[:, mean_d] = dist_sum / n
    out[:, rmse] = np.sqrt(
        np.maximum(np.mean(d * d) - 2.0 * s * np.mean(a) + s * s * np.mean(b), 0)
    )
    turn = reach * np.abs(yaw_rate)
    # 2015's difference is the wrapped one unwrapped (the same up to 2 pi and rounding)
    sn, cs = np.sin(theta), np.cos(theta)
    pairs = [(cs, sn)]  # cos x for both: the sums of cos(theta - s omega)
    folds = []
    for angle, wrapped in ((theta, True), (raw, False)):
        # the sine of |x| folds where sin x (wrapped: |x| <= pi) or x (2015) crosses 0;
        # both move by at most the turn within reach. A fold's pose is summed exactly,
        # the others' sin|x| = sign sin x by the series (weights 0 at the folds)
        fold_at = np.abs(sn) if wrapped else np.abs(angle)
        sign = np.sign(sn) if wrapped else np.sign(angle)
        fold = fold_at <= turn
        sign[fold] = 0.0
        pairs.append((sign * sn, -sign * cs))
        folds.append(np.flatnonzero(fold))
    cos_sum, *sin_sums = _trig_sums(pairs, yaw_rate, s)
    for col, angle, wrapped, rows, sin_sum in zip(
        (orient, o2015), (theta, raw), (True, False), folds, sin_sums, strict=True
    ):
        if len(rows):
            x = angle[rows][None, :] - s[:, None] * yaw_rate[rows][None, :]
            sin_sum += (np.abs(np.sin(x)) if wrapped else np.sign(x) * np.sin(x)).sum(axis=1)
        out[:, col] = np.arctan2(sin_sum, cos_sum)
    stats, _ = order_stats(d, thinned, move, wanted)
    for st in stats:
        # the band's values at each shift, sorted: the statistic interpolates two ranks
        ranked = np.sort(exact(st.poses), axis=1)
        low = ranked[:, st.low]
        value = low + st.fraction * (ranked[:, st.high] - low)
        for col in st.columns:
            out[:, col] = value
    return np.asarray(out[1:] - out[0], dtype=np.float64)
