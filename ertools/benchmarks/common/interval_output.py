"""How a benchmark takes the interval options and prints its intervals (issue 28).

The engine (:mod:`ertools.benchmarks.common.uncertainty`) computes intervals; this module holds
what every benchmark shares around it: the three options as one frozen value
(:class:`IntervalSettings`), the one stderr line of a score with its interval, the method and
the sources' shares (:func:`interval_line`, :func:`interval_lines`), and small helpers for the
result's outputs.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

from ertools.benchmarks.common.inputs import IntervalSettings
from ertools.benchmarks.common.uncertainty import Interval, Uncertainty
from ertools.frozen_dataclass import frozen_dataclass

#: The method named in the ``uncertainty`` block and on stderr.
METHOD = "Monte Carlo over the sources, basic (bias-correcting) bootstrap interval"


@frozen_dataclass
class ResultIntervals:
    """The intervals of one result, by score key (dotted for nested ones), and how they were
    obtained (None without intervals)."""

    intervals: Mapping[str, Interval | None]
    uncertainty: Uncertainty | None


NO_INTERVALS = ResultIntervals({}, None)


def withheld(
    keys: Sequence[str], reason: str, settings: IntervalSettings, method: str = ""
) -> ResultIntervals:
    """No interval for any of ``keys`` (each ``null`` in the result), and why."""
    return ResultIntervals(
        dict.fromkeys(keys),
        Uncertainty(
            settings.confidence,
            method or METHOD,
            settings.draws,
            settings.seed,
            (),
            {},
            dict.fromkeys(keys, reason),
        ),
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


#: Every interval is drawn by :func:`~ertools.benchmarks.common.uncertainty.monte_carlo`: the
#: stderr line names the method by this; the ``uncertainty`` block states it in full (the kind
#: of interval, what is mirrored).
METHOD_NAME = "Monte Carlo"
#: The CLI wraps its error lines at 200 characters; an interval line stays within them.
MAX_LINE = 200


@frozen_dataclass
class ScoreRow:
    """One score to print with its interval: ``value`` and the interval in SI units, shown
    times ``scale`` in ``unit`` (``1000.0``, ``mm``)."""

    name: str
    value: float | None
    interval: Interval | None
    scale: float = 1.0
    unit: str = ""
    key: str = ""  # the score's key in the result (default: ``name``)


def _num(x: float) -> str:
    return f"{x:.4g}"


def interval_line(row: ScoreRow, uncertainty: Uncertainty, *, top: int = 3) -> str:
    """The one stderr line of a score with its interval, in every benchmark:
    ``interval: best_distance_error 0.639 mm [0.41, 0.88] mm at 95% (Monte Carlo, 400 draws,
    seed 0; mocap_noise 71%, d_min 29%)``: the score, its interval at the level, the method
    and the ``top`` sources by share (fewer when the line would pass :data:`MAX_LINE`).
    Without an interval (too few draws scored): ``interval: NAME VALUE: no 95% interval
    (...)``."""
    if row.value is None:
        raise ValueError(f"{row.name}: no score, no interval line")
    u = f" {row.unit}" if row.unit else ""
    head = f"interval: {row.name} {_num(row.value * row.scale)}{u}"
    level = f"{uncertainty.confidence * 100:g}%"
    how = f"{METHOD_NAME}, {uncertainty.draws} draws, seed {uncertainty.seed}"
    iv = row.interval
    withheld = uncertainty.withheld.get(row.key or row.name)
    if iv is None and withheld:
        return f"{head}: no {level} interval ({withheld})"
    if iv is None:
        return f"{head}: no {level} interval ({how}: too few draws scored)"
    span = f"[{_num(iv.low * row.scale)}, {_num(iv.high * row.scale)}]{u}"
    ranked = sorted(iv.shares, key=lambda s: -s[1])
    for n in range(min(top, len(ranked)), 0, -1):
        shares = ", ".join(f"{name} {share * 100:.0f}%" for name, share in ranked[:n])
        line = f"{head} {span} at {level} ({how}; {shares})"
        if len(line) <= MAX_LINE:
            return line
    return f"{head} {span} at {level} ({how})"


def sources_line(uncertainty: Uncertainty) -> str:
    """The sources of the intervals in one stderr line: each one's size, measured from the
    data or a stated default."""
    parts = [
        f"{s.name} {s.value:.3g} {s.unit} ({'measured' if s.measured else 'default'})"
        for s in uncertainty.sources
    ]
    return "interval sources: " + "; ".join(parts)


def interval_lines(rows: Sequence[ScoreRow], uncertainty: Uncertainty | None) -> list[str]:
    """The stderr lines of a result's intervals, the same in every benchmark: one
    :func:`interval_line` per score that has a value, then the :func:`sources_line`; none
    without intervals (``--draws 0``)."""
    if uncertainty is None:
        return []
    out = [interval_line(r, uncertainty) for r in rows if r.value is not None]
    return [*out, sources_line(uncertainty)] if uncertainty.sources else out


def score_table(rows: Sequence[ScoreRow]) -> list[dict[str, Any]]:
    """The ``scores`` table of a report: each score in SI units with its interval's ends."""
    return [
        {
            "score": r.name,
            "value": r.value,
            "low": None if r.interval is None else r.interval.low,
            "high": None if r.interval is None else r.interval.high,
        }
        for r in rows
    ]


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
