"""The audit's figure: the three state machines over time, one lane each.

Drawing only (an ``Axes`` in, nothing global); the data comes from :class:`ertools.audit.Audit`.
"""

from __future__ import annotations

from typing import Any

from ertools.report.figures import FigureSpec
from ertools.streams import Machine
from ertools.timeutil import ns_to_s

_LANES = (Machine.CLIENT, Machine.REFBOX, Machine.BMBOX)  # bottom to top
_COLOURS = {
    "START": "#c9d1dc",
    "WAITING_CLIENT": "#aab6c6",
    "CONNECTING": "#aab6c6",
    "READY": "#8fc1e3",
    "WAITING_GOAL": "#8fc1e3",
    "WAITING_MANUAL_OPERATION": "#f2c46d",
    "EXECUTING_MANUAL_OPERATION": "#f2c46d",
    "COMPLETED_MANUAL_OPERATION": "#e9a23b",
    "TRANSMITTING_GOAL": "#b39ddb",
    "EXECUTING_GOAL": "#5fae6e",
    "WAITING_RESULT": "#2e7d4f",
    "COMPLETED_GOAL": "#2e7d4f",
    "TRANSMITTING_SCORE": "#d96c6c",
    "RECEIVED_SCORE": "#d96c6c",
    "END": "#555e6b",
}


def figure_specs(audit: Any) -> list[FigureSpec]:
    """The timeline figure, when the audit has any state message."""
    if not audit.timeline:
        return []
    span_s = max(ns_to_s(audit.end_ns - audit.start_ns), 1.0)
    width = min(16.0, max(9.0, span_s / 20.0))
    return [
        FigureSpec(
            "audit_timeline",
            "Benchmark state timeline",
            lambda ax: draw_timeline(ax, audit),
            (width, 4.2),
        )
    ]


def draw_timeline(ax: Any, audit: Any) -> None:
    """Gantt chart of the machines' states; runs shaded, findings marked.

    Red crosses: illegal BmBox transitions; grey hatching: heartbeat silences; a red line:
    the RefBox ended the benchmark (timeout/halt).
    """
    t0 = audit.start_ns
    lane = {m: i for i, m in enumerate(_LANES)}
    seen: dict[str, Any] = {}
    for e in audit.timeline:
        y = lane[e.machine]
        colour = _COLOURS.get(e.state_name, "#999999")
        bar = ax.broken_barh(
            [(ns_to_s(e.start_ns - t0), max(ns_to_s(e.duration_ns), 0.05))],
            (y - 0.35, 0.7),
            facecolors=colour,
            edgecolors="white",
            linewidth=0.4,
        )
        seen.setdefault(e.state_name, bar)
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
    ax.set_xlabel("time from the first state message [s]")
    ax.legend(
        list(seen.values()),
        list(seen),
        fontsize=7,
        ncols=5,
        loc="upper center",
        bbox_to_anchor=(0.5, -0.25),
        frameon=False,
    )
