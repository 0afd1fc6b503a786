"""Rank stability: how likely adjacent teams of a leaderboard are to swap places, and which
teams the data cannot order at the chosen confidence (docs/uncertainty.md, "Rank stability").

Each score comes with its confidence interval (``K_interval: [low, high]`` beside the score
key ``K`` in a result, at the result's ``uncertainty.confidence``). The model, stated once:

- a team's score is read as a normal distribution around its score whose spread on each side
  is that side's half of the interval: ``sigma = (high - score) / z`` above the score and
  ``(score - low) / z`` below, ``z`` the two-sided normal quantile of the interval's
  confidence (1.96 at 95 %). A symmetric interval is one normal; a skewed Monte Carlo
  interval keeps its skew where it matters, on the side facing the neighbour. An interval
  that does not hold its score (an older ertools wrote the trajectory's at the clock
  offset the data fits, not the one scored) is not read: that row is not assessed;
- the scores of two teams are independent (different executions, different mocap frames);
  an uncertainty source both share (the ``d_min`` of FBM3) moves both the same way and makes
  their difference *more* certain than this, so the model errs towards calling a tie;
- ``P(swap)`` of a team and the one ranked below it is the probability that the lower team's
  true score is better: with ``d`` the gap in the rule's direction and ``sigma_a``,
  ``sigma_b`` the facing sides, ``Phi(-d / sqrt(sigma_a**2 + sigma_b**2))``;
- the order of the pair is *not supported* (a tie) when ``P(swap) > (1 - confidence) / 2``:
  exactly when the two-sided interval of the difference at that confidence contains 0. Ties
  chain: when A-B and B-C are both unsupported, A, B and C form one group (shown ``=1``),
  even if A and C alone would be told apart.

Pure: numbers in, numbers out. :func:`interval_of` and :func:`confidence_of` read a result's
dict; :func:`stability` orders and groups a leaderboard.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import replace
from itertools import pairwise
from statistics import NormalDist
from typing import Any

from ertools.frozen_dataclass import frozen_dataclass

DEFAULT_CONFIDENCE = 0.95
NO_INTERVAL = "no interval in this result"
OUTSIDE_INTERVAL = "its interval does not hold its score (written by an older ertools)"
NEXT_NO_INTERVAL = "the next has no interval"
NOT_SCOREABLE = "unscoreable"
NONE_EXPLAINED = (
    "No result here has a confidence interval (written by an ertools without intervals, or "
    "scored without them): the ranks follow the values alone, and whether the data supports "
    "each order cannot be judged."
)


@frozen_dataclass
class Contender:
    """One entry of a leaderboard: a score and, when the result has one, its interval."""

    name: str
    score: float
    interval: tuple[float, float] | None = None
    confidence: float = DEFAULT_CONFIDENCE  # of ``interval``
    ident: str = ""  # the caller's own key (an execution), carried to the Standing
    note: str = ""  # why ``interval`` is None, when it is not for want of one

    def read(self) -> Contender:
        """Itself, or without its interval (and saying so) when the interval does not hold
        the score: the model reads the interval's sides around the score."""
        if self.interval is None or self.interval[0] <= self.score <= self.interval[1]:
            return self
        return replace(self, interval=None, note=OUTSIDE_INTERVAL)


@frozen_dataclass
class Standing:
    """A :class:`Contender` placed: its rank by the values (competition ranking: equal values
    share a rank), the probability it swaps with the next one, and its group of teams the
    data cannot order."""

    name: str
    score: float
    interval: tuple[float, float] | None
    rank: int
    p_swap_next: float | None  # None: the last row, or a neighbour without an interval
    group: int  # the rank of the group's first team (``=group`` when tied)
    tied_with: tuple[str, ...]  # the other teams of the group, in rank order
    note: str = ""  # why there is no P(swap): NO_INTERVAL
    ident: str = ""

    @property
    def tied(self) -> bool:
        return bool(self.tied_with)

    @property
    def marker(self) -> str:
        """``=2`` for a team of a tie group starting at rank 2, else its rank."""
        return f"={self.group}" if self.tied else str(self.rank)


def z_value(confidence: float) -> float:
    """The two-sided normal quantile: 1.959964 at 0.95."""
    if not 0.0 < confidence < 1.0:
        raise ValueError(f"confidence must be in (0, 1), got {confidence}")
    return NormalDist().inv_cdf((1.0 + confidence) / 2.0)


