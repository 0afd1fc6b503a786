"""Sample hygiene shared by the benchmarks, each test written once: repeated poses (mocap
tracking lost, samples recorded twice, frozen stretches), poses that cannot be compared (NaN,
infinite, zero quaternions) and frame names that change mid-log.

Every repeat test is exact float equality of whole rows (:func:`rows_equal`): real mocap
measurements never repeat a float64 coordinate, so an equal row is a re-sent pose.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from ertools.arrays import F64, Bool
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
    return rows_equal(poses.xyz[1:], poses.xyz[:-1])


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


def _all_valid(stream: PoseStream) -> bool:
    """Whether :func:`drop_invalid` keeps every sample, shown cheaply or not at all.

    Squared quaternion norms by einsum far from both limits (NaN fails the comparisons too)
    and finite positions, chunk by chunk so that the temporaries stay in cache. False sends
    the stream to the exact per-sample test.
    """
    q, xyz = stream.quat_xyzw, stream.xyz
    buf = np.empty(min(len(q), CHECK_ROWS))
    for a in range(0, len(q), CHECK_ROWS):
        rows = slice(a, a + CHECK_ROWS)
        sq = np.einsum("ij,ij->i", q[rows], q[rows], out=buf[: len(q[rows])])
        if not (np.isfinite(xyz[rows]).all() and sq.min() > 1e-17 and sq.max() < 1e300):
            return False
    return True


def drop_invalid(stream: PoseStream) -> tuple[PoseStream, int]:
    """The stream without samples whose position or orientation is not usable.

    NaN or infinite values, or a zero quaternion (a node publishing "no pose"), cannot be
    compared; dropping them (and saying how many) beats a NaN score.
    """
    if _all_valid(stream):
        return stream, 0
    with np.errstate(over="ignore"):  # an overflowing norm is not finite: dropped below
        norm = row_norm(stream.quat_xyzw)
    ok = np.all(np.isfinite(stream.xyz), axis=1) & np.isfinite(norm) & (norm > 1e-9)
    if ok.all():
        return stream, 0
    return stream.take(ok), int((~ok).sum())


# Identical poses lasting longer than this around a scored moment are reported. Real mocap
# measurements never repeat all 7 float64 exactly (0.05 mm of noise is ~1e11 float64 steps),
# so a repeat is Motive re-sending the last pose after losing the rigid body; at 120 Hz
# 0.1 s is 12 frames, the FBM2H --max-gap default: a frozen stretch that long is a gap of the
# size ertools refuses, disguised as data.
FROZEN_MIN_S = 0.1


@dataclass(frozen=True)
class FrozenSpan:
    """A run of identical poses (position and orientation repeated exactly).

    Attributes:
        start_ns: the last real measurement (the pose that was then repeated).
        end_ns: the last repetition.
        samples: poses in the run, the first included.
    """

    start_ns: int
    end_ns: int
    samples: int

    @property
    def duration_s(self) -> float:
        return (self.end_ns - self.start_ns) / 1e9


def frozen_around(
    poses: PoseStream, query_ns: npt.ArrayLike, min_s: float = FROZEN_MIN_S
) -> list[FrozenSpan | None]:
    """For each moment, the frozen run (longer than ``min_s``) its pose comes from, or None.

    The pose at a moment is taken from the samples just before and just after it (held or
    interpolated); the moment is *frozen* when either of them belongs to a run of identical
    poses (:func:`identical_poses`) spanning more than ``min_s``: the ground truth there is
    the repeated last pose of a lost rigid body, not a measurement.
    """
    q = np.asarray(query_ns, dtype=np.int64).reshape(-1)
    out: list[FrozenSpan | None] = [None] * len(q)
    # Repeats are rare: work on their indices only, not on per-sample arrays.
    rep = np.flatnonzero(identical_poses(poses))  # sample rep+1 repeats sample rep
    if not rep.size or not len(q):
        return out
    t = poses.t_ns
    breaks = np.flatnonzero(np.diff(rep) > 1)
    starts = rep[np.concatenate([[0], breaks + 1])]  # first sample of each run
    ends = rep[np.concatenate([breaks, [rep.size - 1]])] + 1  # last sample of each run
    long_run = (t[ends] - t[starts]) > round(min_s * 1e9)
    if not long_run.any():
        return out
    starts, ends = starts[long_run], ends[long_run]
    before = np.searchsorted(t, q, side="right") - 1
    for k, i in enumerate(before.tolist()):
        for j in (i, i + 1):
            r = int(np.searchsorted(starts, j, side="right")) - 1
            if r >= 0 and j <= ends[r]:
                a, b = int(starts[r]), int(ends[r])
                out[k] = FrozenSpan(int(t[a]), int(t[b]), b - a + 1)
                break
    return out


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
