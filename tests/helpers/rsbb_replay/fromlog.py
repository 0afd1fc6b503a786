"""A :class:`~rsbb_replay.world.Timeline` from an RSBB run bag, read with ertools' readers only
(``read_messages``), the events derived here message by message (independently of
``ertools.rsbb.log``).

The script's moments come from the log (docs/rsbb.md, "Timing in the log"): ``execute()``
starts at the RefBox's EXECUTING_BENCHMARK; a manual operation returns at the RefBox's manual
READY; ``request_goal`` returns at the goal's EXECUTING_GOAL (or, timed out while the robot
prepared, at its READY); ``wait_goal_result`` at the goal's READY; the stop at the benchmark's
STOP or GLOBAL_TIMEOUT; the successful lookups at their broadcasts' stamps. The mocap links
hold every ``/tf`` transform but the script's own, each arriving at its record time.
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

import yaml

from ertools.io.messages import read_messages
from ertools.io.reader import topics
from tests.helpers.rsbb_replay.tf2 import Buffer, frame
from tests.helpers.rsbb_replay.world import TGoal, Timeline, TManual

REFBOX = "/rsbb/bmbox/refbox_state"
BMBOX = "/rsbb/bmbox/bmbox_state"
# RefBoxState / BmBoxState numbers (docs/rsbb.md)
EXECUTING_BENCHMARK, STOP, GLOBAL_TIMEOUT = 1, 3, 6
READY, TRANSMITTING_GOAL, EXECUTING_GOAL, EXECUTING_MANUAL_OPERATION = 7, 8, 9, 11
BM_TRANSMITTING_GOAL, BM_EXECUTING_GOAL = 5, 6

#: Frames the scripts broadcast (tf spelling).
SCRIPT_FRAMES = ("item", "robot", "person", "object")


def _refbox_rows(bag: Path) -> list[tuple[int, tuple[Any, ...]]]:
    rows = []
    for m in read_messages(bag, REFBOX):
        v = m.msg
        rows.append(
            (
                m.t_ns,
                (
                    int(v.benchmark_state),
                    int(v.goal_execution_state),
                    str(v.goal_execution_payload),
                    int(v.manual_operation_state),
                    str(v.manual_operation_payload),
                ),
            )
        )
    return rows


def timeline_from_bag(
    bag: str | Path, params: Any, files: dict[str, Any], team: str = "team"
) -> Timeline:
    """The timeline of a run bag; ``params`` and ``files`` as the script read them (configs),
    completed here with the draws the log shows (items, people, objects, targets)."""
    path = Path(bag)
    present = topics(path)
    rows = _refbox_rows(path)
    timeouts = [m.t_ns for m in read_messages(path, "/timeout")] if "/timeout" in present else []
    t_ready = next(t for t, r in rows if r[0] == EXECUTING_BENCHMARK)
    stop = next(
        ((t, r[0]) for t, r in rows if t >= t_ready and r[0] in (STOP, GLOBAL_TIMEOUT)), None
    )
    manual: list[TManual] = []
    goals: list[TGoal] = []
    requests: list[str] = []
    prev: tuple[Any, ...] | None = None
    pending_goal: list[Any] | None = None
    for t, r in rows:
        if t < t_ready or (stop is not None and t >= stop[0]):
            prev = r
            continue
        if prev is not None and r[3] != prev[3]:
            if r[3] == EXECUTING_MANUAL_OPERATION:
                requests.append(r[4])
            elif r[3] == READY and prev[3] == EXECUTING_MANUAL_OPERATION:
                manual.append(TManual(t, r[4], requests[-1]))
        if prev is not None and r[1] != prev[1]:
            if r[1] == TRANSMITTING_GOAL:
                pending_goal = [t, None]
            elif r[1] == EXECUTING_GOAL and pending_goal is not None:
                pending_goal[1] = t
            elif r[1] == READY and pending_goal is not None:
                timed_out = any(pending_goal[0] <= x <= t for x in timeouts) and r[2] == ""
                if timed_out:
                    goals.append(TGoal(pending_goal[1], t, "timeout"))
                else:
                    goals.append(TGoal(pending_goal[1], t, "result", r[2]))
                pending_goal = None
        prev = r
    if len(requests) > len(manual):
        manual.append(TManual(None, None, requests[-1]))
    if pending_goal is not None:
        goals.append(TGoal(pending_goal[1], None, "stopped"))

    tf = Buffer()
    lookups: dict[str, list[int]] = {}
    for m in read_messages(path, "/tf"):
        for tr in m.msg.transforms:
            child = frame(str(tr.child_frame_id))
            stamp = int(tr.header.stamp.sec) * 1_000_000_000 + int(tr.header.stamp.nanosec)
            if child in SCRIPT_FRAMES or child.startswith("result_"):
                lookups.setdefault(child, []).append(stamp)
                continue
            t3, q = tr.transform.translation, tr.transform.rotation
            value = (
                (float(t3.x), float(t3.y), float(t3.z)),
                (float(q.x), float(q.y), float(q.z), float(q.w)),
            )
            tf.add(str(tr.header.frame_id), child, stamp, m.t_ns, value)
    for stamps in lookups.values():
        stamps.sort()

    goal_payloads = [
        str(m.msg.payload)
        for m in read_messages(path, BMBOX)
        if int(m.msg.state) in (BM_TRANSMITTING_GOAL, BM_EXECUTING_GOAL) and str(m.msg.payload)
    ]
    distinct: list[str] = []
    for p in goal_payloads:
        if not distinct or distinct[-1] != p:
            distinct.append(p)
    out_files = dict(files)
    place = [r for r in requests if r.startswith("Place the positioner")]
    ids = [re.search(r"\(id: (\d+),", r) for r in place]
    out_files.setdefault("items_order", [int(m.group(1)) for m in ids if m is not None])
    marker = " should enter the target area"
    out_files.setdefault("people_order", [r.split(marker, 1)[0] for r in requests if marker in r])
    targets = [
        t for t in (yaml.safe_load(p) for p in distinct) if isinstance(t, list) and len(t) == 3
    ]
    out_files.setdefault("objects_order", [int(t[2]) for t in targets])
    out_files.setdefault("targets", [(float(t[0]), float(t[1])) for t in targets])
    return Timeline(
        t_ready_ns=t_ready,
        stop_ns=None if stop is None else stop[0],
        stop_kind="global_timeout" if stop is not None and stop[1] == GLOBAL_TIMEOUT else "stop",
        manual=manual,
        goals=goals,
        lookups=lookups,
        tf=tf,
        params=params,
        team=team,
        files=out_files,
    )