def p_swap(better: Contender, worse: Contender, *, lower_is_better: bool) -> float | None:
    """The probability that ``worse`` (ranked below ``better`` by the values) truly scores
    better than ``better``, by the model of the module's docstring; None without intervals."""
    if better.interval is None or worse.interval is None:
        return None
    sign = 1.0 if lower_is_better else -1.0
    gap = sign * (worse.score - better.score)  # >= 0 when the two are in rank order
    if not math.isfinite(gap):
        return None  # an infinite score (a hand-edited document): nothing to weigh
    # The sides that face each other: above the better score and below the worse one when
    # lower is better, the other way round when higher is.
    if lower_is_better:
        side_a = better.interval[1] - better.score
        side_b = worse.score - worse.interval[0]
    else:
        side_a = better.score - better.interval[0]
        side_b = worse.interval[1] - worse.score
    sigma_a = max(side_a, 0.0) / z_value(better.confidence)
    sigma_b = max(side_b, 0.0) / z_value(worse.confidence)
    sigma = math.hypot(sigma_a, sigma_b)
    if sigma == 0.0:
        return 0.5 if gap == 0.0 else float(gap < 0.0)
    return 0.5 * math.erfc(gap / (sigma * math.sqrt(2.0)))


def stability(
    contenders: Iterable[Contender],
    *,
    lower_is_better: bool,
    confidence: float = DEFAULT_CONFIDENCE,
) -> list[Standing]:
    """The leaderboard in rank order (stable: equal values keep the given order), with each
    pair's swap probability and the tie groups at ``confidence``.

    A pair is tied when ``P(swap) > (1 - confidence) / 2``, or when the values are equal
    (the rule itself ties them, with or without intervals). A pair with a missing interval
    is not assessed: kept in the rule's order, its row noting :data:`NO_INTERVAL`.
    """
    alpha_half = (1.0 - confidence) / 2.0
    z_value(confidence)  # validates
    sign = 1.0 if lower_is_better else -1.0
    ordered = sorted((c.read() for c in contenders), key=lambda c: sign * c.score)
    ranks: list[int] = []
    for i, c in enumerate(ordered):
        same = i > 0 and c.score == ordered[i - 1].score
        ranks.append(ranks[-1] if same else i + 1)
    probabilities: list[float | None] = []
    joined: list[bool] = []  # joined[i]: row i and row i + 1 are one group
    for a, b in pairwise(ordered):
        p = p_swap(a, b, lower_is_better=lower_is_better)
        probabilities.append(p)
        joined.append(a.score == b.score or (p is not None and p > alpha_half))
    probabilities.append(None)
    groups: list[list[int]] = []
    for i in range(len(ordered)):
        if i > 0 and joined[i - 1]:
            groups[-1].append(i)
        else:
            groups.append([i])
    out: list[Standing] = []
    for members in groups:
        for i in members:
            c = ordered[i]
            out.append(
                Standing(
                    name=c.name,
                    score=c.score,
                    interval=c.interval,
                    rank=ranks[i],
                    p_swap_next=probabilities[i],
                    group=ranks[members[0]],
                    tied_with=tuple(ordered[j].name for j in members if j != i),
                    note=_note(ordered, i),
                    ident=c.ident,
                )
            )
    return out


def _note(ordered: Sequence[Contender], i: int) -> str:
    if ordered[i].interval is None:
        return ordered[i].note or NO_INTERVAL
    if i + 1 < len(ordered) and ordered[i + 1].interval is None:
        return NEXT_NO_INTERVAL
    return ""


def percent(p: float) -> str:
    """``24.4 %``; ``< 0.1 %`` and ``> 99.9 %`` at the ends (a rounded 0.0 % reads as
    impossible)."""
    if p < 0.0005:
        return "< 0.1 %"
    if p > 0.9995:
        return "> 99.9 %"
    return f"{p * 100:.1f} %"


def _finite(value: Any) -> float | None:
    if isinstance(value, bool) or not isinstance(value, int | float):
        return None
    return float(value) if math.isfinite(value) else None


def interval_of(score: Mapping[str, Any] | None, key: str | None) -> tuple[float, float] | None:
    """``score[key + "_interval"]`` as (low, high), or None when absent or not two finite
    numbers with low <= high (an older result, a run without intervals)."""
    if not isinstance(score, Mapping) or not key:
        return None
    pair = score.get(f"{key}_interval")
    if not isinstance(pair, list | tuple) or len(pair) != 2:
        return None
    low, high = _finite(pair[0]), _finite(pair[1])
    if low is None or high is None or low > high:
        return None
    return low, high


