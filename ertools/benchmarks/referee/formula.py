"""The ERL rule as one number, so that a leaderboard orders the runs by it: most achievements,
then fewest penalised behaviours, then least time (ertools' reading, docs/rsbb.md)."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from ertools.benchmarks.referee.config import PENALTY_SCALE, TIME_SCALE
from ertools.benchmarks.referee.items import Tally, group_role


def erl_rank(t: Tally, seconds: float) -> float:
    """``achievements - penalties / 1e3 - seconds / 1e7``: higher is better, in the ERL order
    while penalties < 1000 and seconds < 10,000."""
    return float(t.achievements) - t.penalties / PENALTY_SCALE - seconds / TIME_SCALE


def exact_order(t: Tally, seconds: float) -> bool:
    """Whether :func:`erl_rank` keeps the ERL order for this run (else a warning says so)."""
    return t.penalties < PENALTY_SCALE and 0.0 <= seconds < TIME_SCALE / PENALTY_SCALE


_ROLE_LETTER = {"achievement": "A", "penalty": "P", "disqualifying": "D", "other": "O"}


def leaderboard_columns(score: Mapping[str, Any]) -> list[tuple[str, Any, str]]:
    """A leaderboard row's cells: the totals, the time, then each item (``A1``, ``P2``...,
    by group role and order, each with its group and description)."""
    cells: list[tuple[str, Any, str]] = [
        ("achievements", score.get("achievements"), "the achievement items added up"),
        ("penalized", score.get("penalized_behaviors"), "the penalized behaviors added up"),
        ("time (s)", score.get("execution_time"), "how long the benchmark executed"),
    ]
    counts: dict[str, int] = {}
    for item in score.get("items") or []:
        if not isinstance(item, Mapping):
            continue
        letter = _ROLE_LETTER[group_role(str(item.get("group", ""))).value]
        counts[letter] = counts.get(letter, 0) + 1
        what = f"{item.get('group')}: {item.get('desc')}"
        cells.append((f"{letter}{counts[letter]}", item.get("value"), what))
    return cells
