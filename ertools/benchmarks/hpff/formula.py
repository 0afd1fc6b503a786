"""HPFF's arithmetic (fbm5_person_following.py l. 105-131, 162-172), on arrays, once. No IO.

With S samples where the distance was measured and F where it was not: the average deviation
``sum |d_k - desired| / S``; the distance covered ``sum |p_k - p_{k-1}|`` over the samples
measured within ``[min, max]`` whose robot position and the previous sample's are both known;
the reliability ``str(round(100 - 100 F / (S + F), 1)) + '%'`` (Python 2) and a warning above
50 % failures. The sums run in the samples' order (the script's ``+=``).
"""

from __future__ import annotations

import numpy as np

from ertools.arrays import F64, Bool
from ertools.frozen_dataclass import frozen_dataclass
from ertools.rsbb.py2 import percent_py2

FAILED = "Benchmark failed: finished prematurely or took too long"


@frozen_dataclass(eq=False)
class Following:
    """The statistics of a run's samples.

    Attributes:
        deviation: (K,) ``|d - desired|`` (NaN where not measured).
        steps: (K,) the distance added to ``covered`` at each sample (0 where none).
        counted: (K,) the samples whose step was added.
        measured, failed: S and F.
        average_deviation: the mean deviation (None when S = 0).
        covered: the distance covered (the integer 0 when nothing was added, as the script).
        failure_percent: ``100 F / (S + F)`` (None without samples: the script divides by 0).
    """

    deviation: F64
    steps: F64
    counted: Bool
    measured: int
    failed: int
    average_deviation: float | None
    covered: float | int
    failure_percent: float | None

    @property
    def reliability(self) -> str | None:
        """``"97.5%"`` as the script wrote it (None without samples)."""
        if self.failure_percent is None:
            return None
        return percent_py2(100 - self.failure_percent, 1)

    @property
    def warning(self) -> str | None:
        if self.failure_percent is None or not self.failure_percent > 50:
            return None
        # the script's "%.1f%%" formatting, digit for digit
        percent = f"{self.failure_percent:.1f}%"
        return (
            f"{percent} of the time, mocap pose acquiring failed. Consider repeating the benchmark."
        )


def _sequential(values: F64) -> float:
    return float(np.add.accumulate(values)[-1]) if values.size else 0.0


def following(
    distance: F64,
    measured: Bool,
    robot_xy: F64,
    robot_ok: Bool,
    *,
    desired: float,
    minimum: float,
    maximum: float,
) -> Following:
    """The statistics of K samples: ``distance`` (K,) where ``measured``, the robot's
    (x, y) (K, 2) where ``robot_ok``."""
    s = int(measured.sum())
    f = int(measured.size - s)
    deviation = np.where(measured, np.abs(distance - desired), np.nan)
    in_range = measured & (distance >= minimum) & (distance <= maximum)
    previous_ok = np.concatenate([[False], robot_ok[:-1]]) if robot_ok.size else robot_ok
    counted = in_range & robot_ok & previous_ok
    steps = np.zeros(distance.shape)
    if robot_xy.shape[0] > 1:
        delta = robot_xy[1:] - robot_xy[:-1]
        steps[1:] = np.sqrt(delta[:, 0] ** 2 + delta[:, 1] ** 2)
    steps = np.where(counted, steps, 0.0)
    covered: float | int = _sequential(steps[counted]) if counted.any() else 0
    return Following(
        deviation,
        steps,
        counted,
        s,
        f,
        _sequential(deviation[measured]) / float(s) if s else None,
        covered,
        f / float(s + f) * 100 if s + f else None,
    )
