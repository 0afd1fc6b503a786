"""The invalid spans of a validity summary where a path plot draws them: their ends in
seconds and the (x, y) of the valid samples on either side (FBM2@Home's and FBM3@Work's path
figures; the layers themselves are :mod:`ertools.benchmarks.common.gaps`).
"""

from __future__ import annotations

from ertools.arrays import F64
from ertools.benchmarks.common.validity import STILL_M, Validity, lost_spans
from ertools.frozen_dataclass import frozen_dataclass


@frozen_dataclass
class GapOnPath:
    """An invalid span where a path plot draws it.

    Attributes:
        start_s, end_s: its ends in seconds from the origin the result counts time from.
        reason: as :attr:`~ertools.benchmarks.common.validity.InvalidSpan.reason`.
        start_xy, end_xy: the plot-frame (x, y) of the valid samples at its ends, None where it
            touches the window's edge (nothing was measured on that side).
        lost: whether the tracked point may have moved unmeasured in it
            (:func:`~ertools.benchmarks.common.validity.lost_spans`); False for a tracking loss
            of a point that stood still.
    """

    start_s: float
    end_s: float
    reason: str
    start_xy: tuple[float, float] | None
    end_xy: tuple[float, float] | None
    lost: bool = True


def gaps_on_path(
    validity: Validity, xy: F64 | None, origin_ns: int, still_m: float = STILL_M
) -> tuple[GapOnPath, ...]:
    """The spans of ``validity`` with their (x, y) ends in ``xy``, the window's samples in the
    plot's frame (row 0 = the window's first sample; a rotation of the window's world (x, y)
    keeps the distances that decide ``lost``)."""
    lost = set(lost_spans(validity, xy, still_m))

    def at(i: int) -> tuple[float, float] | None:
        if xy is None or i < 0 or i >= len(xy):
            return None
        return (float(xy[i, 0]), float(xy[i, 1]))

    return tuple(
        GapOnPath(
            (s.start_ns - origin_ns) / 1e9,
            (s.end_ns - origin_ns) / 1e9,
            s.reason,
            at(s.before),
            at(s.after),
            s in lost,
        )
        for s in validity.spans
    )
