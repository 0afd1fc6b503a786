"""What an RSBB script's tf lookup returned from the mocap it was sent: the simulator's own model
of tf2, written from tf2's time cache and LinearMath and ``tf.transformations``, so that the
samples' live scores never come from the scorers' emulation (``ertools.rsbb.tf``).

A lookup at ``t`` takes each mocap link at ``t`` (the sample stamped ``t``, else the two around
it: translation ``(1 - r) a + r b``, rotation by LinearMath's shortest-path slerp, ``r`` from
``ros::Duration::toSec``), puts the script's fixed frame under it, and, for a lookup in another
body's frame, applies that body's inverse as tf2's full-path lookup does. The yaw is
``euler_from_quaternion``'s. A few lookups per run: plain Python, one lookup at a time.
"""

from __future__ import annotations

import bisect
import math
from collections.abc import Sequence

import numpy as np

from ertools.arrays import F64, I64
from ertools.frozen_dataclass import frozen_dataclass

Vec = tuple[float, float, float]
Quat = tuple[float, float, float, float]
_EPS = 4.0 * float(np.finfo(np.float64).eps)  # tf.transformations' _EPS


@frozen_dataclass(eq=False)
class Link:
    """One mocap body as tf had it: header stamps (sorted), translations, rotations."""

    stamps: I64
    xyz: F64
    quat_xyzw: F64


@frozen_dataclass
class Looked:
    """A lookup's result: the frame's position and rotation, and its yaw."""

    xyz: Vec
    quat: Quat
    yaw: float


def _sin(x: float) -> float:
    return float(np.sin(np.float64(x)))


def _acos(x: float) -> float:
    return float(np.arccos(np.float64(x)))


def _atan2(y: float, x: float) -> float:
    return float(np.arctan2(np.float64(y), np.float64(x)))


def _to_sec(ns: int) -> float:
    sec, nsec = divmod(ns, 1_000_000_000)
    return float(sec) + 1e-9 * float(nsec)


def _mul(a: Quat, b: Quat) -> Quat:
    """The Hamilton product, each term summed in the textbook order (LinearMath's order differs
    in the last bit at most; the committed samples were written with this one)."""
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    return (
        aw * bx + ax * bw + ay * bz - az * by,
        aw * by - ax * bz + ay * bw + az * bx,
        aw * bz + ax * by - ay * bx + az * bw,
        aw * bw - ax * bx - ay * by - az * bz,
    )


def _conj(q: Quat) -> Quat:
    return (-q[0], -q[1], -q[2], q[3])


def _rotate(q: Quat, v: Vec) -> Vec:
    """LinearMath's ``quatRotate``: ``(q * v) * q.inverse()`` (the conjugate, unnormalised)."""
    r = _mul(_mul(q, (v[0], v[1], v[2], 0.0)), _conj(q))
    return (r[0], r[1], r[2])


def _dot(a: Quat, b: Quat) -> float:
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3]


def _slerp(a: Quat, b: Quat, r: float) -> Quat:
    """LinearMath's ``Quaternion::slerp`` (half the shortest-path angle; ``a`` when it is 0)."""
    d_ab = _dot(a, b)
    scale = math.sqrt(_dot(a, a) * _dot(b, b))
    half = _acos(max(-1.0, min(1.0, abs(d_ab) / scale)))
    if half == 0.0:
        return a
    inv = 1.0 / _sin(half)
    s0, s1 = _sin((1.0 - r) * half), _sin(r * half)
    if d_ab < 0:
        s1 = -s1
    return (
        (a[0] * s0 + b[0] * s1) * inv,
        (a[1] * s0 + b[1] * s1) * inv,
        (a[2] * s0 + b[2] * s1) * inv,
        (a[3] * s0 + b[3] * s1) * inv,
    )


def _at(link: Link, t_ns: int) -> tuple[Vec, Quat]:
    """The link at ``t_ns`` as tf2's time cache gives it (inside its samples only)."""
    stamps = link.stamps.tolist()
    hi = bisect.bisect_right(stamps, t_ns)
    if hi == 0 or (hi == len(stamps) and stamps[-1] != t_ns):
        raise ValueError(f"lookup at {t_ns} outside the link's samples")
    lo = hi - 1
    a_t = tuple(float(v) for v in link.xyz[lo])
    a_q = tuple(float(v) for v in link.quat_xyzw[lo])
    if stamps[lo] == t_ns:
        return (a_t[0], a_t[1], a_t[2]), (a_q[0], a_q[1], a_q[2], a_q[3])
    b_t = [float(v) for v in link.xyz[hi]]
    b_q = [float(v) for v in link.quat_xyzw[hi]]
    r = _to_sec(t_ns - stamps[lo]) / _to_sec(stamps[hi] - stamps[lo])
    s = 1.0 - r
    xyz = (s * a_t[0] + r * b_t[0], s * a_t[1] + r * b_t[1], s * a_t[2] + r * b_t[2])
    q = _slerp((a_q[0], a_q[1], a_q[2], a_q[3]), (b_q[0], b_q[1], b_q[2], b_q[3]), r)
    return xyz, q


def _yaw(q: Quat) -> float:
    """``euler_from_quaternion(q)[2]`` (static x-y-z axes) of the normalised matrix."""
    n = _dot(q, q)
    if n < _EPS:
        return 0.0
    k = math.sqrt(2.0 / n)
    x, y, z, w = (v * k for v in q)
    m00 = 1.0 - y * y - z * z
    m10 = x * y + z * w
    if math.sqrt(m00 * m00 + m10 * m10) <= _EPS:
        return 0.0
    return _atan2(m10, m00)


def lookup(
    body: Link,
    t_ns: int,
    fixed: tuple[Sequence[float], Sequence[float]],
    reference: Link | None = None,
) -> Looked:
    """The script's frame (``fixed`` = translation, rotation under ``body``) at ``t_ns``, in
    the mocap root (``reference`` None) or in the body ``reference``."""
    ft, fq = fixed
    vec: Vec = (float(ft[0]), float(ft[1]), float(ft[2]))
    quat: Quat = (float(fq[0]), float(fq[1]), float(fq[2]), float(fq[3]))
    b_t, b_q = _at(body, t_ns)
    r = _rotate(b_q, vec)
    vec, quat = (r[0] + b_t[0], r[1] + b_t[1], r[2] + b_t[2]), _mul(b_q, quat)
    if reference is not None:
        ref_t, ref_q = _at(reference, t_ns)
        inv_q = _conj(ref_q)
        back = _rotate(inv_q, (-ref_t[0], -ref_t[1], -ref_t[2]))
        r = _rotate(inv_q, vec)
        vec, quat = (r[0] + back[0], r[1] + back[1], r[2] + back[2]), _mul(inv_q, quat)
    return Looked(vec, quat, _yaw(quat))
