"""Sample hygiene shared by the benchmarks, each test written once: repeated poses (mocap
tracking lost, samples recorded twice), poses that cannot be compared (NaN, infinite, zero
quaternions), poses no body can have taken (kilometres away, or reached faster than any robot:
:func:`impossible_samples`) and frame names that change mid-log. Frozen stretches around the
moments a benchmark scores are :mod:`ertools.benchmarks.common.frozen`'s.

Every repeat test is exact float equality of whole rows (:func:`rows_equal`): real mocap
measurements never repeat a float64 coordinate, so an equal row is a re-sent pose.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
import numpy.typing as npt

from ertools.arrays import F64, Bool, distinct, median
from ertools.frozen_dataclass import frozen_dataclass
from ertools.geometry import row_norm
from ertools.streams import MAX_FRAME_CHANGES, PoseStream
from ertools.timeutil import iso_utc


def rows_equal(a: F64, b: F64) -> Bool:
    """``np.all(a == b, axis=1)`` for two (N, k) arrays, column by column.

    No (N, k) temporary reduced over its short axis: 3-4x faster on an hour of 120 Hz poses.
    """
    same: Bool = a[:, 0] == b[:, 0]
    for k in range(1, a.shape[1]):
        same &= a[:, k] == b[:, k]
    return same


def same_rows(a: F64, i: npt.NDArray[np.intp], j: npt.NDArray[np.intp]) -> Bool:
    """``np.all(a[i] == a[j], axis=1)``: whole rows gathered by ``take``, compared by column."""
    return rows_equal(np.take(a, i, axis=0), np.take(a, j, axis=0))


def repeated_positions(poses: PoseStream) -> Bool:
    """(N-1,) True where a position repeats the previous one exactly (orientation aside)."""
    if len(poses) < 2:
        return np.zeros(0, dtype=bool)
    x = poses.xyz
    # x first, y and z only where x repeats (a moving body's x rarely does): one pass over
    # an hour of 120 Hz poses instead of three
    same: Bool = x[1:, 0] == x[:-1, 0]
    at = np.flatnonzero(same)
    if at.size:
        same[at] = rows_equal(x[at + 1, 1:], x[at, 1:])
    return same


def identical_poses(poses: PoseStream) -> Bool:
    """(N-1,) True where a pose repeats the previous one exactly (position and orientation)."""
    if len(poses) < 2:
        return np.zeros(0, dtype=bool)
    q = poses.quat_xyzw
    return repeated_positions(poses) & rows_equal(q[1:], q[:-1])


def drop_repeats(gt: PoseStream) -> PoseStream:
    """GT without the samples that repeat the previous position (mocap tracking lost).

    Motive repeats the last pose while it has lost the rigid body; interpolating across the
    repeated samples would pretend the body stood still. Dropping them turns the loss into a
    gap, which the max-gap rule then excludes.
    """
    moved = ~repeated_positions(gt)
    if moved.all():
        return gt
    keep = np.ones(len(gt), dtype=bool)
    keep[1:] = moved
    return gt.take(keep)


def drop_duplicates(gt: PoseStream) -> tuple[PoseStream, int]:
    """GT without samples identical to the previous one in time and pose.

    Two loggers recording the same mocap topic (overlapping GT files) store every message
    twice; kept, each pair would look like Motive's tracking-loss repeat. A real repeat has a
    fresh stamp, so it is not dropped.
    """
    if len(gt) < 2:
        return gt, 0
    # Equal stamps are rare: compare the poses only there, not over the whole stream.
    at = np.flatnonzero(gt.t_ns[1:] == gt.t_ns[:-1])
    if at.size:
        same = rows_equal(gt.xyz[at + 1], gt.xyz[at]) & rows_equal(
            gt.quat_xyzw[at + 1], gt.quat_xyzw[at]
        )
        at = at[same]
    if not at.size:
        return gt, 0
    keep = np.ones(len(gt), dtype=bool)
    keep[at + 1] = False
    return gt.take(keep), int(at.size)


CHECK_ROWS = 1 << 14  # rows per chunk of the all-valid check: its buffers stay in cache


def _all_valid(stream: PoseStream, *, finite_xyz: bool = False) -> bool:
    """Whether :func:`drop_invalid` keeps every sample, shown cheaply or not at all.

    Squared quaternion norms (squares summed by column) far from both limits (NaN fails the
    comparisons too) and finite positions (``finite_xyz``: shown already), chunk by chunk so
    that the temporaries stay in cache. False sends the stream to the exact per-sample test.
    """
    q, xyz = stream.quat_xyzw, stream.xyz
    if q.ndim != 2 or q.shape[1] != 4 or not q.flags.c_contiguous:
        return False
    squares = np.empty((min(len(q), CHECK_ROWS), 4))
    for a in range(0, len(q), CHECK_ROWS):
        rows = slice(a, a + CHECK_ROWS)
        # an overflowing square is infinite and fails the test below: the exact test then
        # decides (and says nothing to stderr)
        with np.errstate(over="ignore"):
            part = np.square(q[rows], out=squares[: len(q[rows])])
            # the four columns summed into the first: no einsum over a short axis
            sq = part[:, 0]
            for k in (1, 2, 3):
                sq += part[:, k]
        # margins over drop_invalid's limits: whatever the order the squares are summed in,
        # a norm passing here passes there (a stream failing here goes to the exact test)
        finite = finite_xyz or bool(np.isfinite(xyz[rows]).all())
        if not (finite and sq.min() > 2e-17 and sq.max() < 5e299):
            return False
    return True


def drop_invalid(
    stream: PoseStream, *, jumps: bool = True, found: Impossible | None = None
) -> tuple[PoseStream, int]:
    """The stream without samples whose position or orientation is not usable.

    NaN or infinite values, or a zero quaternion (a node publishing "no pose"), cannot be
    compared; neither can a pose no body took (:func:`impossible_samples`; ``jumps``: the
    jump test too, for a measured body, not a robot's own estimate, which may jump when it
    relocalises). Dropping them (and saying how many) beats a NaN or an absurd score.
    ``found``: :func:`impossible_samples` of this stream, when the caller has it already.
    """
    impossible = (
        found if found is not None else impossible_samples(stream.t_ns, stream.xyz, jumps=jumps)
    )
    # the bounds of impossible_samples showed every coordinate finite: not tested again
    if _all_valid(stream, finite_xyz=impossible.bounded) and not impossible.count:
        return stream, 0
    with np.errstate(over="ignore"):  # an overflowing norm is not finite: dropped below
        norm = row_norm(stream.quat_xyzw)
    ok = np.all(np.isfinite(stream.xyz), axis=1) & np.isfinite(norm) & (norm > 1e-9)
    ok &= ~(impossible.far | impossible.jump)
    if ok.all():
        return stream, 0
    return stream.take(ok), int((~ok).sum())


# Physically impossible samples (docs/uncertainty.md, "Impossible samples"). No frame on Earth
# puts a point further from its origin than the Earth's circumference (4e7 m); nor can any
# squared distance of such points overflow a float64.
MAX_COORD_M = 1e8
# From the stream's median position: no arena is a kilometre across (a home or work testbed is
# about 10 m; ertools.benchmarks.common.arena refuses inputs this far from the GT too).
FAR_M = 1000.0
# Faster than any robot of the leagues: the RoCKIn/ERL robots drive at 1-1.5 m/s at most and
# FBM3's end effector follows its paths at a few cm/s; 5 m/s is three times the fastest of
# them and still five times below a single-frame 1 m spike at 25 Hz. A jump must also exceed
# JUMP_MIN_M, 100 times the 1 mm noise of a mocap frame, so that stamp jitter between two
# nearby samples never makes one.
MAX_SPEED_M_S = 5.0
JUMP_MIN_M = 0.1
# A stretch that leaves by a jump and comes back by one within this is a glitch (a marker set
# mistaken for another for a few frames, a forged pose); longer ones are the data on one side
# of a step, which side cannot be told: said, not dropped.
EXCURSION_MAX_S = 0.5
_MEDIAN_SAMPLES = 10_000  # the centre from at most this many samples (a median is robust)


@frozen_dataclass
class Jump:
    """A move between two consecutive measured samples faster than any robot.

    Attributes:
        t_ns: the stamp of the sample it lands on.
        distance_m: how far it goes.
        speed_m_s: over the time between the two samples (at least the median frame period).
    """

    t_ns: int
    distance_m: float
    speed_m_s: float


@frozen_dataclass
class Impossible:
    """The samples of a stream no body can have taken.

    Attributes:
        far: (N,) positions beyond :data:`MAX_COORD_M`, or :data:`FAR_M` from the stream's
            median position.
        jump: (N,) samples of a stretch left and re-entered by jumps (:class:`Jump`) within
            :data:`EXCURSION_MAX_S`.
        steps: the jumps that bound no such stretch: the data on one side is wrong, which
            cannot be told (their samples stay valid; the warning says where).
        bounded: every coordinate was shown finite and within :data:`MAX_COORD_M` (the
            bounds pass found nothing to test sample by sample); False: not shown.
    """

    far: Bool
    jump: Bool
    steps: tuple[Jump, ...] = ()
    bounded: bool = False

    @property
    def count(self) -> int:
        return int(np.count_nonzero(self.far | self.jump))


def impossible_samples(t_ns: npt.NDArray[np.int64], xyz: F64, *, jumps: bool = True) -> Impossible:
    """Which samples of a stream are physically impossible (:class:`Impossible`).

    Not-finite samples are neither far nor jumps (they are invalid already); a sample that
    repeats the previous position (Motive re-sending a lost body's pose) is not a
    measurement, so a jump is measured from the last real one (no jump when tracking comes
    back after a loss the body moved through).
    """
    n = len(t_ns)
    far = np.zeros(n, dtype=bool)
    jump = np.zeros(n, dtype=bool)
    if not n or _all_possible(t_ns, xyz, jumps=jumps):
        return Impossible(far, jump, bounded=True)
    # Column by column, and the usual stream (every sample finite and near) used as it is
    # rather than gathered: the same values, without (N, 3) temporaries reduced over rows.
    finite = _per_column(np.isfinite, xyz, np.logical_and)
    if finite.all():
        far = _per_column(lambda c: np.abs(c) > MAX_COORD_M, xyz, np.logical_or)
    else:
        far[finite] = (np.abs(xyz[finite]) > MAX_COORD_M).any(axis=1)
    ok = np.flatnonzero(finite & ~far)
    if ok.size:
        centre = median(xyz[ok[:: max(1, ok.size // _MEDIAN_SAMPLES)]], axis=0)
        far[ok[row_norm(_rows(xyz, ok) - centre) > FAR_M]] = True
    if not jumps:
        return Impossible(far, jump)
    measured = finite & ~far
    if n > 1:
        measured[1:] &= ~rows_equal(xyz[1:], xyz[:-1])
    ok = np.flatnonzero(measured)
    if ok.size < 2:
        return Impossible(far, jump)
    t = t_ns[ok]
    dt = np.diff(t)
    positive = dt[dt > 0]
    period = int(median(positive)) if positive.size else 1
    dist = row_norm(np.diff(_rows(xyz, ok), axis=0))
    speed = dist / (np.maximum(dt, max(period, 1)) / 1e9)
    big = (dist > JUMP_MIN_M) & (speed > MAX_SPEED_M_S)
    if not big.any():
        return Impossible(far, jump)
    # stretch k of the measured samples lies between jump k-1 and jump k (or the stream's ends)
    at = np.flatnonzero(big) + 1  # first sample of stretches 1, 2, ...
    first = np.concatenate([[0], at])
    last = np.concatenate([at - 1, [ok.size - 1]])
    kept, steps = _kept_stretches(t, xyz[ok], first, last, period)
    # every sample from a stretch's first measured one to the next stretch's, repeats included
    of = np.searchsorted(ok[at], np.arange(n), side="right")
    jump[:] = ~kept[of] & finite & ~far
    return Impossible(far, jump, steps)


# Bounds shown below hold for the rounded distances too: a sum of three rounded squares and its
# rounded root exceed the exact value by a few units in the last place, far below this margin.
_SQRT3_MARGIN = math.sqrt(3.0) * (1.0 + 1e-9)
BOUND_ROWS = 1 << 14  # rows per chunk of the bounds: the differences stay in cache


def _all_possible(t_ns: npt.NDArray[np.int64], xyz: F64, *, jumps: bool) -> bool:
    """Whether no sample can be far or a jump, shown from bounds in one pass over ``xyz``.

    Every coordinate within [lo, hi] (so are the medians): no sample is further than
    sqrt(3) (hi - lo) from the centre. Every coordinate moving by at most ``step`` between
    consecutive rows: no two consecutive measured samples (repeats between them equal the
    first) are more than sqrt(3) step apart, never a jump; where some move more, the rows
    that do may still be too slow for one (:func:`_slow_steps`). False: not shown (NaN,
    infinite, far or fast samples), and the exact test decides.
    """
    if not xyz.flags.c_contiguous or xyz.ndim != 2 or xyz.shape[1] != 3:
        return False
    flat = xyz.reshape(-1)
    size, width = flat.size, 3 * BOUND_ROWS
    lo, hi, step = math.inf, -math.inf, 0.0
    buf = np.empty(min(width, size))
    for a in range(0, size, width):
        end = min(a + width, size)
        part = flat[a:end]
        part_lo, part_hi = float(part.min()), float(part.max())
        if not (part_lo >= -MAX_COORD_M and part_hi <= MAX_COORD_M):
            return False  # NaN, infinite or beyond any frame
        lo, hi = min(lo, part_lo), max(hi, part_hi)
        start = max(a, 3)  # each coordinate minus the same one of the row before
        if jumps and end > start:
            d = np.subtract(flat[start:end], flat[start - 3 : end - 3], out=buf[: end - start])
            step = max(step, float(d.max()), -float(d.min()))
    if (hi - lo) * _SQRT3_MARGIN > FAR_M:
        return False
    return step * _SQRT3_MARGIN <= JUMP_MIN_M or _slow_steps(t_ns, xyz)


def _slow_steps(t_ns: npt.NDArray[np.int64], xyz: F64) -> bool:
    """Whether no row moving a coordinate by more than JUMP_MIN_M / sqrt(3) from the row before
    can be a jump, for finite positions near each other (:func:`_all_possible`): a GT with
    tracking gaps, or blocks taken out of a stream, moves far between rows far apart in time.

    With stamps in order, the time from the last measured sample to a row is at least the
    time from the row before it (the repeats between them equal that sample), so each such
    row is no jump when sqrt(3) times its largest coordinate move, over its time from the
    row before, is below :data:`MAX_SPEED_M_S` (by a margin far above the rounding).
    False: not shown (stamps out of order, equal stamps, or a fast move).
    """
    t = t_ns
    if len(t) != len(xyz) or not bool(np.all(t[1:] >= t[:-1])):
        return False
    flat = xyz.reshape(-1)
    moved = np.abs(flat[3:] - flat[:-3]) * _SQRT3_MARGIN > JUMP_MIN_M
    rows = distinct(np.flatnonzero(moved) // 3 + 1)  # a row moved from the row before it
    dt = (t[rows] - t[rows - 1]).astype(np.float64)
    step = np.abs(xyz[rows] - xyz[rows - 1]).max(axis=1)
    fast = step * (_SQRT3_MARGIN * 1e9) > MAX_SPEED_M_S * (1.0 - 1e-9) * dt
    return not bool(fast.any())


def _per_column(test: Callable[[F64], Bool], xyz: F64, combine: np.ufunc) -> Bool:
    """``test(xyz).all(axis=1)`` (``combine`` logical_and) or ``.any(axis=1)`` (logical_or),
    one column at a time."""
    out = test(xyz[:, 0])
    for k in range(1, xyz.shape[1]):
        combine(out, test(xyz[:, k]), out=out)
    return out


def _rows(xyz: F64, idx: npt.NDArray[np.intp]) -> F64:
    """``xyz[idx]`` for ascending distinct ``idx``; ``xyz`` itself when that is every row."""
    return xyz if len(idx) == len(xyz) else xyz[idx]


def _kept_stretches(
    t: npt.NDArray[np.int64],
    xyz: F64,
    first: npt.NDArray[np.intp],
    last: npt.NDArray[np.intp],
    period: int,
) -> tuple[Bool, tuple[Jump, ...]]:
    """Which stretches between jumps are the body's, and the steps among them.

    From the longest stretch (the body's own; when even it lasts no longer than a glitch,
    nothing is dropped), outwards both ways: the next stretch is kept
    when the body could have reached it from the last sample kept (a spike's way back lands
    where the body was); else it is dropped when it lasts at most :data:`EXCURSION_MAX_S`
    (the glitch), and kept as a step when longer (which side is wrong cannot be told). A
    handful of stretches, not samples: the loop is short.
    """
    count = len(first)
    lasting = t[last] - t[first]
    short = lasting <= round(EXCURSION_MAX_S * 1e9)
    anchor = int(np.argmax(lasting))
    kept = np.zeros(count, dtype=bool)
    kept[anchor] = True
    if short[anchor]:
        # no stretch outlasts a glitch: which one is the body's cannot be told; all stay
        short[:] = False
    steps: list[Jump] = []

    def move(i: int, j: int) -> Jump:
        d = float(np.linalg.norm(xyz[j] - xyz[i]))
        return Jump(int(t[max(i, j)]), d, d / (max(abs(int(t[j] - t[i])), period) / 1e9))

    for order in (range(anchor + 1, count), range(anchor - 1, -1, -1)):
        ref = int(last[anchor] if order.step > 0 else first[anchor])
        for s in order:
            near, far_end = (
                (int(first[s]), int(last[s])) if order.step > 0 else (int(last[s]), int(first[s]))
            )
            m = move(ref, near)
            if m.distance_m > JUMP_MIN_M and m.speed_m_s > MAX_SPEED_M_S:
                if short[s]:
                    continue  # an excursion: left out
                steps.append(m)
            kept[s] = True
            ref = far_end
    return kept, tuple(steps[:3])


def impossible_warning(
    stream: PoseStream,
    origin_ns: int | None = None,
    *,
    jumps: bool = True,
    found: Impossible | None = None,
) -> str | None:
    """One warning line when ``stream`` holds impossible samples (left out of every score:
    :func:`drop_invalid`, the validity masks) or steps no body can make, else None
    (``found``: as for :func:`drop_invalid`)."""
    if found is None:
        found = impossible_samples(stream.t_ns, stream.xyz, jumps=jumps)
    if not found.count and not found.steps:
        return None

    def when(t: int) -> str:
        return f"{(t - origin_ns) / 1e9:.3f} s" if origin_ns is not None else iso_utc(t)

    parts = []
    far = int(np.count_nonzero(found.far))
    if far:
        i = int(np.flatnonzero(found.far)[0])
        parts.append(
            f"{far} pose(s) kilometres from the others (the first at {when(int(stream.t_ns[i]))})"
        )
    glitch = int(np.count_nonzero(found.jump))
    if glitch:
        i = int(np.flatnonzero(found.jump)[0])
        parts.append(
            f"{glitch} pose(s) reached and left faster than {MAX_SPEED_M_S:g} m/s (the first "
            f"at {when(int(stream.t_ns[i]))})"
        )
    left = f"{'; '.join(parts)}: left out as invalid" if parts else ""
    steps = "; ".join(
        f"{s.distance_m:.3g} m at {s.speed_m_s:.3g} m/s at {when(s.t_ns)}" for s in found.steps
    )
    if steps:
        steps = (
            f"{'; and ' if left else ''}jump(s) faster than any robot that do not come back "
            f"({steps}): the poses on one side are wrong, which cannot be told"
        )
    return f"{stream.source or 'the pose stream'}: {left}{steps}"


def frame_change_warning(stream: PoseStream, origin_ns: int | None = None) -> str | None:
    """One warning line when the stream's frame names change mid-log, else None.

    A ground-truth topic whose ``frame_id`` changes (the mocap re-published in another frame,
    two publishers on one topic) mixes poses of different frames: every number computed
    across the change compares coordinates that do not belong together.

    Args:
        stream: the pose stream.
        origin_ns: times are printed relative to it (the log's first message) when given,
            else as UTC.
    """
    if not stream.frame_changes:
        return None

    def when(t: int) -> str:
        return f"{(t - origin_ns) / 1e9:.3f} s" if origin_ns is not None else iso_utc(t)

    shown = stream.frame_changes[:3]
    listed = "; ".join(f"{c.field} {c.old!r} -> {c.new!r} at {when(c.t_ns)}" for c in shown)
    more = len(stream.frame_changes) - len(shown)
    many = " (and more)" if len(stream.frame_changes) >= MAX_FRAME_CHANGES else ""
    extra = f"; {more} more change(s){many}" if more > 0 else ""
    since = " from the log's first message" if origin_ns is not None else ""
    return (
        f"{stream.source or 'the pose stream'}: the frame names change in the middle of the "
        f"log ({listed}{extra}; times{since}): poses on either side may be in different frames "
        "and numbers computed across the change mix them"
    )
