"""What the trajectory's perturbed statistics depend on, per compared pose, and the closed
forms of the mean-like ones (issue 39; the model: docs/uncertainty.md, "Closed forms")."""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
import numpy.typing as npt

from ertools.arrays import F64
from ertools.benchmarks.common.closed_forms import (
    AngleMoments,
    Raw,
    SumMoments,
    angle_moments,
    chi3_moments,
    chi3_squared_moments,
    circular_mean_moments,
    lag_mixture,
    lag_nodes,
    mean_moments,
    mix_angles,
)
from ertools.benchmarks.common.draws import BAND_SIGMAS
from ertools.frozen_dataclass import frozen_dataclass


@frozen_dataclass(eq=False)
class PoseTerms:
    """What the perturbed statistics of the compared poses depend on, per pose (float64).

    Attributes:
        error: (n, 3) robot minus GT position.
        theta: (n,) wrapped yaw difference robot minus GT; raw: 2015's unwrapped one.
        sigma, sigma_yaw: (n,) the noise of the GT pose used (interpolation averages two).
        velocity, yaw_rate: (n, 3), (n,) of the GT around the pose.
        period: (n,) the GT frame period around the pose, seconds.
        lag: (low, high) of the frame lag in periods (hold: (-1, 0), nearest: (-0.5,
            0.5)); None for ``linear``.
        distance: (n,) |error| when the caller has it (the association's distances, the
            same bits); None: computed from ``error`` where needed.
    """

    error: F64
    theta: F64
    raw: F64
    sigma: F64
    sigma_yaw: F64
    velocity: F64
    yaw_rate: F64
    period: F64
    lag: tuple[float, float] | None
    distance: F64 | None = None

    def norms(self) -> F64:
        """(n,) |error|: ``distance``, or the square root of the squares summed in order."""
        if self.distance is not None:
            return self.distance
        e = self.error
        return np.asarray(np.sqrt(e[:, 0] ** 2 + e[:, 1] ** 2 + e[:, 2] ** 2), dtype=np.float64)

    def take(self, rows: npt.NDArray[np.intp]) -> PoseTerms:
        """The terms of the poses ``rows``."""

        def pick(a: F64) -> F64:
            return np.asarray(np.take(a, rows, axis=0), dtype=np.float64)

        return PoseTerms(
            error=pick(self.error),
            theta=pick(self.theta),
            raw=pick(self.raw),
            sigma=pick(self.sigma),
            sigma_yaw=pick(self.sigma_yaw),
            velocity=pick(self.velocity),
            yaw_rate=pick(self.yaw_rate),
            period=pick(self.period),
            lag=self.lag,
            distance=None if self.distance is None else pick(self.distance),
        )

    def mean_like(self, noise: bool, lag: bool) -> list[Callable[[F64], F64]]:
        """For each of the mean-like statistics (position error, orientation error, RMSE, 2015
        orientation error): a function of standard normal draws z giving the statistic's
        values under the sources (closed forms: the intervals module's doc)."""
        mean, orient, squares, o2015 = self.moments(noise, lag)

        def rmse(z: F64) -> F64:
            return np.asarray(np.sqrt(np.maximum(squares.draw(z), 0.0)), dtype=np.float64)

        return [mean.draw, orient.draw, rmse, o2015.draw]

    def thinned_mean_like(
        self, noise: bool, lag: bool, full: tuple[float, float], count: int
    ) -> list[Callable[[F64], F64]]:
        """:meth:`mean_like` of a comparison of more than ``count`` poses without a frame
        lag, the yaw's terms from fewer poses (the distances' from every pose): every pose
        near a fold of sin|x| and ``count`` of the others spread evenly, weighted
        (:func:`_circular`); ``full``: the orientation errors of every pose."""
        n = len(self.sigma)
        if n <= count or (lag and self.lag is not None):
            return self.mean_like(noise, lag)
        s = self.sigma if noise else np.zeros_like(self.sigma)
        sy = self.sigma_yaw if noise else np.zeros_like(self.sigma_yaw)
        d = self.norms()
        mean = mean_moments(chi3_moments(d, s))
        squares = mean_moments(chi3_squared_moments(d, s))
        orient = _circular(self.theta, sy, False, count, full[0])
        o2015 = _circular(self.raw, sy, True, count, full[1])

        def rmse(z: F64) -> F64:
            return np.asarray(np.sqrt(np.maximum(squares.draw(z), 0.0)), dtype=np.float64)

        return [mean.draw, orient.draw, rmse, o2015.draw]

    def moments(
        self, noise: bool, lag: bool
    ) -> tuple[SumMoments, SumMoments, SumMoments, SumMoments]:
        """The closed-form moments of the mean distance, the orientation error, the mean
        square and the 2015 orientation error."""
        nodes = lag_nodes(*self.lag) if lag and self.lag is not None else np.zeros(1)
        s = self.sigma if noise else np.zeros_like(self.sigma)
        sy = self.sigma_yaw if noise else np.zeros_like(self.sigma_yaw)
        dist: list[Raw] = []
        square: list[Raw] = []
        wrapped: list[AngleMoments] = []
        unwrapped: list[AngleMoments] = []
        for node in nodes:
            shift = node * self.period
            d = np.sqrt(np.sum(np.square(self.error - shift[:, None] * self.velocity), axis=1))
            dist.append(chi3_moments(d, s))
            square.append(chi3_squared_moments(d, s))
            turn = shift * self.yaw_rate
            wrapped.append(angle_moments(self.theta - turn, sy))
            unwrapped.append(angle_moments(self.raw - turn, sy, unwrapped=True))
        one = len(nodes) == 1
        mean = mean_moments(dist[0] if one else lag_mixture(dist))
        squares = mean_moments(square[0] if one else lag_mixture(square))
        orient = circular_mean_moments(wrapped[0] if one else mix_angles(wrapped))
        o2015 = circular_mean_moments(unwrapped[0] if one else mix_angles(unwrapped))
        return mean, orient, squares, o2015

    def bounds(self, noise: bool, lag: bool) -> F64:
        """How far each pose's distance can move in any draw (noise: BAND_SIGMAS sigma)."""
        out = np.zeros(len(self.sigma))
        if noise:
            out += BAND_SIGMAS * self.sigma
        if lag and self.lag is not None:
            reach = max(abs(self.lag[0]), abs(self.lag[1])) * self.period
            out += reach * np.sqrt(np.sum(self.velocity**2, axis=1))
        return out


