"""The FBM3@Work run figure draws the ground truth's gaps where they are on the path and says
the run's valid fraction (issue 28): a noiseless synthetic line run with frames cut by hand, its
figure read back from the SVG (tests/helpers/svg_figure.py) and compared with the generator's points
either side of the hole."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from matplotlib.image import imread

from ertools.benchmarks.fbm3w.pipeline import score_paths
from ertools.benchmarks.fbm3w.settings import Fbm3wConfig
from ertools.benchmarks.fbm3w.shapes import builtin_shapes
from ertools.report.figures import figure_specs, render, wrap_title
from ertools.report.folder import write_report
from tests.benchmarks.fbm3w.fbm3w_synth import one_run
from tests.helpers import svg_figure

STILL = 30
PATH = 3000
L = np.linspace(0.0, 1.0, PATH)


def _result(cut: tuple[int, int]) -> object:
    """One line run without path frames [a, b): the reference and start phases first."""
    stream, window = one_run(builtin_shapes()["line"](L), still=STILL)
    keep = np.ones(len(stream), dtype=bool)
    keep[2 * STILL + cut[0] : 2 * STILL + cut[1]] = False
    return score_paths(stream.take(keep), [window], Fbm3wConfig(), bag_start_ns=0)


def _line_mm(i: int) -> tuple[float, float]:
    """Path point i of the line shape (x = 0.15 l, y = 0.045 l) in mm. The run frame has its
    origin at the start (l = 0) and x from the reference (0.05 m behind the start on the
    shape's x axis) to the start: the shape's own frame."""
    return 150.0 * L[i], 45.0 * L[i]


def _figure_named(result: object, name: str, path: Path) -> Path:
    (spec,) = [s for s in figure_specs(result) if s.name == name]
    render(spec, path)
    return path


def _figure(result: object, tmp_path: Path, suffix: str) -> Path:
    return _figure_named(result, "fbm3w_run0", tmp_path / f"run0.{suffix}")


def _tolerance(fig: svg_figure.Figure) -> float:
    # coordinates are written to 0.1 px and the scale is fitted to ticks at 0.1 px: a pixel
    # in data units is well above both
    return max(abs(fig.scale("x")[0]), abs(fig.scale("y")[0]))


@pytest.mark.slow
def test_a_gap_is_drawn_between_the_samples_around_the_hole(tmp_path: Path) -> None:
    # 30 frames cut: 0.258 s, under the 0.5 s a path may cross, so the run is scored
    result = _result((1000, 1030))
    run = result.runs[0]  # type: ignore[attr-defined]
    assert run.status == "scored"
    fig = svg_figure.read(_figure(result, tmp_path, "svg"))
    xy, n = fig.polyline("GT gap")
    assert n == 2
    tol = _tolerance(fig)
    assert xy[0] == pytest.approx(_line_mm(999), abs=tol)  # the last sample before the cut
    assert xy[1] == pytest.approx(_line_mm(1030), abs=tol)  # the first one after it
    # the still start and end phases repeat their pose (noiseless): drawn, but as no motion
    assert "tracking lost, robot still" in fig.labels()
    assert "tracking lost" not in fig.labels()
    title = " ".join(fig.texts("title"))
    # valid: the path's samples, the phases' 60 repeats and 31 frame periods missing
    frames = PATH + 2 * STILL - 30
    valid = (frames - 60) / (frames + 30)
    assert f"distance_error {run.distance_error * 1000:.3f} mm" in title
    assert title.endswith(f"GT {valid:.1%} valid")


def test_an_unscoreable_run_has_its_figure_and_verdict(tmp_path: Path) -> None:
    result = _result((1000, 1072))  # 0.61 s without data mid-path: unscoreable
    run = result.runs[0]  # type: ignore[attr-defined]
    assert run.status == "unscoreable"
    fig = svg_figure.read(_figure(result, tmp_path, "svg"))
    title = " ".join(fig.texts("title"))
    assert title.startswith(f"FBM3@Work run 0 (line): unscoreable: {run.unscoreable_reason}")
    xy, _ = fig.polyline("GT gap")
    tol = _tolerance(fig)
    assert xy[0] == pytest.approx(_line_mm(999), abs=tol)
    assert xy[1] == pytest.approx(_line_mm(1072), abs=tol)
    # the bar chart of the runs says the fraction too, under the verdict
    runs = svg_figure.read(_figure_named(result, "fbm3w_runs", tmp_path / "runs.svg"))
    assert any(t.endswith("% valid") for t in runs.texts("label"))


@pytest.mark.slow
def test_matplotlib_draws_the_gaps_too(tmp_path: Path) -> None:
    for cut in ((1000, 1030), (1000, 1072)):
        path = _figure(_result(cut), tmp_path, "png")
        assert imread(path).shape[0] > 100


def test_png_titles_wrap_to_the_figure() -> None:
    # matplotlib does not wrap a title; an unscoreable reason is wider than the figure
    result = _result((1000, 1072))
    (spec,) = [s for s in figure_specs(result) if s.name == "fbm3w_run0"]
    lines = wrap_title(spec.title, spec.size[0]).splitlines()
    assert len(lines) > 1 and all(len(line) <= 80 for line in lines)
    assert " ".join(lines) == spec.title


def test_the_report_folder_shows_the_unscoreable_runs_path(tmp_path: Path) -> None:
    result = _result((1000, 1072))
    index = write_report(result, tmp_path / "r", inputs=[], argv=["score", "fbm3w"])  # type: ignore[arg-type]
    figure = tmp_path / "r" / "figures" / "fbm3w_run0.svg"
    assert "figures/fbm3w_run0.svg" in index.read_text(encoding="utf-8")
    title = " ".join(svg_figure.read(figure).texts("title"))
    assert "unscoreable: " in title and "GT gap" in svg_figure.read(figure).labels()
