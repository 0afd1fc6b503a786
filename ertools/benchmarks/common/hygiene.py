"""Sample hygiene shared by the benchmarks: poses that cannot be compared (NaN, infinite, zero
quaternions) and samples recorded twice.
"""

from __future__ import annotations

import numpy as np

from ertools.geometry import row_norm
from ertools.streams import PoseStream


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
        same = np.all(gt.xyz[at + 1] == gt.xyz[at], axis=1) & np.all(
            gt.quat_xyzw[at + 1] == gt.quat_xyzw[at], axis=1
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
