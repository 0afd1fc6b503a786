"""A run's zone as the RefBox showed it on ``/core/to_gui``: when the benchmark was executing,
how it ended, and the referee's items.

A non-scripted (task) benchmark has no BmBox and no RefBox state topic: its run bag holds the
RefBox's GUI messages (10 Hz), whose zone for the run carries the state text, the stop button
(``stop_enabled``: true exactly while the benchmark executes, ``core_zone_exec.h`` at 2bb8a41,
``ExecutingBenchmark::fill``) and the items' current values. The executing time is the time the
stop button was enabled, summed over the run's executions (the referee may start it again
after a stop: the RefBox resumes its timer); the moments are the messages', to 0.1 s.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np

from ertools.arrays import I64
from ertools.benchmarks.referee.items import Item
from ertools.errors import TopicError
from ertools.frozen_dataclass import frozen_dataclass
from ertools.io.messages import read_messages
from ertools.io.reader import topics
from ertools.rsbb_states import CORE_TO_GUI_TOPIC, STATE_PERIOD_NS

PathsLike = str | Path | Sequence[str | Path]


@frozen_dataclass(eq=False)
class ZoneSeries:
    """The run's zone in each ``/core/to_gui`` message that shows it.

    Attributes:
        t_ns: (N,) record times.
        executing: (N,) the stop button was enabled (the benchmark executing).
        states: the state texts' first lines (``Benchmark completed by the robot``...).
        items: the items at the last message.
        team, run: the zone's team and run (the last message's).
    """

    t_ns: I64
    executing: np.ndarray
    states: tuple[str, ...]
    items: tuple[Item, ...]
    team: str = ""
    run: int = 0

    def spans(self) -> list[tuple[int, int]]:
        """The executing spans: from the first executing message to the first that is not
        (the log's last message when it never stops)."""
        ex = np.asarray(self.executing, dtype=bool)
        if not ex.any():
            return []
        edges = np.diff(np.concatenate([[False], ex, [False]]).astype(np.int8))
        starts = np.flatnonzero(edges == 1)
        stops = np.flatnonzero(edges == -1)
        n = len(self.t_ns)
        return [
            (int(self.t_ns[a]), int(self.t_ns[b if b < n else n - 1]))
            for a, b in zip(starts, stops, strict=True)
        ]

    def executing_ns(self) -> int:
        """The time the benchmark executed (the spans added up)."""
        return sum(b - a for a, b in self.spans())

    def end_state(self) -> str:
        """The state text after the last executing span ("" when it never stopped)."""
        ex = np.asarray(self.executing, dtype=bool)
        after = np.flatnonzero(~ex)
        running = np.flatnonzero(ex)
        if running.size == 0:
            return ""
        later = after[after > running[-1]]
        return self.states[int(later[0])] if later.size else ""


def read_zone(
    paths: PathsLike, code: str, team: str | None = None, run: int | None = None
) -> ZoneSeries:
    """The zone of ``code`` run by ``team`` (run ``run``; None: any) in every ``/core/to_gui``
    message.

    Raises:
        TopicError: no ``/core/to_gui`` in the bag, or no message shows that zone.
    """
    plist = [Path(paths)] if isinstance(paths, str | Path) else [Path(p) for p in paths]
    if CORE_TO_GUI_TOPIC not in topics(plist):
        raise TopicError(
            f"no {CORE_TO_GUI_TOPIC} in {plist[0]}: the RefBox's referee items are not logged"
        )
    times: list[int] = []
    executing: list[bool] = []
    states: list[str] = []
    last = None
    for m in read_messages(plist, CORE_TO_GUI_TOPIC):
        # One message a tenth of a second, a few zones each: the zone is picked by its fields.
        for zone in m.msg.zones:
            if zone.code != code or (team is not None and zone.team != team):
                continue
            if run is not None and zone.run != run:
                continue
            times.append(m.t_ns)
            executing.append(bool(zone.stop_enabled))
            states.append(str(zone.state).split("\n", 1)[0])
            last = zone
            break
    if last is None:
        raise TopicError(
            f"{plist[0]}: no {CORE_TO_GUI_TOPIC} message shows {code}"
            + (f" of team {team}" if team is not None else "")
            + (f" run {run}" if run is not None else "")
        )
    items = tuple(
        Item(str(group.group_name), "bool" if int(kind) == 0 else "uint", str(desc), int(value))
        for group in last.scoring
        for kind, desc, value in zip(
            group.types, group.descriptions, group.current_values, strict=False
        )
    )
    return ZoneSeries(
        np.asarray(times, dtype=np.int64),
        np.asarray(executing),
        tuple(states),
        items,
        str(last.team),
        int(last.run),
    )


#: The resolution of a zone's moments (the GUI messages' period).
ZONE_RESOLUTION_NS = STATE_PERIOD_NS
