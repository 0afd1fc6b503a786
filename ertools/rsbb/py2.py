"""What the RSBB scripts' Python 2.7 did to the numbers and texts of a score.

The 2017-19 scripts ran on Python 2.7 with genpy (ROS Kinetic/Melodic). Three of its habits
reach the score fields, and a faithful ``--rules 2019``/``2017`` needs them:

- ``round(x, n)``: rounds the float's exact binary value to ``n`` decimals, halves away from
  zero (Python 3 rounds halves to even: ``round(0.125, 2)`` is 0.13 in 2.7, 0.12 in 3);
- ``str(float)``: 12 significant digits (``repr`` has 17), so ``str(round(87.25, 1))`` is
  ``87.3`` and ``str(1/3.0)`` is ``0.333333333333``;
- ``genpy.Duration.to_sec()``: whole seconds plus nanoseconds / 1e9 as two floats.
"""

from __future__ import annotations

import math
from decimal import ROUND_HALF_UP, Decimal

NS = 1_000_000_000


def round_py2(x: float, ndigits: int) -> float:
    """Python 2.7's ``round(x, ndigits)``."""
    if not math.isfinite(x):
        return x
    step = Decimal((0, (1,), -ndigits))  # 10 ** -ndigits, exactly
    return float(Decimal(x).quantize(step, rounding=ROUND_HALF_UP))


def str_py2(x: float) -> str:
    """Python 2.7's ``str`` of a float."""
    if math.isnan(x):
        return "nan"
    if math.isinf(x):
        return "-inf" if x < 0 else "inf"
    text = format(x, ".12g")
    return text if ("." in text or "e" in text) else text + ".0"


def to_sec(ns: int) -> float:
    """``genpy.Duration.to_sec()`` of a duration of ``ns`` nanoseconds (negative ones too:
    genpy keeps the nanoseconds in [0, 1e9))."""
    secs, nsecs = divmod(int(ns), NS)
    return float(secs) + float(nsecs) / 1e9


def percent_py2(value: float, ndigits: int) -> str:
    """``str(round(value, ndigits)) + '%'`` as the scripts wrote rates (``"60.0%"``)."""
    return str_py2(round_py2(value, ndigits)) + "%"
