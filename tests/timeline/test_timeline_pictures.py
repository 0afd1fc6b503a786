"""The timeline's pictures: the HTML page parsed as HTML, the per-session figure, ``--plot``.

Expected sessions, bags and problems come from the layout of the generated day
(``timeline_day.SESSIONS``: six sessions over six hours, written down by hand) and from the
sample folder's answers file, not from the code under test.
"""

from __future__ import annotations

import json
import re
import time
from datetime import UTC, datetime
from html.parser import HTMLParser
from pathlib import Path
from typing import Any

import matplotlib.dates as mdates
import pytest
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.colors import to_hex

from ertools.cli.main import main
from ertools.report.plots_timeline import timeline_figure
from ertools.report.timeline_page import timeline_page
from ertools.timelines.model import Timeline
from ertools.timelines.scan import scan
from tests.helpers.timeline_day import (
    DAY0,
    EVIL,
    EVIL_IMG,
    SESSIONS,
    UNREADABLE,
    S,
    day_timeline,
    many_bags,
)

REAL = Path(__file__).resolve().parents[2] / ".." / "shared" / "real_bags"
REAL_BAG = REAL / "log_fbm2h_mocap_2015-10-23-16-15-40_0.bag"


class Page(HTMLParser):
    """Text, tags, attributes and the two scripts of a page."""

    def __init__(self, text: str) -> None:
        super().__init__()
        self.text: list[str] = []
        self.tags: list[str] = []
        self.attrs: list[tuple[str, str, str]] = []
        self.scripts: list[dict[str, str | None]] = []
        self.script_text: list[str] = []
        self._in_script = False
        self.feed(text)
        self.close()

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        self.tags.append(tag)
        self.attrs += [(tag, k, v or "") for k, v in attrs]
        if tag == "script":
            self.scripts.append(dict(attrs))
            self.script_text.append("")
            self._in_script = True

    def handle_endtag(self, tag: str) -> None:
        if tag == "script":
            self._in_script = False

    def handle_data(self, data: str) -> None:
        if self._in_script:
            self.script_text[-1] += data
        else:
            self.text.append(data)

    @property
    def all_text(self) -> str:
        return "".join(self.text)


def hms(ns: int) -> str:
    return datetime.fromtimestamp(ns / S, tz=UTC).strftime("%H:%M:%S")


def expected_day() -> list[tuple[str, list[str]]]:
    """(label, bag paths) per session from the layout; the copy on usb/ is no session member."""
    out = []
    for i, (hours, bags) in enumerate(SESSIONS, start=1):
        members = [b for b in bags if not b[0].startswith("usb/")]
        start = DAY0 + round((hours * 3600 + min(b[1] for b in members)) * S)
        end = DAY0 + round((hours * 3600 + max(b[2] for b in members)) * S)
        n = len(members)
        label = f"session {i}, {hms(start)}-{hms(end)}, {n} bag{'s' if n != 1 else ''}"
        out.append((label, [b[0] for b in bags]))
    return out


def check_page(page: Page, timeline: Timeline, labels: list[str], names: list[str]) -> None:
    """Every session label, bag name and problem text as text; nothing loaded, nothing run."""
    text = page.all_text
    for label in labels:
        assert label in text, label
    for name in names:
        assert name in text, name
    for b in timeline.bags:
        for problem in b.problems:
            assert problem in text, problem  # the parser unescapes: text, not markup
    # No remote anything: no src or href leaves the page.
    for tag, key, value in page.attrs:
        if key in ("src", "href"):
            assert "//" not in value and not value.lower().startswith(("http", "data:")), (
                tag,
                value,
            )
    assert "img" not in page.tags and "iframe" not in page.tags
    # Exactly the page's own two scripts: the JSON data and the chart code.
    assert [s.get("type") for s in page.scripts] == ["application/json", None]
    assert [s.get("id") for s in page.scripts] == ["tl-data", None]


