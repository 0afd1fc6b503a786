"""Simulated runs of the RSBB's non-scripted (task) benchmarks: the bag a run left.

A task benchmark (HGTKMH, HWV, HCFGAC) has no BmBox script: the RefBox runs it alone
(``ExecutingSimpleBenchmark``, ``core_zone_exec.h`` at 2bb8a41), so its bag holds no BmBox or
RefBox state topic and no result file is written. What the run leaves is the RefBox's GUI
messages (``/core/to_gui``, 10 Hz) with the run's zone: its state text, its stop button
(enabled while the benchmark executes), its timer (the time left before the timeout while
executing) and the referee's items, entered after the run; ``/timeout`` when the timer ran
out; the map. :func:`write_task_run` writes it at
``rsbb_logs/<CODE>/<team>/run_<n>_<date>.bag``. Computes no score.
"""

from __future__ import annotations

from datetime import datetime, timedelta, timezone
from pathlib import Path
from typing import Any

import numpy as np

from ertools.errors import UsageError
from ertools.frozen_dataclass import frozen_dataclass
from ertools.rsbb_states import BAG_TIME_FORMAT, LOGS_DIR, STATE_PERIOD_NS, TIMEOUT_TOPIC
from ertools.simulator.mocap import simple_map
from ertools.simulator.rsbb import CORE_CALLER, ZoneView, register_types, write_gui
from ertools.simulator.writer import BagWriter

MS = 1_000_000
#: The state texts of ``ExecutingSimpleBenchmark`` (core_zone_exec.h at 2bb8a41).
EXECUTING = "Robot finished preparation, executing (no explicit goal)"
COMPLETED = "Benchmark completed by the robot"
STOPPED = "Benchmark Stopped by referee"
TIMED_OUT = "Stopped due to timeout!"
WAITING = "Waiting for the referee's start"


@frozen_dataclass
class TaskScenario:
    """One task-benchmark run, timed (int64 ns since the epoch).

    Attributes:
        code, team, run: the RefBox event.
        t_connect_ns: the referee's connect (recording starts 0.3 s later).
        spans: the executing spans (start, stop), the referee's start to the robot's end, a
            referee stop or the timeout; a later span is the referee starting it again.
        end_state: the state text after the last span (:data:`COMPLETED`, :data:`STOPPED`,
            :data:`TIMED_OUT`).
        t_scored_ns: when the referee entered the items (their values 0 before).
        t_disconnect_ns: the referee's disconnect (the bag ends 50 ms later).
        items: the referee items (``group_name``, ``desc``, ``type``, ``current_value``).
        timeout_s: the benchmark's timeout (``benchmarks_description.yaml``).
        utc_offset_s, tz_name: the RSBB machine's time zone (the bag's name).
    """

    code: str
    team: str
    run: int
    t_connect_ns: int
    spans: tuple[tuple[int, int], ...]
    end_state: str
    t_scored_ns: int
    t_disconnect_ns: int
    items: tuple[dict[str, Any], ...]
    timeout_s: float = 600.0
    utc_offset_s: int = 0
    tz_name: str = "WET"

    @property
    def t_record_ns(self) -> int:
        return self.t_connect_ns + 300 * MS


def _views(sc: TaskScenario, ticks: np.ndarray) -> list[ZoneView]:
    """The zone at each tick: waiting, executing (timer counting down), or stopped."""
    zeros = tuple(0 for _ in sc.items)
    timeout_ns = round(sc.timeout_s * 1e9)
    views = []
    for t in ticks.tolist():  # 10 Hz over a run of minutes: a few thousand ticks
        values = None if t >= sc.t_scored_ns else zeros
        done = [(a, b) for a, b in sc.spans if b <= t]
        used = sum(b - a for a, b in done)
        current = next(((a, b) for a, b in sc.spans if a <= t < b), None)
        if current is not None:
            left = timeout_ns - used - (t - current[0])
            views.append(ZoneView(EXECUTING, True, False, left, values))
        elif done:
            last = done[-1][1]
            views.append(ZoneView(sc.end_state, False, True, last + 120 * 10**9 - t, values))
        else:
            views.append(ZoneView(WAITING, False, False, timeout_ns, values))
    return views


def write_task_run(root: str | Path, sc: TaskScenario, *, compression: str | None = None) -> Path:
    """Write the run's bag under ``root`` in the RSBB's layout; returns its path.

    Raises:
        UsageError: spans out of order, or a bag that exists already.
    """
    ends = [t for span in sc.spans for t in span]
    if ends != sorted(ends) or any(a >= b for a, b in sc.spans):
        raise UsageError("the executing spans must be in order and not empty")
    zone = timezone(timedelta(seconds=sc.utc_offset_s), sc.tz_name)
    stamp = datetime.fromtimestamp(sc.t_record_ns // 10**9, tz=zone).strftime(BAG_TIME_FORMAT)
    path = Path(root) / LOGS_DIR / sc.code / sc.team / f"run_{sc.run}_{stamp}.bag"
    if path.exists():
        raise UsageError(f"{path} exists already; the simulator never overwrites")
    ticks = np.arange(sc.t_record_ns + 60 * MS, sc.t_disconnect_ns, STATE_PERIOD_NS, dtype=np.int64)
    with BagWriter(path, "ros1", compression=compression) as bag:
        register_types(bag)
        write_gui(bag, ticks, sc.code, sc.team, sc.run, list(sc.items), _views(sc, ticks))
        if sc.end_state == TIMED_OUT and sc.spans:
            conn = bag.connection(TIMEOUT_TOPIC, "std_msgs/Empty", callerid=CORE_CALLER)
            bag.write(conn, sc.spans[-1][1] + 1 * MS, bag.msgclass("std_msgs/Empty")())
        bag.write_map(
            "rsbb", sc.t_record_ns + 200 * MS, sc.t_connect_ns - 60_000 * MS, simple_map()
        )
    return path
