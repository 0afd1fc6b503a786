"""The reports' vector figures (issue 29): an FBM3@Work and an FBM2@Home report of the sample
bags, their SVG figures read back as data, and the pages opened in headless Chromium.

The figures are written from the arrays by ``ertools.report.svg`` (no matplotlib); these tests
check what a reader of them sees: one measured path per run, thinned to the figure's pixels
but still on the measured samples, axes in millimetres, every legend entry, and the browser
loading and painting every figure of the page.
"""

from __future__ import annotations

import re
import shutil
import subprocess
from html.parser import HTMLParser
from pathlib import Path

import numpy as np
import pytest
from matplotlib.image import imread

from ertools import api
from ertools.report.folder import write_report
from tests.helpers import svg_figure
from tests.helpers.fakes import BROWSER, CHROMIUM_FLAGS

pytestmark = pytest.mark.slow

REPO = Path(__file__).resolve().parents[2]
FBM3W = sorted((REPO / "sample_bags" / "fbm3w").glob("*.bag"))
FBM2H = REPO / "sample_bags" / "fbm2h"
# The figure's pixels (8 x 5.5 in at 110 px per inch) bound what a thinned path can keep: at
# two cells per pixel on each axis, a path crossing the figure once keeps at most ~2 vertices
# per pixel of its length; the sample paths are far longer than that in samples.
RUN_PIXELS = 8.0 * 110 * 2


class _Imgs(HTMLParser):
    def __init__(self) -> None:
        super().__init__()
        self.srcs: list[str] = []

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        if tag == "img":
            self.srcs.append(dict(attrs).get("src") or "")


@pytest.fixture(scope="module")
def fbm3w(tmp_path_factory: pytest.TempPathFactory) -> tuple[object, Path]:
    result = api.score("fbm3w", FBM3W)
    out = tmp_path_factory.mktemp("svg") / "fbm3w"
    return result, write_report(result, out, inputs=FBM3W, argv=["ertools", "score", "fbm3w"])


@pytest.fixture(scope="module")
def fbm2h(tmp_path_factory: pytest.TempPathFactory) -> tuple[object, Path]:
    bag = FBM2H / "log_fbm2h_mocap_2015-11-20-12-00-00_0.bag"
    result = api.score(
        "fbm2h",
        bag,
        goal=FBM2H / "fbm2h_goal.yaml",
        transform=FBM2H / "transform-simbot.yaml",
    )
    out = tmp_path_factory.mktemp("svg") / "fbm2h"
    return result, write_report(result, out, inputs=[bag], argv=["ertools", "score", "fbm2h"])


def test_fbm3w_path_figures_hold_each_runs_measured_path(fbm3w: tuple[object, Path]) -> None:
    result, index = fbm3w
    scored = [r for r in result.runs if r.score is not None]  # type: ignore[attr-defined]
    assert len(scored) >= 3
    for run in scored:
        fig = svg_figure.read(index.parent / "figures" / f"fbm3w_run{run.index}.svg")
        assert fig.texts("xlabel")[0].startswith("x in the run frame (mm)")
        assert fig.texts("ylabel") == ["y in the run frame (mm)"]
        assert " ".join(fig.texts("title")) == (
            f"FBM3@Work run {run.index} ({run.spec}): distance_error "
            f"{run.distance_error * 1000:.3f} mm; GT {run.validity.valid_fraction:.1%} valid"
        )
        legend = [e.get("data-label") for e in fig.root.iter() if e.get("class") == "entry"]
        # then one entry per kind of GT gap the run has (issue 28), in this order
        kinds = {
            ("gap", True): "GT gap",
            ("tracking_lost", True): "tracking lost",
            ("tracking_lost", False): "tracking lost, robot still",
        }
        has = {kinds.get((g.reason, g.lost), "invalid GT") for g in run.gaps}
        assert legend == [
            f"target ({run.spec})",
            "measured (every sample)",
            f"kept samples ({len(run.score.kept_frame)}, d_min {run.d_min * 1000:g} mm)",
            "compared with target(l/L)",
            "start",
            "reference",
            *(k for k in [*kinds.values(), "invalid GT"] if k in has),
        ]
        # One polyline of the measured path: fewer vertices than samples (thinned to the
        # figure), more than a handful, none of them off the measured samples.
        measured = np.asarray(run.frame_xy) * 1000.0
        line, count = fig.polyline("measured (every sample)")
        assert count == len(line)
        assert 20 < count < min(len(measured), RUN_PIXELS)
        ax, _ = fig.scale("x")
        ay, _ = fig.scale("y")
        px_mm = max(abs(ax), abs(ay))  # one pixel in mm; the file holds 0.1 px
        gap = np.min(
            np.hypot(*(line[:, None, :2] - measured[None, :, :2]).transpose(2, 0, 1)), axis=1
        )
        assert gap.max() < 0.2 * px_mm
        # Its ends are the first and last sample.
        assert np.allclose(line[0], measured[0, :2], atol=0.2 * px_mm)
        assert np.allclose(line[-1], measured[-1, :2], atol=0.2 * px_mm)
        # Every kept sample is a marker, coloured on the error scale.
        kept = fig.series(
            f"kept samples ({len(run.score.kept_frame)}, d_min {run.d_min * 1000:g} mm)"
        )
        assert len(kept.findall("s:circle", svg_figure.NS)) == len(run.score.kept_frame)
        assert fig.texts("clabel") == ["error (mm)"]


