"""A referee-scored run's result: its items, their tally and the time it executed."""

from __future__ import annotations

from dataclasses import field
from typing import Any

from ertools.benchmarks.base import Rows
from ertools.benchmarks.referee.config import PENALTY_SCALE, TIME_SCALE
from ertools.benchmarks.referee.formula import erl_rank
from ertools.benchmarks.referee.items import Item, Tally
from ertools.benchmarks.results import ResultBase
from ertools.fidelity import Deviation
from ertools.frozen_dataclass import frozen_dataclass
from ertools.streams import Provenance

#: A run whose executing time is not in its log ranks as if it had taken this long.
UNKNOWN_TIME_S = TIME_SCALE / PENALTY_SCALE - 1.0


@frozen_dataclass
class RefereeResult(ResultBase):
    """One referee-scored run (implements ``BenchmarkResult``).

    Attributes:
        name: the registry name (``hwv``).
        code: the RSBB code (``HWV``).
        team, run: the run's team and number, when known.
        items: the referee's items with their values (the description's order when given).
        items_source: where the values were read (``/core/to_gui`` or the result file).
        tally: the items added up.
        executing_ns: how long the benchmark executed; None when the log does not say.
        end: how it ended, as the RefBox said (``Benchmark completed by the robot``...).
    """

    name: str
    code: str
    team: str | None
    run: int | None
    items: tuple[Item, ...]
    items_source: str
    tally: Tally
    executing_ns: int | None
    end: str
    warnings: tuple[str, ...] = ()
    failures: tuple[str, ...] = ()
    provenance: Provenance = field(default_factory=Provenance)
    deviations: tuple[Deviation, ...] = ()

    @property
    def seconds(self) -> float | None:
        return None if self.executing_ns is None else self.executing_ns / 1e9

    @property
    def disqualified(self) -> bool:
        return bool(self.tally.disqualified)

    @property
    def rank_value(self) -> float:
        """:func:`~ertools.benchmarks.referee.formula.erl_rank` (an unknown time as
        :data:`UNKNOWN_TIME_S`)."""
        seconds = self.seconds
        return erl_rank(self.tally, UNKNOWN_TIME_S if seconds is None else seconds)

    def listing(self) -> dict[Any, Any]:
        """The run's score: its tally, time, ERL rank and items."""
        out: dict[str, Any] = {
            "benchmark_code": self.code,
            "team": self.provenance.team or self.team,
            "run": self.run,
            "status": "disqualified" if self.disqualified else "scored",
            "achievements": self.tally.achievements,
            "penalized_behaviors": self.tally.penalties,
            "disqualifying_behaviors": list(self.tally.disqualified),
            "execution_time": self.seconds,
            "end": self.end,
            "erl_rank": self.rank_value,
            "items": [
                {"group": i.group, "type": i.kind, "desc": i.desc, "value": i.value}
                for i in self.items
            ],
            "items_source": self.items_source,
        }
        return out

    def tables(self) -> dict[str, Rows]:
        return {
            "items": [
                {"group": i.group, "type": i.kind, "desc": i.desc, "value": i.value}
                for i in self.items
            ],
            "run": [
                {
                    "benchmark_code": self.code,
                    "team": self.team,
                    "run": self.run,
                    "achievements": self.tally.achievements,
                    "penalized_behaviors": self.tally.penalties,
                    "disqualified": self.disqualified,
                    "execution_time": self.seconds,
                    "end": self.end,
                }
            ],
        }
