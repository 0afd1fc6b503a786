"""Frozen stretches around scored moments: runs of identical poses (Motive re-sending the last
pose of a lost rigid body) that the pose at a moment comes from, and the warning that says so.

Only the benchmarks that score poses at moments use it (FBM2@Home's reached moments, FBM3@Work's
run edges); the repeat test itself is :func:`ertools.benchmarks.common.hygiene.identical_poses`.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import numpy.typing as npt

from ertools.benchmarks.common.hygiene import identical_poses
from ertools.frozen_dataclass import frozen_dataclass
from ertools.streams import PoseStream

# Identical poses lasting longer than this around a scored moment are reported. Real mocap
# measurements never repeat all 7 float64 exactly (0.05 mm of noise is ~1e11 float64 steps),
# so a repeat is Motive re-sending the last pose after losing the rigid body; at 120 Hz
# 0.1 s is 12 frames, the FBM2H --max-gap default: a frozen stretch that long is a gap of the
# size ertools refuses, disguised as data.
FROZEN_MIN_S = 0.1


@frozen_dataclass
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


def frozen_warnings(
    poses: PoseStream, moments: Sequence[tuple[str, str, int]], origin_ns: int
) -> list[str]:
    """A warning per moment ``(who, what, t_ns)`` (``("run 2", "start", t)``) whose pose is a
    frozen (repeated) pose (:func:`frozen_around`): the last pose before a tracking loss, not
    where the body was then."""
    if not moments:
        return []
    out = []
    for (who, what, t), span in zip(
        moments, frozen_around(poses, [m[2] for m in moments]), strict=True
    ):
        if span is None:
            continue
        out.append(
            f"{who}: the pose at its {what} time {(t - origin_ns) / 1e9:.3f} s is frozen: "
            f"{span.samples} identical poses over {span.duration_s:.3f} s "
            f"({(span.start_ns - origin_ns) / 1e9:.3f}-{(span.end_ns - origin_ns) / 1e9:.3f} s "
            "from the log's first message; tracking lost, or a noiseless recording)"
        )
    return out
