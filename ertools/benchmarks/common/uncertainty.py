"""Confidence intervals of scores: the part every benchmark shares (issue 28).

A score is a function of measured poses. Each *source* of uncertainty (mocap noise, the
association of robot and GT times, the marker-set transform, FBM3's ``d_min``) is a way the
measurements could have come out differently around the truth. Each benchmark writes one
vectorised function that re-scores its runs ``draws`` times with the sources it is given
perturbed (a parametric bootstrap); this module turns those draws into intervals.

The interval is the *basic* (reverse-percentile) bootstrap interval,
``[2 s - q(1 - a/2), 2 s - q(a/2)]``: noise does not only spread a score, it biases it (a
robot exactly on its path still scores the noise's mean distance), and the basic interval
removes the bias the draws show instead of centring on the biased number. The score itself is
never changed: the interval is reported beside it.

Each source's *share* is the variance of the draws with only that source perturbed, over the
sum of those variances: the part of the interval that source explains (shares of sources
that interact need not add up to the interval's width exactly, which is why they are
normalised and called shares).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import field
from typing import Any

import numpy as np

from ertools.arrays import F64, nanquantiles
from ertools.benchmarks.common.inputs import (
    DEFAULT_CONFIDENCE,
    DEFAULT_DRAWS,
    DEFAULT_SEED,
    check_confidence,
)
from ertools.frozen_dataclass import frozen_dataclass

# How many measured samples a score needs behind it (docs/uncertainty.md, "Too few samples").
# An interval's width is measured from the samples themselves (the spread of the errors, the
# clock offset's standard error from their cross-correlation, the noise along a path): a
# spread estimated from n values is itself uncertain by about sqrt(2 / (n - 1)) of its size,
# more than half below 10 values, so an interval from fewer would state a precision the data
# cannot show: none is given (null, with the reason). Below 30 the width is known to within a
# quarter only, and a statistic of so few samples describes a moment more than a run (the p90
# of fewer than 10 values is their max): the score is given with a warning.
MIN_INTERVAL_SAMPLES = 10
MIN_SCORE_SAMPLES = 30

# The names of the sources, as they appear in outputs (``uncertainty.sources[].name``).
MOCAP_NOISE = "mocap_noise"
TIME_ASSOCIATION = "time_association"
TRANSFORM = "transform"
D_MIN = "d_min"


def z_value(confidence: float) -> float:
    """The two-sided normal quantile of ``confidence`` (1.959964 for 0.95)."""
    from statistics import NormalDist  # lazy: statistics, random, fractions, decimal: 3 ms

    return NormalDist().inv_cdf(0.5 + check_confidence(confidence) / 2.0)


def sigma_from_epsilon(epsilon: float) -> float:
    """Per-axis mocap noise sigma from ``ertools noise``'s epsilon.

    epsilon is the mean (x, y) distance between consecutive measurements of a still marker set.
    With independent normal noise of sigma per axis, the difference of two measurements is
    normal with sigma * sqrt(2) per axis, its length Rayleigh-distributed with mean
    sigma * sqrt(2) * sqrt(pi / 2) = sigma * sqrt(pi).
    """
    return epsilon / math.sqrt(math.pi)


@frozen_dataclass
class Source:
    """One source of uncertainty and the value used for it.

    Attributes:
        name: one of the names above (``mocap_noise``...).
        value: its size: a standard deviation, or a half-width for a uniform source.
        unit: SI unit of ``value`` (``m``, ``rad``, ``s``).
        measured: True when ``value`` was measured from the data, False for a stated default.
        note: how it was obtained, in words (``3 stationary phases, 1,204 pairs``).
    """

    name: str
    value: float
    unit: str
    measured: bool
    note: str = ""

    def to_dict(self) -> dict[str, Any]:
        return {
            "name": self.name,
            "value": self.value,
            "unit": self.unit,
            "measured": self.measured,
            "note": self.note,
        }


@frozen_dataclass
class Interval:
    """A confidence interval of one score, and each source's share of it."""

    low: float
    high: float
    shares: tuple[tuple[str, float], ...] = ()

    def as_list(self) -> list[float]:
        return [self.low, self.high]

    def contains(self, value: float) -> bool:
        return self.low <= value <= self.high

    def share_dict(self) -> dict[str, float]:
        return dict(self.shares)


