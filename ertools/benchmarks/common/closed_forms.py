"""Sampling distributions of error statistics under Gaussian measurement noise, in closed
form (issue 39): what the intervals use instead of redrawing every pose.

A statistic that averages over many poses (a mean distance, a mean of squared distances, a
circular mean of angles) is a sum of independent per-pose terms when each pose carries its
own noise: its distribution is fixed by the per-pose moments, which have closed forms, and is
close to normal over many poses (the skewness left is corrected to first order, Cornish-
Fisher). The derivations and their assumptions are in docs/uncertainty.md ("Closed forms").

- :func:`chi3_moments`: the distance ``|e + s z|`` of a 3D error ``e`` whose end carries
  noise ``s z`` (``z`` standard normal per axis): a noncentral chi distribution with three
  degrees of freedom, exact moments.
- :func:`chi3_squared_moments`: its square, a scaled noncentral chi-square.
- :func:`angle_moments`: ``|sin x|`` (or 2015's unwrapped ``sign(x) sin x``) and ``cos x``
  of a noisy angle ``x``, the terms of ``atan2(sum sin|x|, sum cos|x|)``.
- :func:`mean_moments`, :func:`circular_mean_moments`: those summed over the poses.

What has no closed form worth its risk (the order statistics) is drawn
(:mod:`ertools.benchmarks.common.draws`).

Pure NumPy (no SciPy on the trajectory's import path): erf is taken from :mod:`math` for
the few arguments where it is not 1 to double precision. Cubes are products, not powers
(a power is a libm or SIMD call, slower and not the same bits on every CPU).
"""

from __future__ import annotations

import math

import numpy as np

from ertools.arrays import F64
from ertools.frozen_dataclass import frozen_dataclass

SQRT_2_PI = math.sqrt(2.0 / math.pi)
INV_SQRT_2PI = 1.0 / math.sqrt(2.0 * math.pi)
# Above this ratio of distance to noise, erf(nu / sqrt 2) is 1 and phi(nu) 0 in double
# precision (erfc(10 / sqrt 2) = 1.5e-23): the moments take their exact large-nu forms.
LARGE_NU = 10.0
# Gauss-Legendre nodes over a uniform lag: a pose's moments are smooth in the lag, and 8
# nodes integrate polynomials of degree 15 exactly.
LAG_NODES = 8


def _erf(x: F64) -> F64:
    """erf of each element (math.erf: exact to double precision; used on few elements)."""
    return np.array([math.erf(v) for v in np.asarray(x, dtype=np.float64).tolist()])


def _phi(x: F64) -> F64:
    return np.asarray(INV_SQRT_2PI * np.exp(-0.5 * x * x), dtype=np.float64)


def _big_phi(x: F64) -> F64:
    """The standard normal CDF of each element."""
    return np.asarray(0.5 * (1.0 + _erf(np.asarray(x) / math.sqrt(2.0))), dtype=np.float64)


@frozen_dataclass
class Raw:
    """Raw moments E[X], E[X^2], E[X^3] of per-pose terms (arrays of one shape): averaging
    them over a lag's nodes gives the moments of the mixture."""

    m1: F64
    m2: F64
    m3: F64

    def central(self) -> tuple[F64, F64, F64]:
        """(mean, variance, third central moment)."""
        m1, m2, m3 = self.m1, self.m2, self.m3
        var = np.maximum(m2 - m1 * m1, 0.0)
        k3 = m3 - 3.0 * m1 * m2 + 2.0 * (m1 * m1 * m1)
        return m1, var, k3