def test_page_of_the_generated_day() -> None:
    tl = day_timeline()
    text = timeline_page(tl)
    page = Page(text)
    expected = expected_day()
    all_paths = [p for _, paths in expected for p in paths] + [UNREADABLE.path]
    check_page(page, tl, [label for label, _ in expected], all_paths)
    # the hostile names and problem texts are in the page only escaped
    assert EVIL not in text and EVIL_IMG not in text
    assert f"odd header {EVIL}" in page.all_text and f"FBM2H_{EVIL_IMG}.bag" in page.all_text
    assert f"truncated {EVIL}" in page.all_text  # the unreadable file's reason, in its table
    assert "http:" not in text and "https:" not in text
    # The data the chart is drawn from: every readable bag once, times from the layout.
    data = json.loads(page.script_text[0])
    assert len(data["bags"]) == 14 == sum(len(b) for _, b in SESSIONS)
    assert [s["label"] for s in data["sessions"]] == [label for label, _ in expected]
    t0 = data["t0"]
    assert t0 == DAY0 // S
    gap_bag = next(b for b in data["bags"] if b["name"].endswith("12-00-00_1.bag"))
    assert gap_bag["s"] == pytest.approx(3 * 3600 + 105, abs=1e-6)
    assert gap_bag["e"] == pytest.approx(3 * 3600 + 200, abs=1e-6)
    assert any("gap of 5.000 s" in p for p in gap_bag["problems"])
    # Pairs linked both ways: the 12:00 robot log and the two GT split files around its gap.
    names = [b["name"] for b in data["bags"]]
    robot = names.index("robots/FBM2H_201511201200_homer.bag")
    gts = sorted(names[i] for i in data["bags"][robot]["linked"])
    assert gts == [
        "gt/log_fbm2h_mocap_2015-11-20-12-00-00_0.bag",
        "gt/log_fbm2h_mocap_2015-11-20-12-00-00_1.bag",
    ]
    for i in data["bags"][robot]["linked"]:
        assert robot in data["bags"][i]["linked"]
    # the 5 s the robot log (50-150 s) spends in the GT gap (100-105 s) is marked uncovered
    assert data["bags"][robot]["uncovered"] == [
        pytest.approx([3 * 3600 + 100, 3 * 3600 + 105], abs=1e-6)
    ]
    # one lane per robot (team), whatever the run: homer's three runs share one lane
    homer = {b["lane"] for b in data["bags"] if "_homer.bag" in b["name"]}
    assert len(homer) == 1 and data["lanes"][homer.pop()] == "robot homer"
    copy = next(b for b in data["bags"] if b["name"].startswith("usb/"))
    assert copy["copy"] and "copy of robots/FBM2H_201511201500_homer.bag" in copy["tip"]


def test_legend_colours_are_the_bars_colours() -> None:
    page = Page(timeline_page(day_timeline()))
    data = json.loads(page.script_text[0])
    legend: dict[str, str] = {}
    kind = ""
    for tag, key, value in page.attrs:
        if tag == "span" and key == "data-kind":
            kind = value
        elif tag == "span" and key == "style" and kind:
            legend[kind] = value.removeprefix("background:")
            kind = ""
    assert set(legend) == {"gt", "benchmark", "robot"}  # the kinds in the day, no more
    for k, colour in legend.items():
        assert data["colors"][k] == colour
    assert len(set(data["colors"].values())) == len(data["colors"])  # distinct per kind


def test_page_of_the_sample_folder() -> None:
    root = Path(__file__).resolve().parents[2] / "sample_bags" / "timeline" / "bags"
    tl = scan([root])
    page = Page(timeline_page(tl))
    # from the answers file: two sessions, 15:00:00-15:00:34 (6 bags) and 15:00:40-15:00:46
    labels = ["session 1, 15:00:00-15:00:34, 6 bags", "session 2, 15:00:40-15:00:46, 1 bag"]
    names = [
        "gtlogger/log_fbm2h_mocap_2015-11-20-14-59-59_3.bag.active",
        "usb_stick/FBM2H_201511201500_homer.bag",
        "old/log_fbm2h_mocap_2015-11-20-15-00-59_0.bag",
    ]
    check_page(page, tl, labels, names)
    assert len(json.loads(page.script_text[0])["bags"]) == 8  # readable, the copy included


