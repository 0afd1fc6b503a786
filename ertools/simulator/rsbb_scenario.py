"""The timed scenario of a simulated RSBB run and the texts the BmBox wrote for it.

:mod:`ertools.simulator.rsbb` writes a scenario's bag and result file; this module holds what a
scenario is (manual operations, goals, the script's broadcasts and saves, the mocap bodies)
and the result mapping and live-score texts made from a save (docs/rsbb.md, "Saving and the
live score").
"""

from __future__ import annotations

import copy
from collections.abc import Sequence
from dataclasses import field
from datetime import datetime, timedelta, timezone
from typing import Any

import numpy as np
import yaml

from ertools.arrays import F64
from ertools.frozen_dataclass import frozen_dataclass
from ertools.rsbb_states import (
    END_DESCRIPTION_OTHER,
    END_DESCRIPTIONS,
    RESULT_TIME_FORMAT,
    RefBoxState,
)
from ertools.simulator.mocap import MocapPublished

MS = 1_000_000


@frozen_dataclass
class ManualOperation:
    """The referee asked ``request`` at ``t_request_ns`` and answered ``answer`` at
    ``t_done_ns`` (None: not completed, the benchmark stopped first)."""

    t_request_ns: int
    t_done_ns: int | None
    request: str
    answer: str = ""


@frozen_dataclass
class Goal:
    """One goal: requested, started by the robot (None: never), ended (None: the benchmark
    stopped first) with ``outcome`` ``result`` (``result`` the robot's string) or ``timeout``.

    ``request`` is the BmBox's payload text (the script's ``yaml.dump`` of its request)."""

    t_request_ns: int
    t_start_ns: int | None
    t_end_ns: int | None
    request: str
    outcome: str = "result"
    result: str = ""


@frozen_dataclass
class Broadcast:
    """One tf broadcast by the script: ``child`` under ``parent`` stamped ``t_ns`` (its
    lookup's ``now``), recorded 1 ms later. Frames are spelt as the script spells them."""

    t_ns: int
    child: str
    parent: str
    xyz: tuple[float, float, float]
    quat_xyzw: tuple[float, float, float, float]


@frozen_dataclass
class Save:
    """A ``save_and_publish_score()`` at ``t_ns`` with the score then."""

    t_ns: int
    score: dict[str, Any]


@frozen_dataclass
class Body:
    """A mocap body as the mocap node published it; ``record_topics``: its pose topics are in
    the bag (the benchmark's ``record_topics``), else only /tf."""

    name: str
    published: MocapPublished
    record_topics: bool = True


@frozen_dataclass
class RsbbScenario:
    """One run, timed (int64 ns since the epoch).

    Attributes:
        code, team, run: the RefBox event.
        season: ``"2017"`` or ``"2019"``: the live score's text form.
        t_connect_ns: the referee's connect (recording starts ~0.3 s later).
        t_start_ns: the referee's start (None: never started).
        t_end_ns, end: the benchmark's end (``end``: ``"end"``, ``"stop"``,
            ``"global_timeout"``); None: still running when disconnected.
        t_disconnect_ns: the referee's disconnect: the bag ends 50 ms later.
        manual_operations, goals, broadcasts, saves: in time order.
        params: the benchmark config (``benchmark_info.params``; None writes ``None``).
        referee_score: the referee items as the RefBox sends them (group_name, desc,
            current_value, type), or None.
        bodies: the mocap bodies.
        utc_offset_s, tz_name: the RSBB machine's time zone (file names, result dates).
    """

    code: str
    team: str
    run: int
    season: str
    t_connect_ns: int
    t_start_ns: int | None
    t_end_ns: int | None
    end: str | None
    t_disconnect_ns: int
    manual_operations: tuple[ManualOperation, ...] = ()
    goals: tuple[Goal, ...] = ()
    broadcasts: tuple[Broadcast, ...] = ()
    saves: tuple[Save, ...] = ()
    params: Any = None
    referee_score: tuple[dict[str, Any], ...] | None = None
    bodies: tuple[Body, ...] = field(default=())
    utc_offset_s: int = 0
    tz_name: str = "WET"

    @property
    def t_record_ns(self) -> int:
        """When the recorder started."""
        return self.t_connect_ns + 300 * MS

    @property
    def t_setup_ns(self) -> int:
        """When the BmBox ran ``setup()`` (the result file's name and start time)."""
        return self.t_connect_ns + 200 * MS


