"""The 2015 benchmark state machines (seed 6.2 to 6.4): enums, message definitions, topics.

Segmentation specific to one benchmark lives in that benchmark's module; this module holds
only what all benchmarks and the audit share.
"""

from __future__ import annotations

import enum


class Machine(enum.Enum):
    """The three 2015 benchmark state machines (seed 6.2)."""

    BMBOX = "bmbox"
    REFBOX = "refbox"
    CLIENT = "client"


class BmBoxState(enum.IntEnum):
    """Seed Listing 6."""

    START = 0
    WAITING_CLIENT = 1
    READY = 2
    WAITING_MANUAL_OPERATION = 3
    COMPLETED_MANUAL_OPERATION = 4
    TRANSMITTING_GOAL = 5
    EXECUTING_GOAL = 6
    WAITING_RESULT = 7
    TRANSMITTING_SCORE = 8
    END = 9


class RefBoxState(enum.IntEnum):
    """Seed Listing 7."""

    START = 0
    WAITING_CLIENT = 1
    READY = 2
    EXECUTING_MANUAL_OPERATION = 3
    EXECUTING_GOAL = 4
    RECEIVED_SCORE = 5
    END = 6


class ClientState(enum.IntEnum):
    """Seed Listing 8."""

    START = 0
    CONNECTING = 1
    READY = 2
    WAITING_GOAL = 3
    EXECUTING_GOAL = 4
    COMPLETED_GOAL = 5
    END = 6


STATE_ENUMS: dict[Machine, type[enum.IntEnum]] = {
    Machine.BMBOX: BmBoxState,
    Machine.REFBOX: RefBoxState,
    Machine.CLIENT: ClientState,
}

# ROS message types as the 2015 system registered them, and their stored definitions.
MSG_TYPES: dict[Machine, str] = {
    Machine.BMBOX: "rockin_scoring/BmBoxState",
    Machine.REFBOX: "rockin_scoring/RefBoxState",
    Machine.CLIENT: "rockin_scoring/ClientState",
}


def _msgdef(enum_type: type[enum.IntEnum]) -> str:
    consts = "".join(f"uint8 {member.name} = {member.value}\n" for member in enum_type)
    return consts + "\nuint8 state\nstring payload\n"


MSG_DEFINITIONS: dict[Machine, str] = {m: _msgdef(e) for m, e in STATE_ENUMS.items()}

# Topic of each machine, relative to the benchmark namespace (``/fbm2h`` + ``/bmbox_state``).
# Section 7.x of the seed lists ``bbbox_state`` in the record lists; the 2015 node published
# ``bmbox_state``. Readers accept both.
STATE_TOPIC_SUFFIXES: dict[Machine, tuple[str, ...]] = {
    Machine.BMBOX: ("bmbox_state", "bbbox_state"),
    Machine.REFBOX: ("refbox_state",),
    Machine.CLIENT: ("client_state",),
}

# BmBox transitions the 2015 implementation allowed (issue 8 / seed Figure 6.2.1).
BMBOX_TRANSITIONS: dict[BmBoxState, frozenset[BmBoxState]] = {
    BmBoxState.START: frozenset({BmBoxState.WAITING_CLIENT, BmBoxState.END}),
    BmBoxState.WAITING_CLIENT: frozenset({BmBoxState.READY, BmBoxState.END}),
    BmBoxState.READY: frozenset(
        {
            BmBoxState.WAITING_MANUAL_OPERATION,
            BmBoxState.TRANSMITTING_GOAL,
            BmBoxState.TRANSMITTING_SCORE,
            BmBoxState.END,
        }
    ),
    BmBoxState.WAITING_MANUAL_OPERATION: frozenset(
        {BmBoxState.COMPLETED_MANUAL_OPERATION, BmBoxState.READY, BmBoxState.END}
    ),
    BmBoxState.COMPLETED_MANUAL_OPERATION: frozenset(
        {BmBoxState.TRANSMITTING_GOAL, BmBoxState.END}
    ),
    BmBoxState.TRANSMITTING_GOAL: frozenset({BmBoxState.EXECUTING_GOAL, BmBoxState.END}),
    BmBoxState.EXECUTING_GOAL: frozenset(
        {BmBoxState.WAITING_RESULT, BmBoxState.READY, BmBoxState.END}
    ),
    BmBoxState.WAITING_RESULT: frozenset({BmBoxState.READY, BmBoxState.END}),
    BmBoxState.TRANSMITTING_SCORE: frozenset({BmBoxState.END}),
    BmBoxState.END: frozenset(),
}


def state_name(machine: Machine, code: int) -> str:
    """The enum name of a state code, or ``UNKNOWN(<code>)``."""
    try:
        return STATE_ENUMS[machine](code).name
    except ValueError:
        return f"UNKNOWN({code})"


def state_topic(namespace: str, machine: Machine) -> str:
    """The canonical topic of a machine in a benchmark namespace, e.g. ``/fbm3w/bmbox_state``."""
    return f"/{namespace.strip('/')}/{STATE_TOPIC_SUFFIXES[machine][0]}"
