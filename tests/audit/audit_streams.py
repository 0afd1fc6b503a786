"""Hand-built state streams: 10 Hz heartbeats from a schedule of (time, state, payload)."""

from __future__ import annotations

import numpy as np

from ertools.states import Machine
from ertools.streams import StateStream

T0_NS = 1_445_000_000_000_000_000  # an epoch time in October 2015
BEAT_NS = 100_000_000  # 10 Hz


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
