"""How a benchmark ended, as the 2015 BmBox saw it: the RefBox END messages and the log's end.

Shared by the FBM scorers (FBM1, FBM2@Home, FBM3@Work):

- :func:`refbox_ends`: each RefBox END in the log (the first message of each stretch of END),
  with what its payload means (:func:`ertools.states.end_reason`: the ``reason: timeout`` /
  ``reason: stop`` the 2015 BmBox compared exactly; the seed's ``timeout`` / ``halt`` too by
  default, not under ``--exact-end-payloads`` (set by ``--2015``), as the 2015 BmBox knew only
  its two strings; anything else ``UNKNOWN``, read as 2015 read it: neither);
- :func:`end_payload_warnings`: one warning per unknown END, naming its file and time;
- :func:`end_payload_deviation`: the ``differs from 2015`` line when the default read one of the
  seed's words the 2015 BmBox did not know (:data:`RULE_END_PAYLOADS`);
- :func:`log_cut`: the moment a log ends inside the benchmark. The 2015 node published nothing
  for a benchmark cut short (it waited for a transition that never came); the rule all the
  scorers follow is that such a log is the benchmark **stopped there**, what the node does on
  a RefBox ``reason: stop`` (``Running()`` false: the run in progress gets no score and no
  time, the loop ends), and the output says so (:func:`cut_warning`).
"""

from __future__ import annotations

from ertools.benchmarks.common.inputs import EXACT_FLAG
from ertools.fidelity import Deviation, Rule
from ertools.frozen_dataclass import frozen_dataclass
from ertools.node_versions import NodeVersion
from ertools.states import (
    BmBoxState,
    EndReason,
    RefBoxState,
    end_reason,
    known_end_payloads,
    seed_word,
    state_name,
    unknown_end_warning,
)
from ertools.streams import StateStream
from ertools.timeutil import ns_to_s

RULE_END_PAYLOADS = Rule(
    key="all.end-payloads",
    benchmark="all",
    title="RefBox END payloads",
    rulebook="END with payload `timeout` or `halt` (seed 6.2.3); an empty payload: the RefBox "
    "did not issue the END",
    node_2015=(
        "rockin_scoring/BmBox.py (7628309) l. 49, 53, 117, 126: only the whole strings "
        "`reason: timeout` (Timeout()) and `reason: stop` (not Running()), which the 2015 "
        "@Home RefBox sent (at_home_rsbb core_zone_exec.h phase_post_2); `timeout` or `halt` "
        "meant neither"
    ),
    ertools=(
        "the 2015 strings and the seed's `timeout` / `halt`, each compared whole (a log "
        "written to the manual means what the manual says); any other payload is warned about "
        "with its file and time and read as neither, never guessed from its words"
    ),
    option=EXACT_FLAG,
)

# The rules of the BmBox every 2015 node imported (ertools.benchmarks.catalogue lists them).
RULES = (RULE_END_PAYLOADS,)

# The BmBox every node imports (rows of the version table, ertools.node_versions.NodeVersion).
_ALL_THREE = "RoCKIn 2015 Lisbon; Lisbon 2016 second local; Lisbon 2017 major tournament"
VERSIONS = (
    NodeVersion(
        "src/rockin_scoring/BmBox.py",
        "3a41cb2",
        "2015-07-06",
        "development (moved from src/rockin_benchmarking/, RoCKIn Camp 2015's 5fdbdc2)",
        "none (the package renamed): a RefBox END during a manual operation left "
        "ManualOperation() waiting",
        "not restorable: no competition of this table ran it",
    ),
    NodeVersion(
        "src/rockin_scoring/BmBox.py",
        "7628309",
        "2015-07-06",
        f"{_ALL_THREE} (unchanged through 89dfa75)",
        "any RefBox END moves WAITING_MANUAL_OPERATION to READY (l. 43-44) and "
        "ManualOperation() returns the RefBox payload (FBM1@Work's item): a stop during a "
        "manual operation ends the benchmark",
        "every `--2015` and `--rules` (tests/helpers/bmbox2015.py replays it)",
    ),
    NodeVersion(
        "src/rockin_scoring/FSM.py",
        "3a41cb2",
        "2015-07-06",
        f"{_ALL_THREE} (its only version)",
        "an update its transition table refuses changes nothing (BmBox.py 133-142): a RefBox "
        "stop while a goal is sent leaves the node waiting in SendGoal()",
        "every `--2015` and `--rules` (tests/helpers/bmbox2015.py replays it)",
    ),
)

