"""FBM1@Work through the same scorer (RefBox names the item), and the FBM1 figures."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from matplotlib.figure import Figure

from ertools.benchmarks.fbm1.config import Fbm1Options
from ertools.benchmarks.fbm1.pipeline import score_fbm1
from ertools.benchmarks.fbm1.runs import runs_from_states
from ertools.cli.main import main
from ertools.configs._yaml import parse_yaml
from ertools.configs.items import parse_items
from ertools.report import svg
from ertools.report.figures import figure_specs
from ertools.states import Machine
from tests.benchmarks.fbm1.fbm1_testkit import (
    ITEMS_YAML,
    RunSpec,
    bodies,
    state_streams,
    write_bag,
    write_items,
)
from tests.helpers import svg_figure

# Item 3 sits 5 cm along x and y of the board; the board at (0.3, 0.2) unrotated, so the item
# is at (0.35, 0.25) yaw 0; item 1 (0.1 m along x) at (0.4, 0.2).
WORK_RUNS = [
    RunSpec(
        "", "{item_class: b, item_instance: b2, x: 0.35, y: 0.25, theta: 0}", refbox_payload="b2"
    ),
    RunSpec(
        "", "{item_class: a, item_instance: a1, x: 0.4, y: 0.3, theta: 90}", refbox_payload="a1"
    ),
]


@pytest.mark.slow
def test_fbm1w_cli_uses_refbox_items(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    bag = write_bag(tmp_path / "work.bag", WORK_RUNS, namespace="fbm1w")
    items = write_items(tmp_path / "fbm1w.yaml")
    code = main(["score", "fbm1w", str(bag), "--items", str(items), "--format", "json"])
    out, err = capsys.readouterr()
    assert code == 0, err
    data = json.loads(out)
    assert data["benchmark"] == "fbm1w"
    assert data["runs"]["1"]["item"]["id"] == 3 and data["runs"]["2"]["item"]["id"] == 1
    assert data["runs"]["1"]["pose_score"] == pytest.approx(1.0, abs=1e-9)
    # Run 2: 0.1 m off in y, 90 deg off: 1 - 0.05 - 0.25.
    assert data["runs"]["2"]["pose_score"] == pytest.approx(0.7, abs=1e-9)
    assert "--gt result" in " ".join(data["deviations"])


@pytest.mark.slow
def test_fbm1w_items_order(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    runs = [RunSpec("", r.answer) for r in WORK_RUNS]  # nothing names the items in the log
    bag = write_bag(tmp_path / "work.bag", runs, namespace="fbm1w")
    items = write_items(tmp_path / "fbm1w.yaml")
    args = ["score", "fbm1w", str(bag), "--items", str(items), "--items-order", "3,a1"]
    code = main(args)
    out, err = capsys.readouterr()
    assert code == 0, err
    assert "class_accuracy: 1.0" in out and "instance_accuracy: 1.0" in out


def test_fbm1_figures_draw_the_answers() -> None:
    streams = state_streams(WORK_RUNS)
    found = runs_from_states(
        streams[Machine.BMBOX], streams[Machine.REFBOX], streams[Machine.CLIENT], benchmark="fbm1w"
    )
    origin, board = bodies(WORK_RUNS)
    items = parse_items(parse_yaml(ITEMS_YAML), "items.yaml")

    result = score_fbm1(origin, board, found, items, Fbm1Options(benchmark="fbm1w"))
    specs = {s.name: s for s in figure_specs(result)}
    assert set(specs) == {"fbm1w_pose_scores", "fbm1w_errors", "fbm1w_table"}
    # The reports' SVG: the answers (crosses) where the robot said, in mm on the table.
    table = svg_figure.read(svg.render(specs["fbm1w_table"].chart((7.0, 7.0)), (7.0, 7.0)))
    assert table.texts("xlabel") == ["x in the table frame (mm)"]
    ax, bx = table.scale("x")
    ay, by = table.scale("y")
    crosses = [
        e
        for e in table.root.iter()
        if e.get("class") == "marker" and e.tag.endswith("path") and "M" in e.get("d", "")
    ]
    answers = sorted(
        (
            round(ax * float(p[1]) + bx + 4.5 * abs(ax), 0),  # a cross' first stroke starts
            round(ay * float(p[2]) + by - 4.5 * abs(ay), 0),  # 4.5 px left of and above it
        )
        for e in crosses
        for p in svg_figure.PAIR.findall(e.get("d", ""))[:1]
    )
    assert answers == [(350.0, 250.0), (400.0, 300.0)]
    scores = svg_figure.read(svg.render(specs["fbm1w_pose_scores"].chart((7.0, 5.0)), (7.0, 5.0)))
    ay, _ = scores.scale("y")
    heights = [
        abs(ay) * float(r.get("height", "nan"))
        for r in scores.root.iter()
        if r.get("class") == "bar"
    ]
    assert heights == pytest.approx([1.0, 0.7], abs=abs(ay) * 0.2)
    legend = [e.get("data-label") for e in scores.root.iter() if e.get("class") == "entry"]
    assert legend == [
        "mean",
        "class and instance right",
        "instance wrong",
        "class wrong",
        "no answer / not scored",
    ]
    # matplotlib draws the same chart (PNG on request).
    ax_ = Figure().add_subplot()
    specs["fbm1w_pose_scores"].draw(ax_)
    heights = [p.get_height() for p in ax_.patches]
    assert heights == pytest.approx([1.0, 0.7], abs=1e-9)
