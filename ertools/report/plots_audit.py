"""The audit's figure: the three state machines over time, one lane each.

Drawing only (an ``Axes`` in, nothing global); the data comes from
:class:`ertools.audit.model.Audit`.
"""

from __future__ import annotations

from typing import Any

from ertools.report import units
from ertools.report.figures import FigureSpec
from ertools.states import Machine
from ertools.timeutil import ns_to_s

_LANES = (Machine.CLIENT, Machine.REFBOX, Machine.BMBOX)  # bottom to top
# Okabe & Ito's colour-blind-safe palette (2008), plus two greys that differ in lightness.
OKABE_ITO = {
    "orange": "#E69F00",
    "sky blue": "#56B4E9",
    "bluish green": "#009E73",
    "yellow": "#F0E442",
    "blue": "#0072B2",
    "vermillion": "#D55E00",
    "reddish purple": "#CC79A7",
    "light grey": "#DDDDDD",
    "dark grey": "#555555",
    "black": "#000000",
}
_P = OKABE_ITO
# One colour per state of each machine (the BmBox has ten states: every colour once). States
# of one phase of a run share their colour across the lanes, so a run reads down the figure:
# the client's WAITING_GOAL while the BmBox is TRANSMITTING_GOAL, the RefBox's
# EXECUTING_MANUAL_OPERATION while the BmBox waits for it.
STATE_COLOURS: dict[Machine, dict[str, str]] = {
    Machine.BMBOX: {
        "START": _P["light grey"],
        "WAITING_CLIENT": _P["sky blue"],
        "READY": _P["blue"],
        "WAITING_MANUAL_OPERATION": _P["yellow"],
        "COMPLETED_MANUAL_OPERATION": _P["orange"],
        "TRANSMITTING_GOAL": _P["reddish purple"],
        "EXECUTING_GOAL": _P["bluish green"],
        "WAITING_RESULT": _P["vermillion"],
        "TRANSMITTING_SCORE": _P["dark grey"],
        "END": _P["black"],
    },
    Machine.REFBOX: {
        "START": _P["light grey"],
        "WAITING_CLIENT": _P["sky blue"],
        "READY": _P["blue"],
        "EXECUTING_MANUAL_OPERATION": _P["yellow"],
        "EXECUTING_GOAL": _P["bluish green"],
        "RECEIVED_SCORE": _P["dark grey"],
        "END": _P["black"],
    },
    Machine.CLIENT: {
        "START": _P["light grey"],
        "CONNECTING": _P["sky blue"],
        "READY": _P["blue"],
        "WAITING_GOAL": _P["reddish purple"],
        "EXECUTING_GOAL": _P["bluish green"],
        "COMPLETED_GOAL": _P["vermillion"],
        "END": _P["black"],
    },
}
UNKNOWN_COLOUR = "#FFFFFF"  # UNKNOWN(<code>): white, outlined (no state has it)


def state_colour(machine: Machine, state: str) -> str:
    """The colour of one state of one machine."""
    return STATE_COLOURS[machine].get(state, UNKNOWN_COLOUR)


def figure_specs(audit: Any) -> list[FigureSpec]:
    """The timeline figure, when the audit has any state message."""
    if not audit.timeline:
        return []
    span_s = max(ns_to_s(audit.end_ns - audit.start_ns), 1.0)
    # Spans the page's width (a wide figure): wide enough that its fonts stay small there.
    width = min(18.0, max(13.0, span_s / 20.0))
    return [
        FigureSpec(
            "audit_timeline",
            "Benchmark state timeline",
            lambda ax: draw_timeline(ax, audit),
            (width, 5.0),
        )
    ]


def draw_timeline(ax: Any, audit: Any) -> None:
    """Gantt chart of the machines' states; runs shaded, findings marked.

    Red crosses: illegal BmBox transitions; grey hatching: heartbeat silences; a red line:
    the RefBox ended the benchmark (timeout/halt).
    """
    t0 = audit.start_ns
    lane = {m: i for i, m in enumerate(_LANES)}
    # Legend: one entry per colour, naming every state drawn in it (with its machine when
    # the name is not the BmBox's).
    # One collection per lane and colour (a broken_barh call costs the same for one bar as
    # for hundreds): the bars of a lane never overlap, so the picture is the same.
    groups: dict[tuple[int, str], list[tuple[float, float]]] = {}
    names: dict[str, list[str]] = {}
    for e in audit.timeline:
        colour = state_colour(e.machine, e.state_name)
        groups.setdefault((lane[e.machine], colour), []).append(
            (ns_to_s(e.start_ns - t0), max(ns_to_s(e.duration_ns), 0.05))
        )
        name = e.state_name
        if name not in STATE_COLOURS[Machine.BMBOX]:
            name = f"{name} ({e.machine.value})"
        if name not in names.setdefault(colour, []):
            names[colour].append(name)
    handles: dict[str, Any] = {}
    for (y, colour), spans in groups.items():
        bar = ax.broken_barh(
            spans,
            (y - 0.35, 0.7),
            facecolors=colour,
            edgecolors="white" if colour != UNKNOWN_COLOUR else "#444444",
            linewidth=0.4,
        )
        handles.setdefault(colour, bar)
    for r in audit.runs:
        ax.axvspan(ns_to_s(r.start_ns - t0), ns_to_s(r.end_ns - t0), color="#000000", alpha=0.04)
        ax.text(
            ns_to_s(r.start_ns - t0),
            len(_LANES) - 0.45,
            f"run {r.index}",
            fontsize=7,
            color="#333333",
        )
    for s in audit.silences:
        ax.broken_barh(
            [(ns_to_s(s.start_ns - t0), ns_to_s(s.duration_ns))],
            (lane[s.machine] - 0.45, 0.9),
            facecolors="none",
            edgecolors="#444444",
            hatch="///",
        )
    for x in audit.illegal_transitions:
        ax.plot(ns_to_s(x.t_ns - t0), lane[Machine.BMBOX], "x", color="#b42318", ms=10, mew=2)
    for end in audit.early_ends:
        ax.axvline(ns_to_s(end.t_ns - t0), color="#b42318", lw=1.5)
        ax.text(ns_to_s(end.t_ns - t0), -0.75, end.reason, color="#b42318", fontsize=8)
    ax.set_yticks(range(len(_LANES)), [m.value for m in _LANES])
    ax.set_ylim(-0.9, len(_LANES) - 0.2)
    ax.set_xlabel(units.label("time from the first state message", "time"))
    ax.legend(
        [handles[colour] for colour in names],
        [" / ".join(found) for found in names.values()],
        fontsize=7,
        ncols=3,
        loc="upper center",
        bbox_to_anchor=(0.5, -0.18),
        frameon=False,
    )
