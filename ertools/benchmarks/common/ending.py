"""How a benchmark ended, as the 2015 BmBox saw it: the RefBox END messages and the log's end.

Shared by the FBM scorers (FBM1, FBM2@Home, FBM3@Work):

- :func:`refbox_ends`: each RefBox END in the log (the first message of each stretch of END),
  with what its payload means to the 2015 BmBox (:func:`ertools.states.end_reason`: the
  ``reason: timeout`` / ``reason: stop`` it compared exactly, the seed's ``timeout`` /
  ``halt``, anything else ``UNKNOWN``, warned with :func:`ertools.states.unknown_end_warning`
  and read as 2015 read it: neither);
- :func:`log_cut`: the moment a log ends inside the benchmark. The 2015 node published nothing
  for a benchmark cut short (it waited for a transition that never came); the rule all the
  scorers follow is that such a log is the benchmark **stopped there**, what the node does on
  a RefBox ``reason: stop`` (``Running()`` false: the run in progress gets no score and no
  time, the loop ends), and the output says so (:func:`cut_warning`).
"""

from __future__ import annotations

from dataclasses import dataclass

from ertools.states import BmBoxState, EndReason, RefBoxState, end_reason, state_name
from ertools.streams import StateStream
from ertools.timeutil import ns_to_s

# BmBox states of a benchmark that is over: the score is being sent, or the node ended.
_FINISHED = (BmBoxState.TRANSMITTING_SCORE, BmBoxState.END)


@dataclass(frozen=True)
class RefBoxEnd:
    """One RefBox END: when (the first message of its stretch), its payload, its meaning."""

    t_ns: int
    payload: str
    reason: EndReason


def refbox_ends(
    refbox: StateStream | None, start_ns: int | None = None, end_ns: int | None = None
) -> list[RefBoxEnd]:
    """Every RefBox END whose first message lies in [start_ns, end_ns] (None: open side).

    A payload change while in END is a new END (the BmBox callback read every message).
    """
    if refbox is None or len(refbox) == 0:
        return []
    ch = refbox.changes()
    out: list[RefBoxEnd] = []
    for t, s, p in zip(ch.t_ns.tolist(), ch.state.tolist(), ch.payload, strict=True):
        if s != RefBoxState.END:
            continue
        if (start_ns is None or t >= start_ns) and (end_ns is None or t <= end_ns):
            out.append(RefBoxEnd(int(t), p, end_reason(p)))
    return out


def log_cut(bmbox: StateStream | None, refbox: StateStream | None = None) -> int | None:
    """The time of the last BmBox message when the log ends inside the benchmark, else None.

    Inside: the last BmBox message is not TRANSMITTING_SCORE or END (the node had not finished)
    and no RefBox stop (``reason: stop`` / ``halt``) came at or before it (a stop is a stop,
    not a cut). An empty BmBox topic is no benchmark at all: None.
    """
    if bmbox is None or len(bmbox) == 0:
        return None
    last_t = int(bmbox.t_ns[-1])
    if int(bmbox.state[-1]) in _FINISHED:
        return None
    if any(e.reason is EndReason.STOP for e in refbox_ends(refbox, None, last_t)):
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