# BmBox states of a benchmark that is over: the score is being sent, or the node ended.
_FINISHED = (BmBoxState.TRANSMITTING_SCORE, BmBoxState.END)


@frozen_dataclass
class RefBoxEnd:
    """One RefBox END: when (the first message of its stretch), its payload, its meaning."""

    t_ns: int
    payload: str
    reason: EndReason


def refbox_ends(
    refbox: StateStream | None,
    start_ns: int | None = None,
    end_ns: int | None = None,
    *,
    exact_2015: bool = False,
) -> list[RefBoxEnd]:
    """Every RefBox END whose first message lies in [start_ns, end_ns] (None: open side).

    A payload change while in END is a new END (the BmBox callback read every message).
    ``exact_2015``: read the payloads as the 2015 BmBox did (:func:`ertools.states.end_reason`).
    """
    if refbox is None or len(refbox) == 0:
        return []
    ch = refbox.changes()
    out: list[RefBoxEnd] = []
    for t, s, p in zip(ch.t_ns.tolist(), ch.state.tolist(), ch.payload, strict=True):
        if s != RefBoxState.END:
            continue
        if (start_ns is None or t >= start_ns) and (end_ns is None or t <= end_ns):
            out.append(RefBoxEnd(int(t), p, end_reason(p, exact_2015=exact_2015)))
    return out


def log_cut(
    bmbox: StateStream | None, refbox: StateStream | None = None, *, exact_2015: bool = False
) -> int | None:
    """The time of the last BmBox message when the log ends inside the benchmark, else None.

    Inside: the last BmBox message is not TRANSMITTING_SCORE or END (the node had not finished)
    and no RefBox stop (``reason: stop``; by default the seed's ``halt`` too) came at or before
    it (a stop is a stop, not a cut). An empty BmBox topic is no benchmark at all: None.
    """
    if bmbox is None or len(bmbox) == 0:
        return None
    last_t = int(bmbox.t_ns[-1])
    if int(bmbox.state[-1]) in _FINISHED:
        return None
    ends = refbox_ends(refbox, None, last_t, exact_2015=exact_2015)
    if any(e.reason is EndReason.STOP for e in ends):
        return None
    return last_t


def cut_warning(cut_ns: int, bmbox: StateStream, t0_ns: int, inside: str, consequence: str) -> str:
    """The line saying the log ended inside the benchmark and what that does to the score."""
    state = state_name(bmbox.machine, int(bmbox.state[-1]))
    return (
        f"the log ends at t={ns_to_s(cut_ns - t0_ns):.3f} s inside {inside} (BmBox in {state}): "
        f"read as the benchmark stopped there, as the 2015 node read a RefBox stop; "
        f"{consequence}"
    )


def end_place(refbox: StateStream, t_ns: int, t0_ns: int) -> str:
    """Where a RefBox END is: its file, topic and time from ``t0_ns``, for the messages."""
    name = refbox.source or "the log"
    topic = refbox.topic or "refbox_state"
    return f"{name}: {topic} at t={ns_to_s(t_ns - t0_ns):.3f} s"


def end_payload_warnings(
    refbox: StateStream | None, t0_ns: int, *, exact_2015: bool = False
) -> list[str]:
    """One warning per RefBox END whose payload is no known form of the reading, in time order.

    Each names its place (:func:`end_place`); the END is read as neither a timeout nor a
    stop, as the 2015 BmBox read a payload it did not compare equal.
    """
    if refbox is None:
        return []
    return [
        unknown_end_warning(e.payload, end_place(refbox, e.t_ns, t0_ns), exact_2015=exact_2015)
        for e in refbox_ends(refbox, exact_2015=exact_2015)
        if e.reason is EndReason.UNKNOWN
    ]


def end_payload_deviation(
    refbox: StateStream | None, t0_ns: int, *, exact_2015: bool = False
) -> Deviation | None:
    """The deviation line when the default read a seed word the 2015 BmBox did not know."""
    if refbox is None or exact_2015:
        return None
    read = [e for e in refbox_ends(refbox) if seed_word(e.payload)]
    if not read:
        return None
    first = read[0]
    said = ", ".join(
        f"{e.payload!r} at t={ns_to_s(e.t_ns - t0_ns):.3f} s as a {e.reason.value}" for e in read
    )
    return RULE_END_PAYLOADS.deviation(
        f"{refbox.source or 'the log'}: RefBox END payload(s) of the seed read by their meaning "
        f"({said}); the 2015 BmBox knew only {known_end_payloads(exact_2015=True)} and read "
        f"{first.payload!r} as neither a timeout nor a stop"
    )
