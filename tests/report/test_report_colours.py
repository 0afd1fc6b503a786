"""The audit timeline's state colours: one per state of each machine, told apart by
colour-blind readers too."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from matplotlib.figure import Figure

from ertools.auditing.analyse import audit_states
from ertools.report import svg
from ertools.report.plots_audit import (
    OKABE_ITO,
    STATE_COLOURS,
    UNKNOWN_COLOUR,
    draw_timeline,
    timeline_chart,
)
from ertools.states import STATE_ENUMS, Machine
from tests.helpers import svg_figure
from tests.helpers.audit_streams import BMBOX, CLIENT, REFBOX, heartbeat

# Machado, Oliveira & Fernandes (2009), "A physiologically-based model for simulation of
# color vision deficiency", Table 1, severity 1.0: matrices on linear RGB.
DICHROMACY = {
    "protanopia": [
        [0.152286, 1.052583, -0.204868],
        [0.114503, 0.786281, 0.099216],
        [-0.003882, -0.048116, 1.051998],
    ],
    "deuteranopia": [
        [0.367322, 0.860646, -0.227968],
        [0.280085, 0.672501, 0.047413],
        [-0.011820, 0.042940, 0.968881],
    ],
    "tritanopia": [
        [1.255528, -0.076749, -0.178779],
        [-0.078411, 0.930809, 0.147602],
        [0.004733, 0.691367, 0.303900],
    ],
    "normal": np.eye(3).tolist(),
}
# Smallest distance (sRGB, each channel 0..1) between two simulated state colours: about
# 25/255 on one channel. The former palette had pairs at 0.041 for deuteranopes (EXECUTING_GOAL
# vs TRANSMITTING_SCORE) and the same colour for four pairs of states.
MIN_DISTANCE = 0.1


def _linear(hex_colour: str) -> np.ndarray:
    c = np.array([int(hex_colour[i : i + 2], 16) / 255.0 for i in (1, 3, 5)])
    return np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)


def _srgb(linear: np.ndarray) -> np.ndarray:
    c = np.clip(linear, 0.0, 1.0)
    return np.where(c <= 0.0031308, 12.92 * c, 1.055 * c ** (1 / 2.4) - 0.055)


@pytest.mark.parametrize("machine", list(Machine))
def test_every_state_has_its_own_colour(machine: Machine) -> None:
    names = [s.name for s in STATE_ENUMS[machine]]
    colours = STATE_COLOURS[machine]
    assert sorted(colours) == sorted(names)  # every state of the seed's listing, no other
    values = [colours[n].upper() for n in names]
    assert len(set(values)) == len(values), colours
    assert set(values) <= {c.upper() for c in OKABE_ITO.values()}
    assert UNKNOWN_COLOUR.upper() not in values


@pytest.mark.parametrize("vision", sorted(DICHROMACY))
@pytest.mark.parametrize("machine", list(Machine))
def test_state_colours_differ_for_colour_blind_readers(machine: Machine, vision: str) -> None:
    matrix = np.array(DICHROMACY[vision])
    seen = {n: _srgb(matrix @ _linear(c)) for n, c in STATE_COLOURS[machine].items()}
    closest = min(
        (float(np.linalg.norm(seen[a] - seen[b])), a, b) for a, b in itertools.combinations(seen, 2)
    )
    assert closest[0] >= MIN_DISTANCE, closest


def test_a_phase_keeps_its_colour_across_lanes() -> None:
    # The states of one moment of a run (seed 6.2) are drawn alike on the three lanes.
    bm, ref, cl = (STATE_COLOURS[m] for m in (Machine.BMBOX, Machine.REFBOX, Machine.CLIENT))
    assert bm["EXECUTING_GOAL"] == ref["EXECUTING_GOAL"] == cl["EXECUTING_GOAL"]
    assert bm["TRANSMITTING_GOAL"] == cl["WAITING_GOAL"]
    assert bm["WAITING_MANUAL_OPERATION"] == ref["EXECUTING_MANUAL_OPERATION"]
    assert bm["TRANSMITTING_SCORE"] == ref["RECEIVED_SCORE"]


@pytest.mark.slow
def test_timeline_bars_are_drawn_in_their_state_colour() -> None:
    audit = audit_states(
        heartbeat(Machine.BMBOX, BMBOX, 20.0),
        heartbeat(Machine.REFBOX, REFBOX, 20.0),
        heartbeat(Machine.CLIENT, CLIENT, 20.0),
        benchmark="fbm2h",
    )
    fig = svg_figure.read(svg.render(timeline_chart(audit), (13.0, 5.0)))
    ax, bx = fig.scale("x")
    # Each lane's centre: its tick label's (the label's baseline sits 0.35 em below it).
    lanes = {
        "".join(e.itertext()): float(e.get("y", "nan")) - 0.35 * float(e.get("font-size", "0"))
        for e in fig.root.iter()
        if e.get("class") == "ytick"
    }
    assert set(lanes) == {m.value for m in Machine}
    # Every bar drawn (one layer per colour): its left edge, its lane and its colour.
    drawn_bars = [
        (
            ax * float(r.get("x", "nan")) + bx,
            float(r.get("y", "nan")) + float(r.get("height", "nan")) / 2,
            group.get("fill"),
        )
        for group in fig.root.iter(f"{{{svg_figure.NS['s']}}}g")
        if group.get("fill")
        for r in group.findall("s:rect", svg_figure.NS)
    ]
    assert len(audit.timeline) >= 10
    for e in audit.timeline:
        start_s = (e.start_ns - audit.start_ns) / 1e9
        lane_y = lanes[e.machine.value]
        faces = [
            f
            for x, y, f in drawn_bars
            if abs(x - start_s) <= abs(ax) * 0.1 and abs(y - lane_y) <= 0.6
        ]
        assert faces == [STATE_COLOURS[e.machine][e.state_name]], e
    # The legend: one entry per colour drawn, each naming its state(s).
    entries = [e.get("data-label") or "" for e in fig.root.iter() if e.get("class") == "entry"]
    findings = {"silence", "illegal transition"}  # marked and named too, when there are any
    labels = [label for label in entries if label not in findings]
    drawn = {(e.machine, e.state_name) for e in audit.timeline}
    assert len(labels) == len({STATE_COLOURS[m][s] for m, s in drawn})
    assert any("EXECUTING_GOAL" in label for label in labels)
    # matplotlib draws the same chart (notebooks): one legend entry per colour too.
    mpl = Figure().add_subplot()
    draw_timeline(mpl, audit)
    assert [t.get_text() for t in mpl.get_legend().get_texts()] == entries