@frozen_dataclass
class Uncertainty:
    """The ``uncertainty`` block of a result: how its intervals were obtained.

    ``shares`` maps a score's key (dotted for nested ones: ``runs_details.2.distance_error``)
    to each source's share of that score's interval; ``withheld`` a score's key to why it has
    no interval (too few samples behind it: :data:`MIN_INTERVAL_SAMPLES`).
    """

    confidence: float
    method: str
    draws: int
    seed: int
    sources: tuple[Source, ...]
    shares: Mapping[str, Mapping[str, float]]
    withheld: Mapping[str, str] = field(default_factory=dict)

    def to_dict(self) -> dict[str, Any]:
        out = {
            "confidence": self.confidence,
            "method": self.method,
            "draws": self.draws,
            "seed": self.seed,
            "sources": [s.to_dict() for s in self.sources],
            "shares": {k: dict(v) for k, v in self.shares.items()},
        }
        if self.withheld:
            out["withheld"] = dict(self.withheld)
        return out


def too_few(
    count: int, what: str, minimum: int = MIN_INTERVAL_SAMPLES, why: str = ""
) -> str | None:
    """Why a score of ``count`` samples (``what``: ``compared pose(s)``) gets no interval, or
    None when it has at least ``minimum`` (a benchmark whose sources need more says ``why``)."""
    if count >= minimum:
        return None
    return f"only {count} {what}: an interval needs at least {minimum}, " + (
        why or "its width being measured from them"
    )


def few_warning(count: int, what: str, where: str) -> str | None:
    """A warning for a score of fewer than :data:`MIN_SCORE_SAMPLES` samples, else None."""
    if count >= MIN_SCORE_SAMPLES:
        return None
    return (
        f"{where} rests on {count} {what} only (fewer than {MIN_SCORE_SAMPLES}): a statistic "
        "of so few samples says little of the whole run"
    )


def basic_intervals(estimate: F64, draws: F64, confidence: float) -> tuple[F64, F64]:
    """The basic bootstrap interval of each score.

    Args:
        estimate: (S,) the scores from the data.
        draws: (D, S) the scores re-computed from perturbed data; NaN where a draw could not
            be scored (left out).
        confidence: the level.

    Returns:
        (low, high), each (S,); NaN where a score has fewer than two finite draws.
    """
    est = np.asarray(estimate, dtype=np.float64)
    d = np.asarray(draws, dtype=np.float64)
    a = (1.0 - check_confidence(confidence)) / 2.0
    low = np.full(est.shape, np.nan)
    high = np.full(est.shape, np.nan)
    finite = np.isfinite(d)
    ok = np.sum(finite, axis=0) >= 2
    if ok.any():
        q = nanquantiles(d[:, ok], [a, 1.0 - a])
        low[ok] = 2.0 * est[ok] - q[1]
        high[ok] = 2.0 * est[ok] - q[0]
    return low, high


# perturbed(rng, sources, n) -> (n, S) scores re-computed with only ``sources`` perturbed
Perturbed = Callable[[np.random.Generator, frozenset[str], int], F64]
# variance() -> (S,) variance of the scores with one source alone perturbed, computed without
# random draws (a quadrature over the source's few dimensions)
AloneVariance = Callable[[], F64]


