"""The 2015 benchmark state machines (seed 6.2 to 6.4): enums, message definitions, topics.

Segmentation specific to one benchmark lives in that benchmark's module; this module holds
only what all benchmarks and the audit share.
"""

from __future__ import annotations

import enum

from ertools.frozen_dataclass import frozen_dataclass


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
# The 2015 BmBox (src/rockin_scoring/BmBox.py of rockin-robot-challenge/benchmark_and_scoring_fbm
# at 7628309, unchanged through 89dfa75) reads one thing from the RefBox besides its state:
# the payload, compared as a whole string.
# ``Timeout()`` is ``payload == "reason: timeout"`` (l. 117), ``Running()`` is
# ``payload != "reason: stop"`` (l. 126), and its RefBox callback leaves WAITING_RESULT /
# EXECUTING_GOAL on END only with one of those two strings (l. 49, 53; any END payload ends a
# WAITING_MANUAL_OPERATION, l. 43). The 2015 @Home RefBox (rockin-robot-challenge/at_home_rsbb,
# src/core_zone_exec.h, ``phase_post_2``) sent exactly those two strings. The seed (6.2.3)
# documents the bare words ``timeout`` and ``halt`` instead: they meant nothing to the 2015
# BmBox, so they are read only by ertools' default (a documented reading of the manual, said in
# the output), never under ``--2015``. An empty payload is no reason: the RefBox ended the
# benchmark itself (seed 6.2.3: a payload only when the referee box issued the END). The Python
# machines never publish END at all (their 10 Hz loop stops there). docs/fidelity.md lists the
# forms with their sources.


class EndReason(enum.Enum):
    """What a RefBox END payload means."""

    TIMEOUT = "timeout"  # Timeout() is true: the run's time counts, the run is over
    STOP = "stop"  # Running() is false: the benchmark is over
    NONE = "none"  # no reason given: the benchmark's own end, neither a timeout nor a stop
    UNKNOWN = "unknown"  # no known form: neither, as the 2015 BmBox went on; warned about

    @property
    def ends_early(self) -> bool:
        """A timeout or a stop: the RefBox cut the run (or the benchmark) short."""
        return self in (EndReason.TIMEOUT, EndReason.STOP)


@frozen_dataclass
class EndPayloadForm:
    """One RefBox END payload the 2015 code or the seed names, and where.

    Attributes:
        text: the whole payload, compared exactly.
        reason: what it means.
        source: where the form comes from.
        read_2015: whether the 2015 BmBox knew it (else it is read only by ertools' default).
    """

    text: str
    reason: EndReason
    source: str
    read_2015: bool


END_PAYLOAD_FORMS: tuple[EndPayloadForm, ...] = (
    EndPayloadForm(
        "reason: timeout",
        EndReason.TIMEOUT,
        "BmBox.py (7628309) l. 49, 97, 117 compare it exactly; the 2015 @Home RefBox "
        "(at_home_rsbb core_zone_exec.h, phase_post_2) sent it on a goal's timeout",
        True,
    ),
    EndPayloadForm(
        "reason: stop",
        EndReason.STOP,
        "BmBox.py (7628309) l. 53, 100, 126 compare it exactly; the 2015 @Home RefBox "
        "(at_home_rsbb core_zone_exec.h, phase_post_2) sent it on the benchmark's end or stop",
        True,
    ),
    EndPayloadForm(
        "timeout",
        EndReason.TIMEOUT,
        "seed 6.2.3 (the RefBox's timeout payload); unknown to the 2015 BmBox",
        False,
    ),
    EndPayloadForm(
        "halt",
        EndReason.STOP,
        "seed 6.2.3 (the referee's emergency halt); unknown to the 2015 BmBox",
        False,
    ),
    EndPayloadForm(
        "",
        EndReason.NONE,
        "seed 6.2.3 (a payload only when the RefBox issued the END); to the 2015 BmBox "
        "neither a timeout nor a stop",
        True,
    ),
)

_END_FORMS = {f.text: f for f in END_PAYLOAD_FORMS}


def end_reason(payload: str, *, exact_2015: bool = False) -> EndReason:
    """The meaning of a RefBox END payload: a known form, compared whole, else ``UNKNOWN``.

    Exact, as the 2015 BmBox compared (``"Reason: Stop"`` or ``"reason: stop "`` meant
    nothing to it); never guessed from the words in it. ``exact_2015``: only the forms the
    2015 BmBox knew (``--2015``), so the seed's bare ``timeout`` / ``halt`` are ``UNKNOWN``
    as they were to it. An ``UNKNOWN`` payload is neither a timeout nor a stop: callers warn
    with :func:`unknown_end_warning`.
    """
    form = _END_FORMS.get(payload)
    if form is None or (exact_2015 and not form.read_2015):
        return EndReason.UNKNOWN
    return form.reason


def seed_word(payload: str) -> bool:
    """Whether ``payload`` is one of the seed's words the 2015 BmBox did not know."""
    form = _END_FORMS.get(payload)
    return form is not None and not form.read_2015


def known_end_payloads(*, exact_2015: bool = False) -> str:
    """The known non-empty END payload forms of a reading, quoted, for messages."""
    return ", ".join(
        repr(f.text) for f in END_PAYLOAD_FORMS if f.text and (f.read_2015 or not exact_2015)
    )


def unknown_end_warning(payload: str, where: str, *, exact_2015: bool = False) -> str:
    """The one-line warning for a RefBox END payload that is no known form of the reading."""
    known = known_end_payloads(exact_2015=exact_2015)
    whose = "the 2015 BmBox knows (--2015)" if exact_2015 else "the 2015 BmBox or the seed know"
    return (
        f"{where}: RefBox END with payload {payload!r}, which is none of the forms {whose} "
        f"({known}); read as the 2015 BmBox did: neither a timeout nor a stop (the BmBox states "
        "show what followed)"
    )
