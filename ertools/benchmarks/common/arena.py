"""Inputs far outside the arena the log's GT covers: a goal waypoint typed in millimetres, a
config from another testbed, a forged 1e308.

The arena is what the GT saw: the box around every finite GT position. A target a few metres
beyond it is possible (a waypoint the robot never reached); one many metres beyond it means
the input is not this arena's, and its score would be a number without meaning (a position
accuracy of 3.5e307 m): warned beyond :data:`WARN_M`, refused beyond :data:`REFUSE_M`.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from ertools.errors import ConfigError

WARN_M = 10.0  # a home or work testbed is about 10 m across
REFUSE_M = 1000.0  # no arena is a kilometre from where its GT was seen


def check_in_arena(
    targets_xy: npt.NDArray[np.float64],
    gt_xyz: npt.NDArray[np.float64],
    *,
    what: str,
    source: str,
) -> str | None:
    """A warning when a target lies more than :data:`WARN_M` outside the GT's box, None when
    all lie near it (or there is no GT to tell).

    Raises:
        ConfigError: a target more than :data:`REFUSE_M` outside it, naming it and ``source``.
    """
    xy = gt_xyz[:, :2]
    xy = xy[np.isfinite(xy).all(axis=1)]
    if not len(xy) or not len(targets_xy):
        return None
    low, high = xy.min(axis=0), xy.max(axis=0)
    outside = np.maximum(np.maximum(low - targets_xy, targets_xy - high), 0.0)
    with np.errstate(over="ignore", invalid="ignore"):  # 1e308 squared: inf, still the worst
        distance = np.hypot(outside[:, 0], outside[:, 1])
    worst = int(np.argmax(distance))
    far = float(distance[worst])
    if far <= WARN_M:
        return None
    x, y = (float(v) for v in targets_xy[worst])
    shown = f"{far:.1f}" if far < 1e7 else f"{far:.3g}"
    line = (
        f"{what}[{worst}] ({x:.6g}, {y:.6g}) lies {shown} m outside the area the GT covers "
        f"(x {low[0]:.2f} to {high[0]:.2f} m, y {low[1]:.2f} to {high[1]:.2f} m)"
    )
    if far > REFUSE_M:
        raise ConfigError(f"{line}: not this arena's input; check its units and file", path=source)
    return f"{line}: is {source} this arena's?"
