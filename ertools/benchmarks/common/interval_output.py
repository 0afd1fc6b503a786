"""How a benchmark takes the interval options and prints its intervals (issue 28).

The engine (:mod:`ertools.benchmarks.common.uncertainty`) computes intervals; this module holds
what the FBM1 and trajectory benchmarks share around it: the three options as one frozen value
(:class:`IntervalSettings`), the stderr line of a score with its interval, the method and the
sources' shares (:func:`score_line`), and small helpers for the result's outputs.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

from ertools.benchmarks.common.uncertainty import (
    DEFAULT_CONFIDENCE,
    DEFAULT_DRAWS,
    DEFAULT_SEED,
    Interval,
    Uncertainty,
    check_confidence,
)

#: The method named in the ``uncertainty`` block and on stderr.
METHOD = "Monte Carlo over the sources, basic (bias-correcting) bootstrap interval"


@dataclass(frozen=True)
class ResultIntervals:
    """The intervals of one result, by score key (dotted for nested ones), and how they were
    obtained (None without intervals)."""

    intervals: Mapping[str, Interval | None]
    uncertainty: Uncertainty | None


NO_INTERVALS = ResultIntervals({}, None)


@dataclass(frozen=True)
class IntervalSettings:
    """``--confidence``, ``--draws`` and ``--seed`` as one value (draws 0: no intervals)."""

    draws: int = DEFAULT_DRAWS
    seed: int = DEFAULT_SEED
    confidence: float = DEFAULT_CONFIDENCE

    @property
    def enabled(self) -> bool:
        return self.draws > 0

    @staticmethod
    def from_values(values: Mapping[str, Any]) -> IntervalSettings:
        """From resolved input values (:data:`~ertools.benchmarks.common.uncertainty.
        INTERVAL_INPUTS`); a level outside (0, 1) is a usage error."""
        confidence = values.get("confidence")
        draws = values.get("draws")
        seed = values.get("seed")
        return IntervalSettings(
            DEFAULT_DRAWS if draws is None else int(draws),
            DEFAULT_SEED if seed is None else int(seed),
            check_confidence(DEFAULT_CONFIDENCE if confidence is None else float(confidence)),
        )


def shares_of(intervals: Mapping[str, Interval | None]) -> dict[str, dict[str, float]]:
    """Each interval's source shares by score key (the ``uncertainty.shares`` mapping)."""
    return {k: iv.share_dict() for k, iv in intervals.items() if iv is not None}


def as_list(iv: Interval | None) -> list[float] | None:
    return None if iv is None else iv.as_list()


def low_high(prefix: str, iv: Interval | None) -> dict[str, float]:
    """``{prefix_low, prefix_high}`` for a CSV row (NaN without an interval)."""
    if iv is None:
        return {f"{prefix}_low": math.nan, f"{prefix}_high": math.nan}
    return {f"{prefix}_low": iv.low, f"{prefix}_high": iv.high}


def score_line(
    key: str,
    value: float | None,
    iv: Interval | None,
    uncertainty: Uncertainty | None,
    *,
    scale: float = 1.0,
    unit: str = "",
    digits: int = 4,
    top: int = 2,
) -> str | None:
    """One stderr line: ``interval: pose_score 0.9312 [0.9301, 0.9322] (95%, Monte Carlo
    ..., 400 draws, seed 0; mocap_noise 71%, transform 29%)``; None without an interval."""
    if value is None or iv is None or uncertainty is None:
        return None
    u = f" {unit}" if unit else ""
    ranked = sorted(iv.shares, key=lambda s: -s[1])[:top]
    shares = ", ".join(f"{name} {share * 100:.0f}%" for name, share in ranked)
    level = f"{uncertainty.confidence * 100:g}%"
    return (
        f"interval: {key} {value * scale:.{digits}f}{u} "
        f"[{iv.low * scale:.{digits}f}, {iv.high * scale:.{digits}f}]{u} ({level}, "
        f"{uncertainty.method}, {uncertainty.draws} draws, seed {uncertainty.seed}; {shares})"
    )


def sources_line(uncertainty: Uncertainty | None) -> str | None:
    """The sources of the intervals in one stderr line (measured or a stated default)."""
    if uncertainty is None:
        return None
    parts = [
        f"{s.name} {s.value:.3g} {s.unit} ({'measured' if s.measured else 'default'})"
        for s in uncertainty.sources
    ]
    return "interval sources: " + "; ".join(parts)


def lines(
    rows: Sequence[tuple[str, float | None, Interval | None, float, str, int]],
    uncertainty: Uncertainty | None,
) -> list[str]:
    """The stderr lines of the main scores, then the sources line."""
    out = [
        score_line(k, v, iv, uncertainty, scale=s, unit=u, digits=d) for k, v, iv, s, u, d in rows
    ]
    out.append(sources_line(uncertainty))
    return [line for line in out if line]


def interval_tables(
    intervals: Mapping[str, Interval | None], uncertainty: Uncertainty | None
) -> dict[str, list[dict[str, Any]]]:
    """The ``interval_shares`` table (one row per score: each source's share of its interval;
    the intervals themselves are the ``_low``/``_high`` columns beside their scores) and the
    ``interval_sources`` table (each source's size, measured or default, and how), for the
    CSV files and the HTML report."""
    if uncertainty is None or not intervals:
        return {}
    names = [s.name for s in uncertainty.sources]
    rows = []
    for key, iv in intervals.items():
        shares = {} if iv is None else iv.share_dict()
        row: dict[str, Any] = {"score": key, "confidence": uncertainty.confidence}
        row.update({f"share_{n}": shares.get(n, math.nan) for n in names})
        rows.append(row)
    sources = [
        {
            "source": s.name,
            # mixed units (m, s, rad): the size is written with its own
            "size": f"{s.value:.6g} {s.unit}",
            "measured": s.measured,
            "method": uncertainty.method,
            "draws": uncertainty.draws,
            "seed": uncertainty.seed,
            "note": s.note,
        }
        for s in uncertainty.sources
    ]
    return {"interval_shares": rows, "interval_sources": sources}
