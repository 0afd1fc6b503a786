"""The ERL rule as one number, so that a leaderboard orders the runs by it: most achievements,
then fewest penalised behaviours, then least time (ertools' reading, docs/rsbb.md)."""

from __future__ import annotations

from ertools.benchmarks.referee.config import PENALTY_SCALE, TIME_SCALE
from ertools.rsbb.referee import Tally


def erl_rank(t: Tally, seconds: float) -> float:
    """``achievements - penalties / 1e3 - seconds / 1e7``: higher is better, in the ERL order
    while penalties < 1000 and seconds < 10,000."""
    return float(t.achievements) - t.penalties / PENALTY_SCALE - seconds / TIME_SCALE


def exact_order(t: Tally, seconds: float) -> bool:
    """Whether :func:`erl_rank` keeps the ERL order for this run (else a warning says so)."""
    return t.penalties < PENALTY_SCALE and 0.0 <= seconds < TIME_SCALE / PENALTY_SCALE
