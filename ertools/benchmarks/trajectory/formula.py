"""The error statistics of an association: mean, RMSE and percentiles of the 3D position error, the
orientation error (wrapped, and as the 2015 script computed it).
"""

from __future__ import annotations

import numpy as np

from ertools.arrays import percentiles_and_median
from ertools.benchmarks.trajectory.association import COMPARED, Matched
from ertools.frozen_dataclass import frozen_dataclass

PERCENTILES = (50.0, 90.0, 95.0, 99.0)


@frozen_dataclass
class Metrics:
    """Errors over the compared poses.

    Attributes:
        position_error: mean 3D distance (the 2015 score), metres.
        orientation_error: atan2(sum sin|dyaw|, sum cos|dyaw|) with dyaw wrapped (2015 form).
        rmse, median, max: of the 3D distances, metres.
        percentiles: (percent, value) of the 3D distances.
        orientation_error_2015: the same with dyaw not wrapped, as the 2015 script computed it.
    """

    position_error: float
    orientation_error: float
    rmse: float
    median: float
    max: float
    percentiles: tuple[tuple[float, float], ...]
    orientation_error_2015: float


def metrics(m: Matched) -> Metrics | None:
    """The error statistics of the compared poses, None when none was compared."""
    ok = m.status == COMPARED
    if not ok.any():
        return None
    # every pose compared (the usual comparison): the arrays as they are, not gathered copies
    every = bool(ok.all())
    d = m.position_error if every else m.position_error[ok]
    dyaw = m.yaw_error if every else m.yaw_error[ok]
    raw = np.abs(m.yaw_diff_raw if every else m.yaw_diff_raw[ok])
    pct, middle = percentiles_and_median(d, PERCENTILES)  # one partition for both
    return Metrics(
        position_error=float(d.mean()),
        orientation_error=float(np.arctan2(np.sin(dyaw).sum(), np.cos(dyaw).sum())),
        rmse=float(np.sqrt(np.mean(d * d))),
        median=float(middle),
        max=float(d.max()),
        percentiles=tuple((p, float(v)) for p, v in zip(PERCENTILES, pct, strict=True)),
        orientation_error_2015=float(np.arctan2(np.sin(raw).sum(), np.cos(raw).sum())),
    )
