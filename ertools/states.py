"""The 2015 benchmark state machines (seed 6.2 to 6.4): enums, message definitions, topics.

Segmentation specific to one benchmark lives in that benchmark's module; this module holds
only what all benchmarks and the audit share.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass


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


# --- RefBox END payloads ----------------------------------------------------------------------
#
# The 2015 BmBox (rockin_scoring/BmBox.py) reads one thing from the RefBox besides its state:
# the payload, compared as a whole string. ``Timeout()`` is ``payload == "reason: timeout"``,
# ``Running()`` is ``payload != "reason: stop"``, and its RefBox callback leaves
# WAITING_RESULT / EXECUTING_GOAL on END only with one of those two strings (any END payload
# ends a WAITING_MANUAL_OPERATION). The seed (6.2.3) documents the bare words ``timeout`` and
# ``halt``. The Python machines themselves never publish END (their 10 Hz loop stops at END),
# and a ``None`` payload goes out as "" (genpy fills unset strings). docs/fidelity.md lists
# the forms with their sources.


class EndReason(enum.Enum):
    """What a RefBox END payload means to the 2015 BmBox."""

    TIMEOUT = "timeout"  # Timeout() is true: the run's time counts, the run is over
    STOP = "stop"  # Running() is false: the benchmark is over
    UNKNOWN = "unknown"  # neither: the 2015 BmBox went on as if nothing was said


@dataclass(frozen=True)
class EndPayloadForm:
    """One RefBox END payload the 2015 code or the seed names, and where."""

    text: str
    reason: EndReason
    source: str


END_PAYLOAD_FORMS: tuple[EndPayloadForm, ...] = (
    EndPayloadForm(
        "reason: timeout",
        EndReason.TIMEOUT,
        "rockin_scoring/BmBox.py: _refbox_state_cb, WaitResult, Timeout() compare it exactly",
    ),
    EndPayloadForm(
        "reason: stop",
        EndReason.STOP,
        "rockin_scoring/BmBox.py: _refbox_state_cb, WaitResult, Running() compare it exactly",
    ),
    EndPayloadForm("timeout", EndReason.TIMEOUT, "seed 6.2.3: the RefBox's timeout payload"),
    EndPayloadForm("halt", EndReason.STOP, "seed 6.2.3: the RefBox's emergency-halt payload"),
)

_END_FORMS = {f.text: f for f in END_PAYLOAD_FORMS}


def end_reason(payload: str) -> EndReason:
    """The meaning of a RefBox END payload: a known form exactly, else ``UNKNOWN``.

    Exact, as the 2015 BmBox compared (``"Reason: Stop"`` or ``"reason: stop "`` meant
    nothing to it). An ``UNKNOWN`` payload is neither a timeout nor a stop: callers warn with
    :func:`unknown_end_warning` rather than guess from its words.
    """
    form = _END_FORMS.get(payload)
    return EndReason.UNKNOWN if form is None else form.reason


def known_end_payloads() -> str:
    """The known END payload forms, quoted, for messages."""
    return ", ".join(repr(f.text) for f in END_PAYLOAD_FORMS)


def unknown_end_warning(payload: str, where: str) -> str:
    """The one-line warning for a RefBox END payload that is no known form."""
    return (
        f"{where}: RefBox END with payload {payload!r}, which is none of the forms the 2015 "
        f"BmBox or the seed know ({known_end_payloads()}); read as the 2015 BmBox did: neither "
        "a timeout nor a stop (the BmBox states show what followed)"
    )
