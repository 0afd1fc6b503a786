"""What the scripts' Python 2.7 (and genpy, PyYAML 3, tf.transformations) did to numbers and text.

- :func:`py2_round`: Python 2.7's ``round(x, n)``: the exact binary value rounded to n decimals,
  ties away from zero (Python 3 rounds ties to even), then the nearest float.
- :func:`py2_str`: ``str(float)``: 12 significant digits (``%.12g``), ``.0`` added when the text
  has no point, exponent, ``inf`` or ``nan``.
- :func:`to_sec`: ``genpy.Duration.to_sec()``: ``float(secs) + float(nsecs) / 1e9`` with
  ``nsecs`` in [0, 1e9).
- :func:`dump_pose2d`, :func:`dump_none`, :func:`dump_request`: ``yaml.dump`` of a
  ``geometry_msgs/Pose2D`` message (genpy pickles its slots as a list, so PyYAML writes a
  ``python/object/new`` mapping with a ``state`` list), of None and of a goal request, with
  PyYAML 3's default flow style (``None``: collections of scalars inline; PyYAML 5.1 changed
  the default to block style).
- :func:`euler_yaw`: the z angle of ``tf.transformations.euler_from_quaternion`` (static x-y-z
  axes): ``atan2(R10, R00)`` of the normalised rotation matrix, 0 at gimbal lock.
"""

from __future__ import annotations

import math
from decimal import ROUND_HALF_UP, Decimal
from typing import Any

import yaml

NS = 1_000_000_000
_EPS4 = 4.0 * 2.220446049250313e-16  # tf.transformations' _EPS (numpy's float64 eps * 4)


def py2_round(x: float, ndigits: int) -> float:
    """Python 2.7's ``round``: half away from zero on the float's exact decimal value."""
    if math.isnan(x) or math.isinf(x):
        return x
    exact = Decimal(x)
    quantum = Decimal(1).scaleb(-ndigits)
    return float(exact.quantize(quantum, rounding=ROUND_HALF_UP))


def py2_str(x: float) -> str:
    """Python 2.7's ``str`` of a float."""
    if math.isnan(x):
        return "nan"
    if math.isinf(x):
        return "inf" if x > 0 else "-inf"
    text = "%.12g" % x
    if not any(c in text for c in ".e"):
        text += ".0"
    return text


def to_sec(ns: int) -> float:
    """``genpy.Duration(nsecs=ns).to_sec()``: seconds and nanoseconds added as floats."""
    secs, nsecs = divmod(int(ns), NS)
    return float(secs) + float(nsecs) / 1e9


class _Pose2D:
    def __init__(self, x: Any, y: Any, theta: Any) -> None:
        self.state = [x, y, theta]


class _Py2Dumper(yaml.Dumper):
    """PyYAML's default dumper (as Python 2's ``yaml.dump`` used it) knowing genpy's Pose2D."""


def _represent_pose2d(dumper: yaml.Dumper, data: _Pose2D) -> yaml.Node:
    tag = "tag:yaml.org,2002:python/object/new:geometry_msgs.msg._Pose2D.Pose2D"
    return dumper.represent_mapping(tag, {"state": data.state})


_Py2Dumper.add_representer(_Pose2D, _represent_pose2d)


def dump_pose2d(x: Any, y: Any, theta: Any) -> str:
    """``yaml.dump(Pose2D(x, y, theta))`` as Python 2 wrote it (default flow style)."""
    return str(yaml.dump(_Pose2D(x, y, theta), Dumper=_Py2Dumper, default_flow_style=None))


def dump_none() -> str:
    """``yaml.dump(None)``."""
    return str(yaml.dump(None, default_flow_style=None))


def dump_request(request: Any) -> str:
    """``yaml.dump`` of a goal request (the BmBox's payload text)."""
    return str(yaml.dump(request, default_flow_style=None))


def euler_yaw(q: tuple[float, float, float, float]) -> float:
    """``euler_from_quaternion(q)[2]`` (q as x, y, z, w), statement by statement."""
    x, y, z, w = (float(v) for v in q)
    nq = x * x + y * y + z * z + w * w
    if nq < _EPS4:
        return 0.0  # the identity matrix
    s = math.sqrt(2.0 / nq)
    x, y, z, w = x * s, y * s, z * s, w * s
    m00 = 1.0 - y * y - z * z
    m10 = x * y + z * w
    cy = math.sqrt(m00 * m00 + m10 * m10)
    if cy > _EPS4:
        return math.atan2(m10, m00)
    return 0.0
