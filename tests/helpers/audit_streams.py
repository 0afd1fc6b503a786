"""Hand-built state streams: 10 Hz heartbeats from a schedule of (time, state, payload), the
schedules of an FBM2-like benchmark, and a bag written from them."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ertools.simulator.writer import BagWriter
from ertools.states import BmBoxState as B
from ertools.states import ClientState as C
from ertools.states import Machine
from ertools.states import RefBoxState as R
from ertools.streams import StateStream

T0_NS = 1_445_000_000_000_000_000  # an epoch time in October 2015
BEAT_NS = 100_000_000  # 10 Hz

GOAL = "goal:\n  waypoints:\n  - [1.0, 2.0, 0.5]\n"

# An FBM2-like benchmark of two segments. Segment 1 contains an illegal transition
# (EXECUTING_GOAL -> TRANSMITTING_GOAL at 12.0 s) and is ended by a RefBox timeout at 19.9 s;
# the BmBox heartbeat is lost between 5.0 s and 7.0 s.
BMBOX = [
    (0.0, B.START, ""),
    (1.0, B.WAITING_CLIENT, ""),
    (2.0, B.READY, ""),
    (3.0, B.TRANSMITTING_GOAL, GOAL),
    (3.5, B.EXECUTING_GOAL, ""),
    (4.0, B.WAITING_RESULT, ""),
    (10.0, B.READY, ""),
    (11.0, B.TRANSMITTING_GOAL, ""),
    (11.5, B.EXECUTING_GOAL, ""),
    (12.0, B.TRANSMITTING_GOAL, ""),
    (12.5, B.EXECUTING_GOAL, ""),
    (13.0, B.WAITING_RESULT, ""),
    (20.0, B.END, ""),
]
REFBOX = [
    (0.0, R.START, ""),
    (0.5, R.WAITING_CLIENT, ""),
    (1.5, R.READY, ""),
    (3.0, R.EXECUTING_GOAL, ""),
    (19.9, R.END, "timeout"),
]
CLIENT = [
    (0.0, C.START, ""),
    (0.5, C.CONNECTING, ""),
    (1.5, C.READY, ""),
    (2.5, C.WAITING_GOAL, ""),
    (3.5, C.EXECUTING_GOAL, ""),
    (9.8, C.COMPLETED_GOAL, "{int: 1}"),
    (10.2, C.WAITING_GOAL, ""),
    (11.5, C.EXECUTING_GOAL, ""),
    (20.0, C.END, ""),
]


def heartbeat(
    machine: Machine,
    schedule: list[tuple[float, int, str]],
    end_s: float,
    *,
    drop: tuple[float, float] | None = None,
    topic: str = "",
) -> StateStream:
    """One message every 0.1 s from 0 to end_s, carrying the state in force at that time.

    ``drop=(a, b)`` removes the messages with a < t < b (a silence from a to b).
    """
    k = np.arange(round(end_s * 10) + 1, dtype=np.int64)
    t_rel = k * BEAT_NS
    starts = np.array([round(s * 1e9) for s, _, _ in schedule], dtype=np.int64)
    idx = np.searchsorted(starts, t_rel, side="right") - 1
    keep = idx >= 0
    if drop is not None:
        keep &= ~((t_rel > round(drop[0] * 1e9)) & (t_rel < round(drop[1] * 1e9)))
    t_rel, idx = t_rel[keep], idx[keep]
    return StateStream(
        machine,
        T0_NS + t_rel,
        np.array([schedule[i][1] for i in idx], dtype=np.uint8),
        tuple(schedule[i][2] for i in idx),
        topic,
        "hand-built",
    )


def write_bag(path: Path, streams: list[StateStream]) -> Path:
    """A ROS1 bag of the streams' state messages, on their topics."""
    with BagWriter(path, "ros1") as bag:
        for s in streams:
            bag.write_state(s.machine, s.topic, s.t_ns, [int(x) for x in s.state], list(s.payload))
    return path
