"""The toy's arithmetic, written once, on arrays (no IO)."""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt

Floats = npt.NDArray[np.float64]


def measured(xyz: Floats) -> npt.NDArray[np.bool_]:
    """The poses with a position (no NaN coordinate)."""
    return ~np.isnan(xyz).any(axis=1)


def mean_x(xyz: Floats, keep: npt.NDArray[np.bool_]) -> float:
    """The mean x (metres) of the kept poses; NaN when none is kept."""
    return float(xyz[keep, 0].mean()) if keep.any() else math.nan
