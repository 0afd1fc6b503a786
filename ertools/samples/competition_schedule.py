"""The sample competition's schedule: who runs which benchmark when, and how well.

:data:`SCHEDULE` is the day (13 executions by five teams, 09:10 to 13:21 UTC, 2015-11-20); the
team knobs say how each team's runs differ (FBM2H: how far it stops from the waypoints and
where its marker set sits; FBM1H: how wrong its answers are; FBM3W: how far it strays from the
paths); :func:`simulate_slot` runs the benchmark's simulator for one slot. The ids of the slots
something goes wrong with are named here so that the writer and the tests agree. Each
benchmark's part (its teams' knobs, how a slot is simulated) is its package's ``sample``
module's (``COMPETITION_TEAMS``, ``competition_run``), reached through the registry.
"""

from __future__ import annotations

from typing import Any

from ertools.benchmarks import registry
from ertools.errors import UsageError
from ertools.frozen_dataclass import frozen_dataclass
from ertools.simulator.answers import EPOCH_2015
from ertools.simulator.simulated import SimulatedRun

NS = 1_000_000_000


@frozen_dataclass
class Slot:
    """One execution of the day's schedule."""

    at: str  # HH:MM:SS UTC: the benchmark recorder's start
    benchmark: str
    team: str
    attempt: int = 1

    @property
    def start_ns(self) -> int:
        hh, mm, ss = (int(v) for v in self.at.split(":"))
        return EPOCH_2015 + ((hh - 10) * 3600 + mm * 60 + ss) * NS

    @property
    def id(self) -> str:
        """``<benchmark>-<team>-<start, UTC, %Y%m%dT%H%M%S>``, as ``ertools rescore`` names it."""
        return f"{self.benchmark}-{self.team}-20151120T{self.at.replace(':', '')}"


SCHEDULE: tuple[Slot, ...] = (
    Slot("09:10:05", "fbm1h", "socrob"),
    Slot("09:24:30", "fbm3w", "b-it-bots"),
    Slot("09:41:12", "fbm2h", "homer"),
    Slot("09:59:31", "fbm2h", "socrob"),  # straddles the 09:59:58 split of the GT logger
    Slot("10:18:44", "fbm3w", "robotto"),
    Slot("10:36:02", "fbm1h", "homer"),
    Slot("10:52:27", "fbm1h", "skuba"),
    Slot("11:14:50", "fbm2h", "skuba"),  # no transform-skuba.yaml
    Slot("11:37:15", "fbm3w", "b-it-bots", 2),  # benchmark log truncated
    Slot("12:06:40", "fbm2h", "homer", 2),  # robot PC clock 4 s ahead
    Slot("12:31:05", "fbm3w", "robotto", 2),  # no robot log (USB key lost)
    Slot("12:58:50", "fbm1h", "socrob", 2),
    Slot("13:21:33", "fbm2h", "socrob", 2),  # in the GT logger's .bag.active file
)
MISSING_TRANSFORM = "skuba"
TRUNCATED = "fbm3w-b-it-bots-20151120T113715"
CLOCK_OFF = "fbm2h-homer-20151120T120640"
NO_ROBOT_LOG = "fbm3w-robotto-20151120T123105"
COPIED = "fbm2h-homer-20151120T094112"


def simulate_slot(slot: Slot, seed: int, items: list[dict[str, Any]]) -> SimulatedRun:
    """The execution of one schedule slot: its benchmark's sample module's
    ``competition_run`` (the team's knobs are that module's ``COMPETITION_TEAMS``)."""
    sample = registry.package_module(slot.benchmark, "sample")
    if sample is None:
        raise UsageError(f"the sample competition: {slot.benchmark} has no sample module")
    run: SimulatedRun = sample.competition_run(slot.team, slot.attempt, seed, slot.start_ns, items)
    return run