def test_fbm2h_figures_show_waypoints_and_errors(fbm2h: tuple[object, Path]) -> None:
    result, index = fbm2h
    segments = result.segments  # type: ignore[attr-defined]
    path = svg_figure.read(index.parent / "figures" / "fbm2h_path.svg")
    assert path.texts("xlabel") == ["x in the testbed frame (mm)"]
    # Each waypoint: a marker, its number beside it, and a heading arrow.
    marks = path.series("waypoint (target heading)")
    assert len(marks.findall("s:circle", svg_figure.NS)) == len(segments)
    assert sorted(path.texts("label")) == sorted(str(s.index) for s in segments)
    arrows = [p for p in path.root.iter() if p.get("class") == "arrow-head"]
    reached = sum(s.robot is not None for s in segments)
    assert len(arrows) == len(segments) + reached
    # The waypoint markers sit at the goal's targets (mm), read back through the ticks.
    ax, bx = path.scale("x")
    ay, by = path.scale("y")
    xy = np.array(
        [
            (ax * float(c.get("cx", "nan")) + bx, ay * float(c.get("cy", "nan")) + by)
            for c in marks.findall("s:circle", svg_figure.NS)
        ]
    )
    targets = np.array([s.target[:2] for s in segments]) * 1000.0
    assert np.allclose(xy, targets, atol=abs(ax) * 0.2)

    errors = svg_figure.read(index.parent / "figures" / "fbm2h_errors.svg")
    assert errors.texts("ylabel") == ["distance error (mm)"]
    assert errors.texts("rlabel") == ["orientation error (deg)"]
    ay, _ = errors.scale("y")
    heights = [
        abs(ay) * float(r.get("height", "nan"))
        for r in errors.series("distance error").findall("s:rect", svg_figure.NS)
    ]
    expected = [s.distance_error * 1000.0 for s in segments if s.distance_error is not None]
    assert np.allclose(heights, expected, atol=abs(ay) * 0.2)


def _chromium(tmp_path: Path, url: str, *extra: str) -> subprocess.CompletedProcess[str]:
    profile = tmp_path / f"profile{len(list(tmp_path.glob('profile*')))}"
    return subprocess.run(
        [BROWSER or "chromium", *CHROMIUM_FLAGS, f"--user-data-dir={profile}", *extra, url],
        capture_output=True,
        text=True,
        timeout=90,
        check=False,
    )


# Counts the page's figures the browser decoded (an SVG it cannot read has no natural size).
# The report has no script (its CSP forbids them); this copy of it gets one.
_LOADED = """<script>
window.addEventListener("load", () => {
  const imgs = [...document.querySelectorAll("main img")];
  const ok = imgs.filter(i => i.complete && i.naturalWidth > 100 && i.naturalHeight > 100);
  document.body.setAttribute("data-imgs", String(imgs.length));
  document.body.setAttribute("data-loaded", ok.map(i => i.getAttribute("src")).join(" "));
});
</script>"""


@pytest.mark.browser
@pytest.mark.skipif(BROWSER is None, reason="chromium not installed (apt-get install chromium)")
@pytest.mark.parametrize("which", ["fbm3w", "fbm2h"])
def test_browser_loads_every_svg_figure(
    which: str, request: pytest.FixtureRequest, tmp_path: Path
) -> None:
    _, index = request.getfixturevalue(which)
    srcs = _Imgs()
    srcs.feed(index.read_text(encoding="utf-8"))
    svgs = [s for s in srcs.srcs if s.endswith(".svg")]
    names = {"fbm3w": "fbm3w_run", "fbm2h": "fbm2h_path"}
    assert any(names[which] in s for s in svgs), srcs.srcs
    copy = tmp_path / "copy"
    shutil.copytree(index.parent, copy)
    page = (copy / "index.html").read_text(encoding="utf-8")
    page, n = re.subn(r'<meta http-equiv="Content-Security-Policy"[^>]*>', "", page)
    assert n == 1
    (copy / "index.html").write_text(page.replace("</body>", _LOADED + "</body>"), "utf-8")
    proc = _chromium(
        tmp_path, (copy / "index.html").as_uri(), "--dump-dom", "--virtual-time-budget=5000"
    )
    assert proc.returncode == 0, proc.stderr[-2000:]
    loaded = re.search(r'data-loaded="([^"]*)"', proc.stdout)
    assert loaded is not None, proc.stdout[-2000:]
    assert set(svgs) <= set(loaded.group(1).split()), (svgs, loaded.group(1))


@pytest.mark.browser
@pytest.mark.skipif(BROWSER is None, reason="chromium not installed (apt-get install chromium)")
def test_browser_paints_the_path_figure(fbm3w: tuple[object, Path], tmp_path: Path) -> None:
    """The run figure as Chromium paints it: the black target line, the viridis markers of
    the kept samples at both ends of the scale, the green start."""

    _, index = fbm3w
    shot = tmp_path / "shot.png"
    svg = index.parent / "figures" / "fbm3w_run1.svg"
    proc = _chromium(tmp_path, svg.as_uri(), f"--screenshot={shot}", "--window-size=880,605")
    assert proc.returncode == 0 and shot.exists(), proc.stderr[-2000:]
    pixels = (imread(shot)[..., :3] * 255).round().astype(int)

    def count(colour: str, tol: int = 12) -> int:
        rgb = np.array([int(colour[i : i + 2], 16) for i in (1, 3, 5)])
        return int((np.abs(pixels - rgb).max(axis=2) <= tol).sum())

    assert count("#000000", 40) > 500  # target line, frame, text
    assert count("#440154") > 20  # viridis' low end: the smallest errors
    assert count("#fde725", 20) > 20  # its high end: the largest (and the colour bar)
    assert count("#2ca02c") > 20  # the start