def monte_carlo(
    estimate: Sequence[float] | F64,
    perturbed: Perturbed,
    sources: Sequence[str],
    *,
    draws: int = DEFAULT_DRAWS,
    seed: int = DEFAULT_SEED,
    confidence: float = DEFAULT_CONFIDENCE,
    nonnegative: bool = True,
    alone_variance: Mapping[str, AloneVariance] | None = None,
) -> list[Interval | None]:
    """Intervals of ``S`` scores from draws with every source perturbed at once, and each
    source's share from draws with it alone.

    ``alone_variance`` gives, for some sources, their variance alone without a pass of
    draws. When one source is left without it, its variance is what the together pass's
    variance leaves over the others' (exact for sources whose effects add up; the shares
    say how the interval divides, not more), and no pass of draws is run for shares.

    Reproducible: the draws of each pass come from ``numpy.random.default_rng([seed, k])``,
    ``k`` = 0 for all sources together and 1.. for each source alone, whatever the order of
    the scores. ``nonnegative`` clips the low end at 0 for scores that cannot be negative
    (a distance): the truth is in the clipped interval whenever it was in the unclipped one.
    Every interval holds its score (a referee reads it as that score's): where the basic
    interval would lie wholly on one side of it (a bias larger than the spread: a score of
    noise alone), it is widened to the score, which can only add coverage.

    Returns one Interval per score, None where the score is not finite or the draws do not
    give one.
    """
    est = np.asarray(estimate, dtype=np.float64)
    if draws <= 0 or not sources or est.size == 0:
        return [None] * int(est.size)
    check_confidence(confidence)
    names = tuple(sources)
    together = np.asarray(perturbed(np.random.default_rng([seed, 0]), frozenset(names), draws))
    low, high = basic_intervals(est, together.reshape(draws, est.size), confidence)
    variances: list[F64] = []
    if len(names) > 1:
        given = dict(alone_variance or {})
        missing = [n for n in names if n not in given]
        by_name: dict[str, F64] = {n: np.asarray(f(), dtype=np.float64) for n, f in given.items()}
        if len(missing) == 1:
            rest = _nanvar(together.reshape(draws, est.size))
            for name in names:
                if name != missing[0]:
                    rest = rest - by_name[name]
            by_name[missing[0]] = np.maximum(rest, 0.0)
        else:
            for k, name in enumerate(names, start=1):
                if name in by_name:
                    continue
                rng = np.random.default_rng([seed, k])
                alone = perturbed(rng, frozenset((name,)), draws)
                by_name[name] = _nanvar(np.asarray(alone).reshape(draws, est.size))
        variances = [by_name[n] for n in names]
    out: list[Interval | None] = []
    for i in range(est.size):
        if not (math.isfinite(est[i]) and math.isfinite(low[i]) and math.isfinite(high[i])):
            out.append(None)
            continue
        lo = max(0.0, float(low[i])) if nonnegative else float(low[i])
        hi = max(lo, float(high[i]))
        # an interval holds its score: where the draws' bias is larger than their spread
        # (a score all noise), the reflected interval would pass it; it reaches it instead
        lo, hi = min(lo, float(est[i])), max(hi, float(est[i]))
        out.append(Interval(lo, hi, _shares(names, variances, i)))
    return out


def _nanvar(draws: F64) -> F64:
    """(S,) variance of each column's finite draws (0 with fewer than two)."""
    finite = np.sum(np.isfinite(draws), axis=0) >= 2
    var = np.zeros(draws.shape[1])
    if finite.any():
        var[finite] = np.nanvar(draws[:, finite], axis=0)
    return var


def _shares(names: tuple[str, ...], variances: list[F64], i: int) -> tuple[tuple[str, float], ...]:
    if len(names) == 1:
        return ((names[0], 1.0),)
    v = [float(var[i]) for var in variances]
    total = sum(v)
    if total <= 0.0:
        return tuple((n, 0.0) for n in names)
    return tuple((n, x / total) for n, x in zip(names, v, strict=True))


def interval_keys(
    data: Mapping[str, Any], intervals: Mapping[str, Interval | None]
) -> dict[str, Any]:
    """``data`` with ``K_interval: [low, high]`` inserted right after each key ``K`` that has
    an interval (None: ``K_interval: null``), the other keys in their order."""
    out: dict[str, Any] = {}
    for key, value in data.items():
        out[key] = value
        if key in intervals:
            iv = intervals[key]
            out[f"{key}_interval"] = None if iv is None else iv.as_list()
    return out


def split_interval(row: dict[str, Any], key: str) -> None:
    """A table row's ``K_interval: [low, high]`` as ``K_low`` and ``K_high`` columns (CSV),
    in its place."""
    name = f"{key}_interval"
    if name not in row:
        return
    pairs = list(row.items())
    row.clear()
    for k, v in pairs:
        if k == name:
            row[f"{key}_low"] = None if v is None else v[0]
            row[f"{key}_high"] = None if v is None else v[1]
        else:
            row[k] = v


def uncertainty_rows(uncertainty: Uncertainty) -> list[dict[str, Any]]:
    """The ``uncertainty`` block as table rows: one per score and source (its share, a
    fraction), with the source's size (text with its unit) and whether it was measured."""
    sources = {s.name: s for s in uncertainty.sources}
    rows: list[dict[str, Any]] = []
    for score, shares in uncertainty.shares.items():
        for name, share in shares.items():
            s = sources.get(name)
            rows.append(
                {
                    "score": score,
                    "source": name,
                    "share": share,
                    # one text cell: the sources' sizes are in different units
                    "size": None if s is None else f"{s.value:.6g} {s.unit}",
                    "measured": None if s is None else s.measured,
                    "confidence": uncertainty.confidence,
                    "draws": uncertainty.draws,
                    "seed": uncertainty.seed,
                }
            )
    return rows
