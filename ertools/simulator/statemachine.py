"""The three 2015 benchmark state machines as they appeared in a bag (seed 6.2 to 6.4).

Scenarios describe a benchmark as a list of :class:`Transition` (time, machine, state,
payload); :func:`state_messages` turns it into what was recorded: each machine publishes its
current (state, payload) at 10 Hz (the 2015 nodes ran a ``rospy.Rate(10)`` publishing loop),
plus one message at the exact time of every transition. The heartbeat grid of a machine starts
at its first transition (``t0 + k * 100 ms``); a grid tick that coincides with a transition is
not doubled. A machine stops publishing after its ``END`` transition (or at ``end_ns``).

The scorers see the transition times exactly (the first message of each run of equal
(state, payload) is the transition), so answers can use the transition times directly.

Example::

    tr = [Transition(t0, Machine.BMBOX, BmBoxState.START),
          Transition(t0 + 1_000_000_000, Machine.BMBOX, BmBoxState.WAITING_CLIENT), ...]
    publish_states(bag, "fbm3w", tr)
"""

from __future__ import annotations

import itertools
from collections.abc import Iterable, Sequence

import numpy as np
import numpy.typing as npt

from ertools.arrays import I64
from ertools.frozen_dataclass import frozen_dataclass
from ertools.simulator.writer import BagWriter
from ertools.states import BMBOX_TRANSITIONS, STATE_ENUMS, BmBoxState, Machine, state_topic

HEARTBEAT_NS = 100_000_000  # 10 Hz


@frozen_dataclass
class Transition:
    """A machine enters ``state`` (an enum member or code) with ``payload`` at ``t_ns``."""

    t_ns: int
    machine: Machine
    state: int
    payload: str = ""


@frozen_dataclass(eq=False)
class StateMessages:
    """The messages one machine published: record times, state codes, payloads."""

    machine: Machine
    t_ns: I64
    state: npt.NDArray[np.uint8]
    payload: tuple[str, ...]
    is_transition: npt.NDArray[np.bool_]

    def __len__(self) -> int:
        return int(self.t_ns.shape[0])


def _check(machine: Machine, trs: Sequence[Transition], validate: bool) -> None:
    enum_type = STATE_ENUMS[machine]
    for a, b in itertools.pairwise(trs):
        if b.t_ns <= a.t_ns:
            raise ValueError(
                f"{machine.value}: transitions must be strictly increasing in time "
                f"({a.t_ns} then {b.t_ns})"
            )
    for tr in trs:
        enum_type(tr.state)  # raises ValueError on an unknown code
    if validate and machine is Machine.BMBOX:
        for a, b in itertools.pairwise(trs):
            if (
                a.state != b.state
                and BmBoxState(b.state) not in BMBOX_TRANSITIONS[BmBoxState(a.state)]
            ):
                raise ValueError(
                    f"bmbox: {BmBoxState(a.state).name} -> {BmBoxState(b.state).name} at "
                    f"{b.t_ns} is not a 2015 transition (pass validate=False to simulate it)"
                )


def machine_messages(
    machine: Machine,
    transitions: Sequence[Transition],
    *,
    end_ns: int | None = None,
    period_ns: int = HEARTBEAT_NS,
    validate: bool = True,
) -> StateMessages:
    """Heartbeats plus transition messages of one machine (see the module docstring)."""
    trs = sorted((t for t in transitions if t.machine is machine), key=lambda t: t.t_ns)
    _check(machine, trs, validate)
    if not trs:
        return StateMessages(
            machine, np.empty(0, np.int64), np.empty(0, np.uint8), (), np.empty(0, bool)
        )
    t_tr = np.array([t.t_ns for t in trs], dtype=np.int64)
    ends = [t.t_ns for t in trs if t.state == int(STATE_ENUMS[machine]["END"])]
    stop = min([*ends, *([end_ns] if end_ns is not None else [])], default=None)
    if stop is None:
        stop = int(t_tr[-1]) + period_ns  # one last heartbeat after the final transition
    ticks = np.arange(int(t_tr[0]), stop + 1, period_ns, dtype=np.int64)
    ticks = ticks[~np.isin(ticks, t_tr)]
    t_tr = t_tr[t_tr <= stop]
    times = np.concatenate([t_tr, ticks])
    is_tr = np.concatenate([np.ones(t_tr.size, bool), np.zeros(ticks.size, bool)])
    order = np.argsort(times, kind="stable")
    times = times[order]
    is_tr = is_tr[order]
    # The transition in force at each message time.
    which = np.searchsorted(t_tr, times, side="right") - 1
    states = np.array([trs[i].state for i in which], dtype=np.uint8)
    payloads = tuple(trs[i].payload for i in which)
    return StateMessages(machine, times, states, payloads, is_tr)


def state_messages(
    transitions: Iterable[Transition],
    *,
    end_ns: int | None = None,
    period_ns: int = HEARTBEAT_NS,
    validate: bool = True,
) -> dict[Machine, StateMessages]:
    """:func:`machine_messages` for every machine that has a transition."""
    trs = list(transitions)
    machines = [m for m in Machine if any(t.machine is m for t in trs)]
    return {
        m: machine_messages(m, trs, end_ns=end_ns, period_ns=period_ns, validate=validate)
        for m in machines
    }


def publish_states(
    bag: BagWriter,
    namespace: str,
    transitions: Iterable[Transition],
    *,
    end_ns: int | None = None,
    period_ns: int = HEARTBEAT_NS,
    validate: bool = True,
) -> dict[Machine, StateMessages]:
    """Write the state topics of ``namespace`` (``/<ns>/bmbox_state``...); returns the messages.

    Caller ids: ``/<ns>/bmbox``, ``/<ns>/refbox``, ``/<ns>/client``.
    """
    ns = namespace.strip("/")
    msgs = state_messages(transitions, end_ns=end_ns, period_ns=period_ns, validate=validate)
    for machine, m in msgs.items():
        if len(m) == 0:
            continue
        bag.write_state(
            machine,
            state_topic(ns, machine),
            m.t_ns,
            [int(s) for s in m.state],
            list(m.payload),
            callerid=f"/{ns}/{machine.value}",
        )
    return msgs
