"""HNF's arithmetic (fbm2_navigation.py l. 189-205, 227-238), on arrays, once. No IO.

Per segment with a pose: ``distance_error = sqrt(dx^2 + dy^2)``; ``s = sin(|dtheta|)``,
``c = cos(|dtheta|)``; ``orientation_error = atan2(|s|, c)`` (``atan2(s, c)`` before
f594ff1). Totals: ``position_accuracy = sum(d) / divisor``; ``orientation_accuracy =
atan2(|sum(s)|, sum(c))`` (without the ``fabs`` before f594ff1). The script's dtheta is
unwrapped; ertools' reading wraps it to [-pi, pi] first. The sums run in the script's order
(NumPy's accumulate is sequential, as the script's ``+=``).
"""

from __future__ import annotations

import numpy as np

from ertools.arrays import F64, Bool
from ertools.frozen_dataclass import frozen_dataclass
from ertools.geometry import wrap_angle


@frozen_dataclass(eq=False)
class SegmentErrors:
    """Per-segment errors (M,) of the segments with a pose.

    Attributes:
        distance: metres.
        dtheta: robot yaw minus waypoint theta (wrapped when asked).
        sin, cos: of ``|dtheta|``: the script's summands.
        orientation: the segment's orientation error, radians.
    """

    distance: F64
    dtheta: F64
    sin: F64
    cos: F64
    orientation: F64


def segment_errors(
    robot_x: F64, robot_y: F64, robot_theta: F64, target: F64, *, wrap: bool, fabs: bool = True
) -> SegmentErrors:
    """The errors of robot poses against waypoints ``target`` (M, 3)."""
    dx = robot_x - target[:, 0]
    dy = robot_y - target[:, 1]
    distance = np.sqrt(dx**2 + dy**2)
    dtheta = robot_theta - target[:, 2]
    if wrap:
        dtheta = wrap_angle(dtheta)
    s = np.sin(np.abs(dtheta))
    c = np.cos(np.abs(dtheta))
    orientation = np.arctan2(np.abs(s) if fabs else s, c)
    return SegmentErrors(distance, dtheta, s, c, orientation)


def _sequential_sum(values: F64) -> float:
    return float(np.add.accumulate(values)[-1]) if values.size else 0.0


def accuracies(
    errors: SegmentErrors, summed: Bool, divisor: int, *, fabs: bool = True
) -> tuple[float | None, float | None]:
    """(position_accuracy, orientation_accuracy) over the segments ``summed``, divided by
    ``divisor``; (None, None) when the divisor is 0, as the script wrote them."""
    if divisor <= 0:
        return None, None
    sum_d = _sequential_sum(errors.distance[summed])
    sum_s = _sequential_sum(errors.sin[summed])
    sum_c = _sequential_sum(errors.cos[summed])
    position = sum_d / divisor
    orientation = float(np.arctan2(abs(sum_s) if fabs else sum_s, sum_c))
    return position, orientation
