"""The audit's figure: the three state machines over time, one lane each, as a
:class:`~ertools.views.chart.Chart` (reports write it as SVG); the data comes from
:class:`ertools.auditing.model.Audit`.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ertools.report import chart_mpl
from ertools.states import Machine
from ertools.timeutil import ns_to_s
from ertools.views import units
from ertools.views.chart import Axis, Chart, Layer, Rects, RefLine, Scatter, Span, Text
from ertools.views.spec import ChartSpec

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


def figure_specs(audit: Any) -> list[ChartSpec]:
    """The timeline figure, when the audit has any state message."""
    if not audit.timeline:
        return []
    span_s = max(ns_to_s(audit.end_ns - audit.start_ns), 1.0)
    # Spans the page's width (a wide figure): wide enough that its fonts stay small there.
    width = min(18.0, max(13.0, span_s / 20.0))
    return [
        ChartSpec(
            "audit_timeline",
            "Benchmark state timeline",
            lambda size: timeline_chart(audit),
            (width, 5.0),
        )
    ]


def timeline_chart(audit: Any) -> Chart:
    """Gantt chart of the machines' states, one lane per machine; runs shaded, findings
    marked: red crosses, illegal BmBox transitions; hatching, heartbeat silences; a red
    line, the RefBox ended the benchmark (timeout/halt)."""
    t0 = audit.start_ns
    lane = {m: i for i, m in enumerate(_LANES)}
    # One layer per colour, over every lane (the legend names every state drawn in it, with
    # its machine when the name is not the BmBox's): a few layers, not one per state span.
    spans: dict[str, list[tuple[float, float, int]]] = {}
    names: dict[str, list[str]] = {}
    for e in audit.timeline:
        colour = state_colour(e.machine, e.state_name)
        start = ns_to_s(e.start_ns - t0)
        spans.setdefault(colour, []).append(
            (start, start + max(ns_to_s(e.duration_ns), 0.05), lane[e.machine])
        )
        name = e.state_name
        if name not in STATE_COLOURS[Machine.BMBOX]:
            name = f"{name} ({e.machine.value})"
        if name not in names.setdefault(colour, []):
            names[colour].append(name)
    layers: list[Layer] = [
        Span(ns_to_s(r.start_ns - t0), ns_to_s(r.end_ns - t0), "x", "#000000", 0.04)
        for r in audit.runs
    ]
    for colour, found in names.items():
        a = np.asarray(spans[colour], dtype=float)
        layers.append(
            Rects(
                a[:, 0],
                a[:, 1],
                a[:, 2] - 0.35,
                a[:, 2] + 0.35,
                colour,
                edge="#ffffff" if colour != UNKNOWN_COLOUR else "#444444",
                label=" / ".join(found),
            )
        )
    layers += [
        Text(ns_to_s(r.start_ns - t0), len(_LANES) - 0.45, f"run {r.index}", "#333333")
        for r in audit.runs
    ]
    if audit.silences:
        s = audit.silences
        starts = np.array([ns_to_s(x.start_ns - t0) for x in s])
        ends = starts + np.array([ns_to_s(x.duration_ns) for x in s])
        y = np.array([lane[x.machine] for x in s], dtype=float)
        layers.append(
            Rects(starts, ends, y - 0.45, y + 0.45, edge="#444444", hatch=True, label="silence")
        )
    if audit.illegal_transitions:
        x = np.array([ns_to_s(t.t_ns - t0) for t in audit.illegal_transitions])
        layers.append(
            Scatter(
                x,
                np.full(len(x), float(lane[Machine.BMBOX])),
                "#b42318",
                marker="x",
                size=6,
                label="illegal transition",
            )
        )
    for end in audit.early_ends:
        at = ns_to_s(end.t_ns - t0)
        layers.append(RefLine(at, "x", "#b42318", 1.5, "solid"))
        layers.append(Text(at, -0.75, end.reason, "#b42318"))
    return Chart(
        tuple(layers),
        x=Axis(units.label("time from the first state message", "time")),
        y=Axis(ticks=tuple((float(i), m.value) for i, m in enumerate(_LANES)), limits=(-0.9, 2.8)),
        grid="x",
    )


def draw_timeline(ax: Any, audit: Any) -> None:
    """The timeline chart drawn by matplotlib on ``ax`` (notebooks: :func:`ertools.api.figures`)."""
    chart_mpl.draw(timeline_chart(audit), ax)