# A pose whose |sin x| is within this many yaw sigmas of 0 is near the fold of sin|x|, where
# its moments change fast with it (angle_moments' folded normal reaches 10 sigmas)
NEAR_FOLD = 12.0


def _sums(m: AngleMoments) -> F64:
    """(sum a, sum b, sum var a, sum var b, sum cov ab) of per-pose angle moments."""
    va = np.maximum(m.ea2 - m.ea**2, 0.0)
    vb = np.maximum(m.eb2 - m.eb**2, 0.0)
    terms = (m.ea, m.eb, va, vb, m.eab - m.ea * m.eb)
    return np.array([float(np.sum(t)) for t in terms])


def _circular(angle: F64, sy: F64, unwrapped: bool, count: int, full: float) -> SumMoments:
    """:func:`circular_mean_moments` of ``angle``'s poses from those near a fold (all) and
    ``count`` of the others spread evenly, weighted by how many each stands for. Away from
    the folds the moments vary slowly (the bias |sin x| (e^(-s^2/2) - 1), the variances
    s^2 cos^2 x and s^2 sin^2 x), so the weighted sums are those of every pose to a fraction
    of a per cent; the mean is ``full`` plus the bias the weighted poses show."""
    sn = np.sin(angle)
    near = np.abs(sn) <= NEAR_FOLD * sy
    rest = np.flatnonzero(~near)
    if len(rest) <= count:
        return circular_mean_moments(angle_moments(angle, sy, unwrapped=unwrapped))
    # more than count rows: steps over 1, so the rounded picks are distinct and increasing
    pick = rest[np.linspace(0, len(rest) - 1, count).round().astype(np.intp)]
    weight = len(rest) / len(pick)
    close = np.flatnonzero(near)
    total = _sums(angle_moments(angle[close], sy[close], unwrapped=unwrapped))
    total += weight * _sums(angle_moments(angle[pick], sy[pick], unwrapped=unwrapped))
    a, b, va, vb, cab = (float(x) for x in total)

    def folded(rows: npt.NDArray[np.intp]) -> tuple[float, float]:
        x = angle[rows]
        up = np.sin(np.abs(x)) if unwrapped else np.abs(sn[rows])
        return float(np.sum(up)), float(np.sum(np.cos(x)))

    (ua, ub), (wa, wb) = folded(close), folded(pick)
    plain = math.atan2(ua + weight * wa, ub + weight * wb)
    r2 = a * a + b * b
    var = (b * b * va + a * a * vb - 2.0 * a * b * cab) / r2**2 if r2 > 0.0 else 0.0
    return SumMoments(full + math.atan2(a, b) - plain, max(var, 0.0), 0.0)