@pytest.mark.real
@pytest.mark.skipif(not REAL_BAG.exists(), reason=f"real 2015 bags not found at {REAL}")
def test_page_of_the_real_bag() -> None:
    tl = scan([REAL])
    page = Page(timeline_page(tl))
    # README: one GT logger bag of 57.6 s: one session. Its name has the logger's local start
    # time, 16:15:40 CEST (UTC+2): 14:15:40 UTC, ending 57.6 s later at 14:16:37.
    data = json.loads(page.script_text[0])
    assert len(data["bags"]) == 1 and data["bags"][0]["kind"] == "gt"
    assert data["bags"][0]["e"] - data["bags"][0]["s"] == pytest.approx(57.6, abs=0.1)
    (label,) = [s["label"] for s in data["sessions"]]
    assert label == "session 1, 14:15:40-14:16:37, 1 bag"
    check_page(page, tl, [label], [REAL_BAG.name])


@pytest.mark.slow
@pytest.mark.xdist_group("timing")
def test_page_of_1000_bags_is_built_quickly() -> None:
    tl = many_bags(1000)
    t = time.perf_counter()
    page = Page(timeline_page(tl))
    took = time.perf_counter() - t
    data = json.loads(page.script_text[0])
    assert len(data["bags"]) == 1000 and len(data["lanes"]) == 20
    assert took < 5.0  # about 0.1 s on the build machine; generous for a loaded CI box


# --- the static figure -----------------------------------------------------------------------


def session_axes(fig: Any) -> dict[int, Any]:
    return {
        int(ax.get_label().split()[1]): ax
        for ax in fig.axes
        if ax.get_label().startswith("session ")
    }


@pytest.mark.slow
def test_figure_has_one_panel_per_session_spanning_it() -> None:
    tl = day_timeline()
    fig = timeline_figure(tl)
    panels = session_axes(fig)
    assert sorted(panels) == [1, 2, 3, 4, 5, 6]
    for (label, _), (index, ax) in zip(expected_day(), sorted(panels.items()), strict=True):
        assert ax.get_title(loc="left").startswith(label)
        s = tl.sessions[index - 1]
        lo, hi = (mdates.num2date(x).timestamp() for x in ax.get_xlim())
        duration = s.duration_ns / S
        # the panel shows the session and little else: 5 % margin or 0.2 s, each side
        assert lo <= s.start_ns / S and hi >= s.end_ns / S
        assert hi - lo == pytest.approx(duration + 2 * max(0.05 * duration, 0.2), abs=1e-3)
    # the 8 s session: 8 s on a panel of 8.8 s, not a hairline on a 6-hour axis
    two = panels[2]
    lo, hi = two.get_xlim()
    bar = next(p for p in two.patches if p.get_gid() and "fbm3w_mocap" in p.get_gid())
    assert bar.get_width() / (hi - lo) == pytest.approx(8.0 / 8.8, abs=1e-6)


