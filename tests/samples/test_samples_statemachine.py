"""State topics: 10 Hz heartbeats, transitions at their exact times, read back from a bag."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from rosbags.highlevel import AnyReader

from ertools.simulator.statemachine import Transition, machine_messages, publish_states
from ertools.simulator.writer import BagWriter
from ertools.states import BmBoxState, ClientState, Machine, RefBoxState

T0 = 1_448_013_600_000_000_000
S = 1_000_000_000

BM = [
    Transition(T0, Machine.BMBOX, BmBoxState.START),
    Transition(T0 + 1_234_567_891, Machine.BMBOX, BmBoxState.WAITING_CLIENT),
    Transition(T0 + 2 * S, Machine.BMBOX, BmBoxState.READY),  # on a heartbeat tick
    Transition(T0 + 3 * S + 1, Machine.BMBOX, BmBoxState.TRANSMITTING_GOAL, "line"),
    Transition(T0 + 4 * S + 50_000_000, Machine.BMBOX, BmBoxState.EXECUTING_GOAL, "line"),
    Transition(T0 + 5 * S + 7, Machine.BMBOX, BmBoxState.WAITING_RESULT),
    Transition(T0 + 6 * S + 3, Machine.BMBOX, BmBoxState.READY),
    Transition(T0 + 7 * S + 250_000_000, Machine.BMBOX, BmBoxState.TRANSMITTING_SCORE, "s: 1"),
    Transition(T0 + 8 * S + 10, Machine.BMBOX, BmBoxState.END),
]


def test_heartbeats_and_exact_transitions() -> None:
    m = machine_messages(Machine.BMBOX, BM)
    tr_times = [t.t_ns for t in BM]
    assert m.t_ns[m.is_transition].tolist() == tr_times
    beats = m.t_ns[~m.is_transition]
    # Heartbeats on the 100 ms grid from the first transition, never doubling a transition.
    assert np.all((beats - T0) % 100_000_000 == 0)
    assert np.all(np.diff(beats) >= 100_000_000)
    assert T0 + 2 * S not in beats.tolist()
    grid = np.arange(T0, BM[-1].t_ns + 1, 100_000_000)
    assert beats.tolist() == [t for t in grid.tolist() if t not in tr_times]
    # Stops at END: the last message is the END transition.
    assert m.t_ns[-1] == BM[-1].t_ns and m.state[-1] == BmBoxState.END
    # Every message carries the state in force at its time.
    for t, s, p in zip(m.t_ns.tolist(), m.state.tolist(), m.payload, strict=True):
        current = [x for x in BM if x.t_ns <= t][-1]
        assert (s, p) == (current.state, current.payload)
    assert len(m) == len(tr_times) + len(beats)


def test_end_ns_cuts_and_no_end_adds_one_heartbeat() -> None:
    trs = [Transition(T0, Machine.CLIENT, ClientState.START)]
    m = machine_messages(Machine.CLIENT, trs)
    assert m.t_ns.tolist() == [T0, T0 + 100_000_000]
    m = machine_messages(Machine.CLIENT, trs, end_ns=T0 + 350_000_000)
    assert m.t_ns.tolist() == [T0 + k * 100_000_000 for k in range(4)]


def test_invalid_bmbox_transition_is_refused_unless_asked() -> None:
    bad = [
        Transition(T0, Machine.BMBOX, BmBoxState.START),
        Transition(T0 + S, Machine.BMBOX, BmBoxState.EXECUTING_GOAL),
    ]
    with pytest.raises(ValueError, match="START -> EXECUTING_GOAL"):
        machine_messages(Machine.BMBOX, bad)
    assert len(machine_messages(Machine.BMBOX, bad, validate=False)) == 12
    with pytest.raises(ValueError, match="increasing"):
        machine_messages(Machine.BMBOX, [BM[1], BM[1]])


def test_published_state_topics_read_back(tmp_path: Path) -> None:
    trs = [
        *BM,
        Transition(T0 + 50_000_000, Machine.REFBOX, RefBoxState.START),
        Transition(T0 + 2_500_000_000, Machine.REFBOX, RefBoxState.READY),
        Transition(T0 + 8 * S + 500_000_000, Machine.REFBOX, RefBoxState.END),
        Transition(T0 + 70_000_000, Machine.CLIENT, ClientState.START),
        Transition(T0 + 1_900_000_000, Machine.CLIENT, ClientState.CONNECTING),
        Transition(T0 + 8 * S + 600_000_000, Machine.CLIENT, ClientState.END),
    ]
    path = tmp_path / "s.bag"
    with BagWriter(path) as bag:
        written = publish_states(bag, "/fbm3w/", trs)
    got: dict[str, list[tuple[int, int, str]]] = {}
    with AnyReader([path]) as reader:
        for conn, t, raw in reader.messages():
            msg = reader.deserialize(raw, conn.msgtype)
            got.setdefault(conn.topic, []).append((t, msg.state, msg.payload))
    assert set(got) == {"/fbm3w/bmbox_state", "/fbm3w/refbox_state", "/fbm3w/client_state"}
    for machine, topic in [
        (Machine.BMBOX, "/fbm3w/bmbox_state"),
        (Machine.REFBOX, "/fbm3w/refbox_state"),
        (Machine.CLIENT, "/fbm3w/client_state"),
    ]:
        m = written[machine]
        assert got[topic] == list(zip(m.t_ns.tolist(), m.state.tolist(), m.payload, strict=True))
    refbox_times = [t for t, _, _ in got["/fbm3w/refbox_state"]]
    # 8.45 s of 10 Hz plus the READY and END transitions off the grid.
    assert len(refbox_times) == 85 + 2
