"""HPPF's arithmetic on arrays, once (docs/hppf.md, "Formula"; fbm4_people_perception.py at
2bb8a41, l. 190-215). No IO, no options parsing.

Per detected goal: ``position_error = sqrt((x_a - x_g)^2 + (y_a - y_g)^2)``, (x_g, y_g) the cap's
marker set in the testbed frame; ``recognized`` = the names equal lower-cased. Totals:
``Distance error`` = the position errors' sum (in order) / the goals detected;
``% Recognized persons`` = Python 2's ``str(round(recognized / float(N) * 100, 2)) + '%'``, N
the people of the config.
"""

from __future__ import annotations

import numpy as np

from ertools.arrays import F64
from ertools.rsbb.py2 import percent_py2


def position_errors(answer_xy: F64, truth_xy: F64) -> F64:
    """(n,) distances between (n, 2) answers and (n, 2) ground truths (l. 197-199)."""
    a = np.asarray(answer_xy, dtype=np.float64).reshape(-1, 2)
    g = np.asarray(truth_xy, dtype=np.float64).reshape(-1, 2)
    dx = a[:, 0] - g[:, 0]
    dy = a[:, 1] - g[:, 1]
    out: F64 = np.sqrt(dx**2 + dy**2)
    return out


def running_sum(values: F64) -> float:
    """The sum in order, one addition at a time, as the script's ``+=`` made it."""
    v = np.asarray(values, dtype=np.float64)
    return float(np.cumsum(v)[-1]) if v.size else 0.0


def distance_error(errors: F64, detected: int) -> float | None:
    """``position_error_sum / detected_sum`` (l. 215); None when nothing was detected."""
    return running_sum(errors) / detected if detected > 0 else None


def recognized_percent(recognized: int, people: int) -> str:
    """``str(round(recognized / float(N) * 100, 2)) + '%'`` (l. 214): ``60.0%``, ``66.67%``."""
    return percent_py2(recognized / float(people) * 100, 2)


def position_text(x: float, y: float) -> str:
    """``'(%.2f, %.2f)' % (x, y)`` (l. 209-210)."""
    return f"({x:.2f}, {y:.2f})"