@pytest.mark.slow
def test_figure_colours_match_the_legend_and_problems_are_numbered() -> None:
    tl = day_timeline()
    fig = timeline_figure(tl)
    (legend,) = fig.legends
    by_label = {
        t.get_text(): to_hex(h.get_facecolor())
        for t, h in zip(legend.get_texts(), legend.legend_handles, strict=True)
    }
    kind_colour = {
        "gt": by_label["GT logger"],
        "benchmark": by_label["benchmark log"],
        "robot": by_label["robot log"],
    }
    assert len(set(kind_colour.values())) == 3
    kinds = {b.path: b for b in tl.bags}
    seen = set()
    for ax in session_axes(fig).values():
        for patch in ax.patches:
            path = patch.get_gid()
            if not path:
                continue
            b = kinds[path]
            seen.add(path)
            if b.copy_of is None:
                assert to_hex(patch.get_facecolor()) == kind_colour[b.kind], path
            assert bool(patch.get_hatch()) == bool(b.problems), path
            if b.problems:
                assert to_hex(patch.get_edgecolor()) == "#000000"
    assert seen == {b.path for b in tl.bags if b.readable}
    # numbered markers: 1..3 on the readable problem bags in time order; 4 is the unreadable
    marks = sorted(
        int(t.get_text())
        for ax in session_axes(fig).values()
        for t in ax.texts
        if t.get_text().isdigit()
    )
    assert marks == [1, 2, 3]
    problems = next(ax for ax in fig.axes if ax.get_label() == "problems")
    listing = problems.texts[0].get_text()
    assert "1. gt/log_fbm2h_mocap_2015-11-20-12-00-00_1.bag: gap of 5.000 s" in listing
    assert f"2. robots/FBM2H_{EVIL_IMG}.bag: odd header {EVIL}" in listing
    assert "3. usb/FBM2H_201511201500_homer.bag: same recording as" in listing
    assert f"4. {UNREADABLE.path} (unreadable): truncated {EVIL}" in listing


def test_table_times_stay_on_one_line() -> None:
    """Every time in the sessions and bags tables is one unbreakable span: a table cell that
    wraps inside ``2015-11-20 09:00:00.000`` misreads."""

    tl = day_timeline()
    text = timeline_page(tl)
    assert ".ts { white-space: nowrap; }" in text
    stamp = r"\d{4}-\d\d-\d\d \d\d:\d\d:\d\d\.\d{3}"
    assert not re.findall(rf"<td>{stamp}</td>", text)
    spans = re.findall(rf'<td><span class="ts">{stamp}</span></td>', text)
    readable = [b for b in tl.bags if b.readable]
    assert len(spans) == 2 * (len(tl.sessions) + len(readable))  # start and end of each


@pytest.mark.slow
def test_figure_problem_list_fits_the_picture() -> None:
    """The numbered problems are listed within the picture, however wide the panels' lane
    labels make its left margin (the whole sample folder: a rosbag2 lane label of 42
    characters)."""
    tl = scan([Path(__file__).resolve().parents[2] / "sample_bags"], check_clocks=False)
    fig = timeline_figure(tl)

    canvas = FigureCanvasAgg(fig)
    canvas.draw()
    problems = next(ax for ax in fig.axes if ax.get_label() == "problems")
    (listing,) = problems.texts
    assert listing.get_text().count("\n") >= 4  # the folder's problem bags, wrapped
    box = listing.get_window_extent(canvas.get_renderer())
    assert box.x0 >= 0 and box.x1 <= fig.bbox.x1, (box, fig.bbox)
    # and the panels' lane labels push the axes far right of where the list starts
    assert problems.get_window_extent(canvas.get_renderer()).x0 > box.x0 + 50


# --- the command line ------------------------------------------------------------------------


@pytest.mark.slow
def test_cli_plot_picks_the_format_by_suffix(folder: dict[str, Any], tmp_path: Path) -> None:
    page, png = tmp_path / "day.html", tmp_path / "day.png"
    argv = ["timeline", str(folder["root"]), "--plot", str(page), "--plot", str(png)]
    assert main(argv) == 0
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    parsed = Page(page.read_text(encoding="utf-8"))
    assert "session 1, 15:00:00-15:00:34, 6 bags" in parsed.all_text


def test_cli_plot_refuses_other_suffixes_before_reading(tmp_path: Path) -> None:
    # the folder does not exist: the usage error comes first, and nothing is written
    assert main(["timeline", str(tmp_path / "none"), "--plot", str(tmp_path / "x.pdf")]) == 2
    assert not (tmp_path / "x.pdf").exists()
