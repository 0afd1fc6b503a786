"""The sample competition's schedule: who runs which benchmark when, and how well.

:data:`SCHEDULE` is the day (13 executions by five teams, 09:10 to 13:21 UTC, 2015-11-20); the
team knobs say how each team's runs differ (FBM2H: how far it stops from the waypoints and
where its marker set sits; FBM1H: how wrong its answers are; FBM3W: how far it strays from the
paths); :func:`simulate_slot` runs the benchmark's simulator for one slot. The ids of the slots
something goes wrong with are named here so that the writer and the tests agree.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from ertools.benchmarks.fbm1 import sample as fbm1
from ertools.benchmarks.fbm2h import sample as fbm2h
from ertools.benchmarks.fbm3w import sample as fbm3w
from ertools.simulator.answers import EPOCH_2015
from ertools.simulator.simulated import SimulatedRun

NS = 1_000_000_000


@dataclass(frozen=True)
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

# Team knobs. FBM2H: stop errors scale and marker mount (t, rpy of T_marker_robot).
FBM2H_TEAMS: dict[str, tuple[float, tuple[float, ...], tuple[float, ...]]] = {
    "homer": (0.6, (0.10, 0.03, -0.78), (0.0, 0.01, 0.45)),
    "socrob": (1.0, fbm2h.MARKER_TO_ROBOT_T, fbm2h.MARKER_TO_ROBOT_RPY),
    "skuba": (1.5, (-0.05, 0.0, -0.92), (0.015, 0.0, -1.2)),
}
# FBM1H: scale of the pose errors of runs 1-6 and the runs (1-based) answered with a wrong class.
FBM1H_TEAMS: dict[str, tuple[float, tuple[int, ...]]] = {
    "homer": (1.0, ()),
    "socrob": (1.8, (2, 3)),
    "skuba": (0.5, (1,)),
}
# FBM3W: path deviation amplitude scale per attempt.
FBM3W_TEAMS: dict[str, tuple[float, float]] = {"b-it-bots": (1.1, 1.3), "robotto": (1.7, 2.2)}


def _fbm1_errors(
    scale: float, wrong: tuple[int, ...]
) -> tuple[tuple[bool, bool, float, float, float], ...]:
    """The default answers with runs 1-6's pose errors scaled and some classes wrong (runs 7-9
    keep their seam and clip cases)."""
    out = []
    for k, (cls, inst, dx, dy, dth) in enumerate(fbm1.ANSWER_ERRORS):
        if k < 6:
            dx, dy, dth = dx * scale, dy * scale, dth * scale
        if k + 1 in wrong:
            cls = inst = False
        out.append((cls, inst, dx, dy, dth))
    return tuple(out)


def simulate_slot(slot: Slot, seed: int, items: list[dict[str, Any]]) -> SimulatedRun:
    """The execution of one schedule slot, by its benchmark's simulator and the team's knobs."""
    if slot.benchmark == "fbm1h":
        scale, wrong = FBM1H_TEAMS[slot.team]
        return fbm1.simulate(
            seed, start_ns=slot.start_ns, answer_errors=_fbm1_errors(scale, wrong), items=items
        )
    if slot.benchmark == "fbm2h":
        scale, t, rpy = FBM2H_TEAMS[slot.team]
        errors = tuple((dx * scale, dy * scale, dth * scale) for dx, dy, dth in fbm2h.STOP_ERRORS)
        return fbm2h.simulate(
            seed,
            start_ns=slot.start_ns,
            team=slot.team,
            stop_errors=errors,
            marker_to_robot_t=(t[0], t[1], t[2]),
            marker_to_robot_rpy=(rpy[0], rpy[1], rpy[2]),
            transform_stamp="2015-11-20_08:40:00",
        )
    scale = FBM3W_TEAMS[slot.team][slot.attempt - 1]
    return fbm3w.simulate(
        seed, start_ns=slot.start_ns, amplitude=tuple(a * scale for a in fbm3w.AMPLITUDE)
    )