def stopped_run(
    code: str,
    team: str,
    times_ns: tuple[int, int, int],
    *,
    manual_operations: Sequence[ManualOperation],
    goals: Sequence[Goal],
    broadcasts: Sequence[Broadcast],
    saves: Sequence[Save],
    params: Any,
    bodies: Sequence[Body],
) -> RsbbScenario:
    """Run 1 of ``team`` in the 2019 season (a sample run), connected, started and stopped
    by the referee at ``times_ns``, who left a second after the stop."""
    t_connect_ns, t_start_ns, t_stop_ns = times_ns
    return RsbbScenario(
        code=code,
        team=team,
        run=1,
        season="2019",
        t_connect_ns=t_connect_ns,
        t_start_ns=t_start_ns,
        t_end_ns=t_stop_ns,
        end="stop",
        t_disconnect_ns=t_stop_ns + 1_000 * MS,
        manual_operations=tuple(manual_operations),
        goals=tuple(goals),
        broadcasts=tuple(broadcasts),
        saves=tuple(saves),
        params=params,
        bodies=tuple(bodies),
    )


def local_time(sc: RsbbScenario, t_ns: int) -> datetime:
    """``t_ns`` in the RSBB machine's time zone."""
    zone = timezone(timedelta(seconds=sc.utc_offset_s), sc.tz_name)
    return datetime.fromtimestamp(t_ns // 1_000_000_000, tz=zone)


def result_time_text(sc: RsbbScenario, t_ns: int) -> str:
    """A result-file date (``2017-12-14_20:37:46_WET(+0000)``) of ``t_ns`` in the run's zone."""
    return local_time(sc, t_ns).strftime(RESULT_TIME_FORMAT)


def _end_description(sc: RsbbScenario, t_ns: int) -> str:
    if sc.t_end_ns is None or sc.end is None or t_ns < sc.t_end_ns:
        return END_DESCRIPTION_OTHER
    kind = {
        "end": RefBoxState.END,
        "stop": RefBoxState.STOP,
        "global_timeout": RefBoxState.GLOBAL_TIMEOUT,
    }[sc.end]
    return END_DESCRIPTIONS[kind]


def result_object(sc: RsbbScenario, score: dict[str, Any], t_save_ns: int) -> dict[str, Any]:
    """The BmBox's result mapping at a save (``benchmark_info``, ``score``, ``referee_score``)."""
    return {
        "benchmark_info": {
            "benchmark_code": sc.code,
            "team": sc.team,
            "run": sc.run,
            "end_description": _end_description(sc, t_save_ns),
            "params": "None" if sc.params is None else copy.deepcopy(sc.params),
            "start_time": result_time_text(sc, sc.t_setup_ns),
            "end_time": result_time_text(sc, t_save_ns),
        },
        "score": copy.deepcopy(score),
        "referee_score": None if sc.referee_score is None else [dict(i) for i in sc.referee_score],
    }


def live_score_text(result: dict[str, Any], season: str) -> str:
    """The live topic's text: 2017 the whole result dumped, 2019 the totals apart."""
    if season == "2017":
        return str(yaml.safe_dump(result, default_flow_style=False))
    copied = copy.deepcopy(result)
    score = copied["score"]
    totals = {k: v for k, v in score.items() if not isinstance(v, dict)}
    for key in totals:
        del score[key]
    return (
        yaml.safe_dump(copied, default_flow_style=False)
        + "\n\nSCORE SUMMARY:\n"
        + yaml.safe_dump(totals, default_flow_style=False)
    )


def still_pose(
    t_ns: np.ndarray, xyz: Sequence[float], quat_xyzw: Sequence[float]
) -> tuple[F64, F64]:
    """Truth arrays of a body standing still at one pose (for :func:`simulate_mocap`)."""
    n = int(np.asarray(t_ns).shape[0])
    return (
        np.tile(np.asarray(xyz, dtype=np.float64), (n, 1)),
        np.tile(np.asarray(quat_xyzw, dtype=np.float64), (n, 1)),
    )