def chi3_moments(d: F64, s: F64) -> Raw:
    """Raw moments of R = |e + s z| with |e| = ``d``, z ~ N(0, I3), ``s`` >= 0 per element.

    R / s is noncentral chi with 3 degrees of freedom and nu = d / s. With E = erf(nu / sqrt
    2) and phi the normal density (docs/uncertainty.md derives them from the normal's partial
    moments):

        E[R]   = s (2 phi(nu) + (nu + 1/nu) E)
        E[R^2] = s^2 (nu^2 + 3)
        E[R^3] = s^3 (2 phi(nu) (nu^2 + 5) + (nu^3 + 6 nu + 3/nu) E)

    For nu > :data:`LARGE_NU` (and s = 0) E = 1 and phi = 0 exactly in double precision;
    the moments are then written about d, where the large terms cancel by hand: the mean is
    d + s^2/d, the variance s^2 (1 - s^2/d^2), the third central moment 2 s^6 / d^3.
    """
    d = np.asarray(d, dtype=np.float64)
    s = np.broadcast_to(np.asarray(s, dtype=np.float64), d.shape)
    with np.errstate(divide="ignore", invalid="ignore"):
        nu = np.where(s > 0.0, d / np.where(s > 0.0, s, 1.0), np.inf)
    large = nu > LARGE_NU
    mean = np.empty(d.shape)
    var = np.empty(d.shape)
    k3 = np.empty(d.shape)
    if large.all():
        # every pose far from its noise (a long comparison): no rows gathered and scattered
        r = np.divide(s * s, d, out=np.zeros_like(d), where=d > 0.0)
        return _raw_of(d + r, s * s - r * r, 2.0 * (r * r * r))
    if large.any():
        dl, sl = d[large], s[large]
        r = np.divide(sl * sl, dl, out=np.zeros_like(dl), where=dl > 0.0)  # s = 0: exact d
        mean[large] = dl + r
        var[large] = sl * sl - r * r
        k3[large] = 2.0 * (r * r * r)
    small = ~large
    if small.any():
        v, sv = nu[small], s[small]
        e = _erf(v / math.sqrt(2.0))
        ph = _phi(v)
        with np.errstate(divide="ignore", invalid="ignore"):
            e_over = np.where(v > 0.0, e / np.where(v > 0.0, v, 1.0), SQRT_2_PI)
        m1 = 2.0 * ph + v * e + e_over
        m2 = v * v + 3.0
        m3 = 2.0 * ph * (v * v + 5.0) + (v**3 + 6.0 * v) * e + 3.0 * e_over
        mu, va, c3 = Raw(m1, m2, m3).central()
        mean[small] = sv * mu
        var[small] = sv * sv * va
        k3[small] = (sv * sv * sv) * c3
    return _raw_of(mean, var, k3)


def _raw_of(mean: F64, var: F64, k3: F64) -> Raw:
    """Raw moments from (mean, variance, third central moment)."""
    m2 = var + mean * mean
    return Raw(mean, m2, k3 + 3.0 * mean * var + mean * mean * mean)


def chi3_squared_moments(d: F64, s: F64) -> Raw:
    """Raw moments of R^2 = |e + s z|^2: s^2 times a noncentral chi-square with 3 degrees
    of freedom and noncentrality d^2 / s^2, whose cumulants are k + l, 2(k + 2 l),
    8(k + 3 l) (k = 3, l = d^2 / s^2): mean d^2 + 3 s^2, variance 4 d^2 s^2 + 6 s^4, third
    central moment 24 d^2 s^4 + 24 s^6."""
    d2 = np.asarray(d, dtype=np.float64) ** 2
    s2 = np.broadcast_to(np.asarray(s, dtype=np.float64) ** 2, d2.shape)
    return _raw_of(
        d2 + 3.0 * s2, 4.0 * d2 * s2 + 6.0 * s2 * s2, 24.0 * d2 * s2 * s2 + 24.0 * (s2 * s2 * s2)
    )


def lag_mixture(raw_at: list[Raw]) -> Raw:
    """The raw moments of a term whose lag is uniform, from its moments at the
    :func:`lag_nodes` (Gauss-Legendre: the average weighted by the nodes' weights)."""
    _, w = np.polynomial.legendre.leggauss(len(raw_at))
    w = w / 2.0
    m1 = sum(wk * r.m1 for wk, r in zip(w, raw_at, strict=True))
    m2 = sum(wk * r.m2 for wk, r in zip(w, raw_at, strict=True))
    m3 = sum(wk * r.m3 for wk, r in zip(w, raw_at, strict=True))
    return Raw(np.asarray(m1), np.asarray(m2), np.asarray(m3))


def lag_nodes(low: float, high: float, count: int = LAG_NODES) -> F64:
    """Gauss-Legendre nodes of a lag uniform over [low, high] (in periods)."""
    x, _ = np.polynomial.legendre.leggauss(count)
    return np.asarray(low + (x + 1.0) / 2.0 * (high - low), dtype=np.float64)


@frozen_dataclass
class SumMoments:
    """Mean, variance and skewness of a statistic that sums independent per-pose terms."""

    mean: float
    var: float
    skew: float

    def draw(self, z: F64) -> F64:
        """Values of the statistic for standard normal ``z``: mean + sd * w with w the
        Cornish-Fisher correction of z for the skewness, z + skew (z^2 - 1) / 6, taken while
        it is monotone (|skew| <= 1: beyond, the normal alone)."""
        sd = math.sqrt(max(self.var, 0.0))
        g = self.skew if abs(self.skew) <= 1.0 else 0.0
        return np.asarray(self.mean + sd * (z + g / 6.0 * (z * z - 1.0)), dtype=np.float64)


def mean_moments(raw: Raw) -> SumMoments:
    """The moments of the mean of the n independent terms whose raw moments are ``raw``."""
    mean, var, k3 = raw.central()
    n = mean.size
    v = float(np.sum(var)) / n**2
    c3 = float(np.sum(k3)) / n**3
    skew = c3 / v**1.5 if v > 0.0 else 0.0
    return SumMoments(float(np.sum(mean)) / n, v, skew)