def confidence_of(score: Mapping[str, Any] | None) -> float | None:
    """The result's ``uncertainty.confidence``, or None."""
    if not isinstance(score, Mapping):
        return None
    block = score.get("uncertainty")
    value = _finite(block.get("confidence")) if isinstance(block, Mapping) else None
    return value if value is not None and 0.0 < value < 1.0 else None


def board_confidence(confidences: Iterable[float | None]) -> float:
    """The confidence a leaderboard's ties are judged at: its results' own when they agree,
    the highest when they differ (the most cautious), 0.95 when none says."""
    said = {c for c in confidences if c is not None}
    return max(said) if said else DEFAULT_CONFIDENCE


def rule_key(rule: str) -> str:
    """The score key a registry rule's text names first: every ``Ranking.text`` starts with
    it (``best_distance_error (metres, the best run's ...): lower is better``)."""
    return rule.split(" ", 1)[0] if rule else ""


def ranked_key(score: Mapping[str, Any] | None, value: float | None, rule: str = "") -> str | None:
    """The top-level key of ``score`` holding the ranked ``value``: the one the rule's text
    names (:func:`rule_key`) when several keys hold that value."""
    if not isinstance(score, Mapping) or value is None:
        return None
    keys = [k for k, v in score.items() if _finite(v) == value]
    named = rule_key(rule)
    return named if named in keys else (keys[0] if keys else None)


def p_text(standing: Standing) -> str:
    """A row's ``P(swap with next)`` as shown: ``13.8 %``, or why there is none."""
    if standing.p_swap_next is None:
        return f"\u2014 ({standing.note})" if standing.note else "\u2014"
    return percent(standing.p_swap_next)


def unscoreable_reason(score: Mapping[str, Any] | None) -> str | None:
    """The reason of a result whose data cannot support a score (``status: unscoreable``)."""
    if not isinstance(score, Mapping) or score.get("status") != NOT_SCOREABLE:
        return None
    return str(score.get("unscoreable_reason") or "the data cannot support a score")


BEST_OF_RUNS = (
    " The score is the best of the execution's runs: its interval is the result's interval of "
    "that best-of-runs value (another run close behind the best widens it), not of one run."
)


def explanation(confidence: float, lower_is_better: bool, key: str | None = None) -> str:
    """The words above a leaderboard with rank stability (``key``: the ranked score key; a
    best-of-runs key, ``best_...``, says what its interval covers)."""
    pct = f"{confidence * 100:g} %"
    direction = "lower" if lower_is_better else "higher"
    return (
        f"Each score comes with its {pct} interval: where the score free of measurement "
        f"error lies, at that confidence, given the motion-capture noise and the other "
        f"uncertainties measured from the log. "
        f"'P(swap)' is the chance that the team below truly scored better ({direction} is "
        f"better), reading each interval as a normal spread around the score. Where that "
        f"chance exceeds {(1 - confidence) / 2 * 100:g} % (the {pct} interval of the "
        f"difference contains 0), the data does not support the order: those teams are "
        f"tied, shown '=' with the rank of the group's first team and bracketed in the plot."
    ) + (BEST_OF_RUNS if key and key.startswith("best_") else "")


def summary(standings: Sequence[Standing]) -> str:
    """``1 of 3 adjacent orders supported by the data; tied: b, c (=2)``: one line for a
    leaderboard (a pair not assessed, for want of an interval, is not counted as supported)."""
    pairs = list(pairwise(standings))
    joined = [a.group == b.group for a, b in pairs]
    unassessed = sum(
        a.p_swap_next is None and not j for (a, _), j in zip(pairs, joined, strict=True)
    )
    supported = len(pairs) - sum(joined) - unassessed
    parts = [f"{supported} of {len(pairs)} adjacent order(s) supported by the data"]
    if unassessed:
        why = NO_INTERVAL
        if any(s.note == OUTSIDE_INTERVAL for s in standings):
            why = f"{NO_INTERVAL}, or {OUTSIDE_INTERVAL}"
        parts.append(f"{unassessed} not assessed ({why})")
    groups: dict[int, list[str]] = {}
    for s in standings:
        if s.tied:
            groups.setdefault(s.group, []).append(s.name)
    if groups:
        parts.append(
            "tied: " + "; ".join(f"{', '.join(n)} (={g})" for g, n in sorted(groups.items()))
        )
    return "; ".join(parts)
