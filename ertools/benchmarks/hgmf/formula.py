"""HGMF's arithmetic (fbm6_grasping_manipulation.py at 2bb8a41, l. 176-274; docs/hgmf.md),
on arrays, once: no IO, no options.

- the distance of the object to its target in the table's plane (l. 227-229);
- a grasp: the object's height over its height before the goal by more than 3 cm (l. 270);
- a segment's time as ``genpy.Duration.to_sec()`` gives it (l. 181);
- the totals: the texts and the average over the counted goals (l. 239-240).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import numpy.typing as npt

from ertools.arrays import F64, I64
from ertools.benchmarks.hgmf.config import GRASP_RISE_M

NS_PER_S = 1_000_000_000
Bools = npt.NDArray[np.bool_]


def to_sec(ns: I64 | int) -> F64:
    """``genpy.Duration.to_sec()`` of durations in ns: whole seconds and the remainder
    (floored, 0 <= nsecs < 1e9) each as a float, added: ``float(secs) + float(nsecs) / 1e9``."""
    secs, nsecs = np.divmod(np.asarray(ns, dtype=np.int64), NS_PER_S)
    return np.asarray(secs.astype(np.float64) + nsecs.astype(np.float64) / 1e9, dtype=np.float64)


def planar_distance(target_xy: F64, measured_xy: F64) -> F64:
    """|target - measured| in the table's x-y plane, per row (N, 2) -> (N,): ``sqrt(x_err**2
    + y_err**2)`` with ``x_err = target_x - x`` (l. 227-229)."""
    err = np.asarray(target_xy, dtype=np.float64) - np.asarray(measured_xy, dtype=np.float64)
    return np.asarray(np.sqrt(err[..., 0] ** 2 + err[..., 1] ** 2), dtype=np.float64)


def risen(z: F64, z_ref: float, rise: float = GRASP_RISE_M) -> Bools:
    """Heights strictly above ``z_ref + rise``, the sum computed first as the script does
    (``current_object_height > (object_height_reference + 0.03)``, l. 270)."""
    threshold = z_ref + rise
    return np.asarray(np.asarray(z, dtype=np.float64) > threshold, dtype=np.bool_)


def first_rise(t_ns: I64, z: F64, z_ref: float, rise: float = GRASP_RISE_M) -> int | None:
    """The first time the object was above ``z_ref + rise`` (None: never)."""
    up = np.flatnonzero(risen(z, z_ref, rise))
    return int(t_ns[up[0]]) if up.size else None


def sequential_sum(values: Sequence[float]) -> float:
    """The sum in the given order, each addition rounded (the script's ``+=`` from int 0)."""
    total = 0.0
    for v in values:  # a few goals a run: the order of the additions is the script's
        total += float(v)
    return total


def average(values: Sequence[float], divisor: int) -> float:
    """``sum / divisor`` (``distance_error_sum / goals_completed_sum``, l. 240)."""
    return sequential_sum(values) / divisor


def grasp_text(grasped: int, objects: int) -> str:
    """``Objects grasped``: ``str(k) + " out of " + str(N)`` (l. 239)."""
    return f"{grasped} out of {objects}"


def position_text(x: float, y: float) -> str:
    """``"(%.2f, %.2f)" % (x, y)`` (l. 232-236)."""
    return "(%.2f, %.2f)" % (x, y)  # noqa: UP031 - the script's own format, kept verbatim


def object_text(description: str, object_id: int) -> str:
    """``"%s (id %d)" % (description, id)`` (l. 237)."""
    return "%s (id %d)" % (description, object_id)  # noqa: UP031 - the script's format