@frozen_dataclass
class AngleMoments:
    """Per-pose moments of a = sin|x| (wrapped; 2015: sign(x) sin x unwrapped) and
    b = cos x for a noisy angle x, summed by :func:`circular_mean_moments`."""

    ea: F64
    ea2: F64
    eb: F64
    eb2: F64
    eab: F64


def angle_moments(theta: F64, s: F64, *, unwrapped: bool = False) -> AngleMoments:
    """Moments of the terms of ``atan2(sum sin|x|, sum cos|x|)`` with x ~ N(theta, s^2).

    cos x and sin x have exact moments (E cos x = cos theta e^(-s^2/2), E cos^2 x = (1 + cos
    2 theta e^(-2 s^2)) / 2, ...). sin|x| = |sin x| for a wrapped x folds sin x at 0: for
    small s sin x is normal where it crosses 0 (it is linear there), so |sin x| is a folded
    normal there and sin x itself elsewhere (the same formula: the folding term vanishes).
    2015's unwrapped difference folds only at x = 0 (``sign(x) sin x`` is smooth at +-pi):
    for |theta| >= pi/2 the term is sign(theta) sin x. Cov(a, b) = E[sign sin x] Cov(sin x,
    cos x) (Stein's lemma on the linearised sine).
    """
    th = np.asarray(theta, dtype=np.float64)
    s2 = np.broadcast_to(np.asarray(s, dtype=np.float64) ** 2, th.shape)
    damp, damp4 = np.exp(-0.5 * s2), np.exp(-2.0 * s2)
    c, sn = np.cos(th), np.sin(th)
    eb = c * damp
    eb2 = 0.5 * (1.0 + np.cos(2.0 * th) * damp4)
    eu = sn * damp
    eu2 = 0.5 * (1.0 - np.cos(2.0 * th) * damp4)
    cov_ub = 0.5 * np.sin(2.0 * th) * damp4 - sn * c * damp * damp
    tau = np.sqrt(np.maximum(eu2 - eu * eu, 0.0))
    fold = np.ones(th.shape, dtype=bool)
    if unwrapped:
        fold = np.abs(th) < math.pi / 2.0
    ea = np.where(fold, np.abs(eu), np.sign(th) * eu)
    sign = np.where(fold, np.sign(eu), np.sign(th))
    # folded normal where the fold is within reach of the noise (|mu| < 10 tau): mean
    # tau sqrt(2/pi) exp(-mu^2 / 2 tau^2) + mu (1 - 2 Phi(-mu / tau)), E[sign] 1 - 2 Phi(.)
    near = fold & (np.abs(eu) < LARGE_NU * tau)
    if near.any():
        mu, t = eu[near], tau[near]
        r = mu / t
        k = 1.0 - 2.0 * _big_phi(-r)
        ea[near] = t * SQRT_2_PI * np.exp(-0.5 * r * r) + mu * k
        sign[near] = k
    eab = sign * cov_ub + ea * eb
    return AngleMoments(ea, eu2, eb, eb2, eab)


def mix_angles(at: list[AngleMoments]) -> AngleMoments:
    """:class:`AngleMoments` of a uniform lag's mixture, from its Gauss-Legendre nodes."""
    _, w = np.polynomial.legendre.leggauss(len(at))
    w = w / 2.0

    def avg(name: str) -> F64:
        return np.asarray(sum(wk * getattr(m, name) for wk, m in zip(w, at, strict=True)))

    return AngleMoments(avg("ea"), avg("ea2"), avg("eb"), avg("eb2"), avg("eab"))


def circular_mean_moments(m: AngleMoments) -> SumMoments:
    """Mean and variance of atan2(A, B), A = sum a, B = sum b over independent poses, by
    the delta method: A and B are sums of many terms (normal), atan2's gradient is
    (B, -A) / (A^2 + B^2); its curvature adds O(var / R^2), negligible at R ~ n."""
    va = np.maximum(m.ea2 - m.ea**2, 0.0)
    vb = np.maximum(m.eb2 - m.eb**2, 0.0)
    cab = m.eab - m.ea * m.eb
    a, b = float(np.sum(m.ea)), float(np.sum(m.eb))
    r2 = a * a + b * b
    if r2 <= 0.0:
        return SumMoments(math.atan2(a, b), 0.0, 0.0)
    var = b * b * float(np.sum(va)) + a * a * float(np.sum(vb)) - 2 * a * b * float(np.sum(cab))
    return SumMoments(math.atan2(a, b), max(var, 0.0) / r2**2, 0.0)
