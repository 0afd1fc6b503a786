"""The timeline page in a real browser: headless Chromium opens it from disk, offline.

The page's script builds the chart; ``--dump-dom`` gives the DOM after it ran, so the tests
count the bars it drew and read the view it zoomed to (``page.html#session=2``) from the
attributes it wrote. The page's Content-Security-Policy forbids every fetch, and Chromium
runs with networking features off: a page that needed the network would show no chart.
Skipped, saying why, where Chromium is not installed (Debian: ``apt-get install chromium``).
"""

from __future__ import annotations

import subprocess
from html.parser import HTMLParser
from pathlib import Path

import pytest

from ertools.report.timeline_page import write_timeline_page
from ertools.timelines.model import Timeline
from ertools.timelines.scan import scan
from tests.helpers.fakes import BROWSER, CHROMIUM_FLAGS
from tests.helpers.timeline_day import EVIL, EVIL_IMG, S, day_timeline
from tests.timeline.test_timeline_pictures import expected_day

pytestmark = [pytest.mark.browser, pytest.mark.slow]

FLAGS = [
    *CHROMIUM_FLAGS,
    "--window-size=1400,900",
    # No proxy can be reached: anything the page tried to fetch would fail.
    "--proxy-server=127.0.0.1:9",
    "--enable-logging=stderr",
    "--v=0",
]
needs_browser = pytest.mark.skipif(
    BROWSER is None, reason="chromium not installed (apt-get install chromium)"
)


class Dom(HTMLParser):
    """The chart's elements in a dumped DOM."""

    def __init__(self, text: str) -> None:
        super().__init__()
        self.svg: dict[str, str] = {}
        self.bars: list[dict[str, str]] = []
        self.bands: list[dict[str, str]] = []
        self.clip: dict[str, str] = {}
        self.titles: list[str] = []
        self.ticks: list[str] = []
        self.links = 0
        self._tick: str | None = None
        self.tags: list[str] = []
        self.scripts = 0
        self.body: dict[str, str] = {}
        self._stack: list[str] = []
        self._title: str | None = None
        self._in_clip = False
        self.feed(text)

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        a = {k: v or "" for k, v in attrs}
        self.tags.append(tag)
        cls = a.get("class", "").split()
        if tag == "body":
            self.body = a
        elif tag == "svg" and a.get("id") == "tl-svg":
            self.svg = a
        elif tag == "rect" and "bar" in cls:
            self.bars.append(a)
        elif tag == "rect" and "band" in cls:
            self.bands.append(a)
        elif tag == "clippath":
            self._in_clip = True
        elif tag == "rect" and self._in_clip:
            self.clip = a
        elif tag == "title":
            self._title = ""
        elif tag == "line" and "link" in cls:
            self.links += 1
        elif tag == "text" and "tick-label" in cls:
            self._tick = ""
        elif tag == "script":
            self.scripts += 1

    def handle_endtag(self, tag: str) -> None:
        if tag == "text" and self._tick is not None:
            self.ticks.append(self._tick)
            self._tick = None
        elif tag == "clippath":
            self._in_clip = False
        elif tag == "title" and self._title is not None:
            self.titles.append(self._title)
            self._title = None

    def handle_data(self, data: str) -> None:
        if self._title is not None:
            self._title += data
        if self._tick is not None:
            self._tick += data


def dump(tmp_path: Path, url: str) -> tuple[Dom, str]:
    profile = tmp_path / f"profile{len(list(tmp_path.glob('profile*')))}"
    proc = subprocess.run(
        [BROWSER or "chromium", *FLAGS, f"--user-data-dir={profile}", "--dump-dom", url],
        capture_output=True,
        text=True,
        timeout=90,
        check=False,
    )
    assert proc.returncode == 0, proc.stderr[-2000:]
    return Dom(proc.stdout), proc.stderr


def no_script_errors(stderr: str) -> None:
    # Chromium logs uncaught exceptions and CSP refusals of the page as console lines.
    bad = [
        line
        for line in stderr.splitlines()
        if "CONSOLE" in line and ("Uncaught" in line or "Refused" in line)
    ]
    assert not bad, bad


@pytest.fixture(scope="module")
def day(tmp_path_factory: pytest.TempPathFactory) -> tuple[Timeline, Path]:
    tl = day_timeline()
    return tl, write_timeline_page(tl, tmp_path_factory.mktemp("page") / "day.html")


@needs_browser
def test_page_loads_offline_and_draws_every_bag(day: tuple[Timeline, Path], tmp_path: Path) -> None:
    tl, page = day
    dom, stderr = dump(tmp_path, page.as_uri() + "#day")
    no_script_errors(stderr)
    assert dom.svg.get("data-ready") == "1", "the chart script did not finish"
    readable = [b for b in tl.bags if b.readable]
    assert len(dom.bars) == len(readable) == 14
    assert len(dom.bands) == len(tl.sessions) == 6
    # kinds drawn in their legend colours: one colour per kind
    fills = {(b["data-kind"], b["fill"]) for b in dom.bars}
    assert len(fills) == len({k for k, _ in fills}) == 3
    # Fit day: the view holds the day (09:00:00 to 15:02:00) and little more.
    start, end = float(dom.svg["data-view-start"]), float(dom.svg["data-view-end"])
    first = min(b.start_ns for b in readable if b.start_ns is not None) / S
    last = max(b.end_ns for b in readable if b.end_ns is not None) / S
    assert start <= first and end >= last
    assert end - start <= (last - first) * 1.05
    # every problem, with the hostile text as text, in the tooltips; nothing injected ran
    tips = "\n".join(dom.titles)
    for b in readable:
        for problem in b.problems:
            assert problem in tips
    assert f"odd header {EVIL}" in tips and f"FBM2H_{EVIL_IMG}.bag" in tips
    assert "img" not in dom.tags and dom.scripts == 2
    # each session band's tooltip is its label, computed from the day's layout
    bands = [t for t in dom.titles if t.startswith("session ")]
    assert bands == [label for label, _ in expected_day()]


@needs_browser
def test_page_opens_on_the_sessions(day: tuple[Timeline, Path], tmp_path: Path) -> None:
    """Without a fragment the page opens on the sessions, not on a day in which they are
    slivers: the day's six sessions fill little of its six hours, so it opens on the one with
    the most bags (ties: the first)."""
    tl, page = day
    dom, stderr = dump(tmp_path, page.as_uri())
    no_script_errors(stderr)
    day_s = (tl.sessions[-1].end_ns - tl.sessions[0].start_ns) / S
    assert sum(s.duration_ns for s in tl.sessions) / S < 0.2 * day_s
    most = max(len(s.paths) for s in tl.sessions)
    busiest = next(s for s in tl.sessions if len(s.paths) == most)
    s0, s1 = busiest.start_ns / S, busiest.end_ns / S
    start, end = float(dom.svg["data-view-start"]), float(dom.svg["data-view-end"])
    assert start <= s0 and end >= s1
    assert end - start <= (s1 - s0) * 1.2 + 1.0  # the session and its margin (8 %, >= 0.5 s)


@needs_browser
def test_fragment_zooms_to_the_session(day: tuple[Timeline, Path], tmp_path: Path) -> None:
    tl, page = day
    dom, stderr = dump(tmp_path, page.as_uri() + "#session=2")
    no_script_errors(stderr)
    two = tl.sessions[1]
    s0, s1 = two.start_ns / S, two.end_ns / S  # 10:30:00 to 10:30:08
    start, end = float(dom.svg["data-view-start"]), float(dom.svg["data-view-end"])
    # The 8 s session fills the view (with a margin): not a sliver of a 6-hour day.
    assert start <= s0 and end >= s1
    assert 8.0 < end - start < 10.0
    left, width = float(dom.clip["x"]), float(dom.clip["width"])
    px_per_s = float(dom.svg["data-px-per-s"])
    assert px_per_s == pytest.approx(width / (end - start), rel=1e-6)
    bars = {tl.bags[int(b["data-i"])].path: b for b in dom.bars}
    gt = bars["gt_work/log_fbm3w_mocap_2015-11-20-10-30-00_0.bag"]  # 0 to 8 s
    robot = bars["robots/FBM3W_201511201030_bitbots.bag"]  # 1 to 7 s
    # x and width from the session's times (attributes rounded to 0.01 px)
    assert float(gt["x"]) == pytest.approx(left + (s0 - start) * px_per_s, abs=0.02)
    assert float(gt["width"]) == pytest.approx(8.0 * px_per_s, abs=0.02)
    assert float(robot["x"]) - float(gt["x"]) == pytest.approx(1.0 * px_per_s, abs=0.02)
    assert float(robot["width"]) == pytest.approx(6.0 * px_per_s, abs=0.02)
    # tick labels on whole seconds of the session (last: the date in the corner)
    assert dom.ticks[-1] == "2015-11-20 UTC"
    assert dom.ticks[:-1] == [f"10:30:0{i}" for i in range(len(dom.ticks) - 1)]
    assert len(dom.ticks) - 1 >= 8  # 10:30:00 to 10:30:08 at least every second
    # the other sessions' bars are out of view (hours away)
    for path, b in bars.items():
        if path not in (
            "gt_work/log_fbm3w_mocap_2015-11-20-10-30-00_0.bag",
            "robots/FBM3W_201511201030_bitbots.bag",
        ):
            x, w = float(b["x"]), float(b["width"])
            assert x + w <= left or x >= left + width, path


# Synthetic input, dispatched after the page's script ran: the chart's own handlers react to
# it as to a mouse. What the view was before, and where the pointer is, go into the DOM.
INPUT = """<script>
(function () {
  var svg = document.getElementById("tl-svg"), r = svg.getBoundingClientRect();
  var clip = document.querySelector("#tl-clip rect");
  var x = Math.round(r.left + (+clip.getAttribute("x")) + 0.25 * (+clip.getAttribute("width")));
  var y = Math.round(r.top + 60);
  document.body.setAttribute("data-before", [svg.getAttribute("data-view-start"),
    svg.getAttribute("data-view-end"), x - r.left, svg.getAttribute("data-px-per-s")].join(","));
  function send(type, cls, dx, extra) {
    var init = {clientX: x + dx, clientY: y, bubbles: true, cancelable: true, pointerId: 1,
                isPrimary: true, pointerType: "mouse", button: 0, buttons: 1};
    for (var k in extra) { init[k] = extra[k]; }
    svg.dispatchEvent(new cls(type, init));
  }
  %s
  // the handlers redraw on the next animation frame, which a page being dumped may never
  // get: a resize redraws at once, from the view the handlers set
  window.dispatchEvent(new Event("resize"));
})();
</script>"""
WHEEL = 'send("wheel", WheelEvent, 0, {deltaY: -400, deltaMode: 0});'
DRAG = (
    'send("pointerdown", PointerEvent, 0, {}); send("pointermove", PointerEvent, 60, {});'
    'send("pointermove", PointerEvent, 120, {}); send("pointerup", PointerEvent, 120, {});'
)


@needs_browser
@pytest.mark.parametrize("gesture", ["wheel", "drag"])
def test_wheel_zooms_and_drag_pans(
    day: tuple[Timeline, Path], tmp_path: Path, gesture: str
) -> None:
    _, page = day
    html = page.read_text(encoding="utf-8")
    code = INPUT % (WHEEL if gesture == "wheel" else DRAG)
    test_page = tmp_path / f"{gesture}.html"
    test_page.write_text(html.replace("</body>", code + "</body>"), encoding="utf-8")
    dom, stderr = dump(tmp_path, test_page.as_uri())
    no_script_errors(stderr)
    start0, end0, pointer_px, px_per_s0 = map(float, dom.body["data-before"].split(","))
    start, end = float(dom.svg["data-view-start"]), float(dom.svg["data-view-end"])
    left = float(dom.clip["x"])
    # the time under the pointer, before and after (pixels from the chart's left edge)
    t_before = start0 + (pointer_px - left) / px_per_s0
    px_per_s = float(dom.svg["data-px-per-s"])
    if gesture == "wheel":
        assert end - start < 0.9 * (end0 - start0)  # zoomed in
        t_after = start + (pointer_px - left) / px_per_s
        # zoomed around the pointer: the same time stays under it (1 ms on a 6 h view)
        assert t_after == pytest.approx(t_before, abs=1e-3)
    else:
        # dragged 120 px to the right: the view moved 120 px worth of time to the left
        assert end - start == pytest.approx(end0 - start0, rel=1e-9)
        assert start == pytest.approx(start0 - 120 / px_per_s0, abs=1e-3)
        assert dom.svg.get("class", "") == ""  # a drag is no click: nothing selected


@needs_browser
def test_selecting_a_log_links_its_gt_files(day: tuple[Timeline, Path], tmp_path: Path) -> None:
    tl, page = day
    readable = [b.path for b in tl.bags if b.readable]
    robot = readable.index("robots/FBM2H_201511201200_homer.bag")
    dom, stderr = dump(tmp_path, page.as_uri() + f"#bag={robot}")
    no_script_errors(stderr)
    by_class = {
        c: sorted(readable[int(b["data-i"])] for b in dom.bars if c in b["class"].split())
        for c in ("sel", "linked")
    }
    assert by_class["sel"] == ["robots/FBM2H_201511201200_homer.bag"]
    # the layout: the robot log (50-150 s) overlaps both split files around the GT gap
    assert by_class["linked"] == [
        "gt/log_fbm2h_mocap_2015-11-20-12-00-00_0.bag",
        "gt/log_fbm2h_mocap_2015-11-20-12-00-00_1.bag",
    ]
    assert dom.links == 2  # a dashed line to each
    assert "selecting" in dom.svg["class"]


@needs_browser
def test_sample_folder_page_in_the_browser(tmp_path: Path) -> None:
    root = Path(__file__).resolve().parents[2] / "sample_bags" / "timeline" / "bags"
    tl = scan([root])
    page = write_timeline_page(tl, tmp_path / "sample.html")
    dom, stderr = dump(tmp_path, page.as_uri() + "#session=1")
    no_script_errors(stderr)
    assert len(dom.bars) == 8  # the answers: 8 readable bags (the USB copy drawn hollow)
    assert sum("copy" in b.get("class", "") for b in dom.bars) == 1
    assert sum("problem" in b.get("class", "") for b in dom.bars) == 4  # + 1 unreadable
    start, end = float(dom.svg["data-view-start"]), float(dom.svg["data-view-end"])
    assert start <= 1448031600.0 and end >= 1448031634.0 and end - start < 40.0


REAL = Path(__file__).resolve().parents[2] / ".." / "shared" / "real_bags"


@needs_browser
@pytest.mark.real
@pytest.mark.skipif(not REAL.is_dir(), reason=f"real 2015 bags not found at {REAL}")
def test_real_and_simulated_logs_in_one_page(tmp_path: Path) -> None:
    """The issue's acceptance: real and simulated logs, every session and problem shown."""
    sample = Path(__file__).resolve().parents[2] / "sample_bags" / "timeline" / "bags"
    tl = scan([REAL, sample])
    page = write_timeline_page(tl, tmp_path / "mixed.html")
    # opened as it is: on the session with the most bags (session 2), not on a month
    dom, stderr = dump(tmp_path, page.as_uri())
    no_script_errors(stderr)
    start, end = float(dom.svg["data-view-start"]), float(dom.svg["data-view-end"])
    assert 1448031590.0 <= start <= 1448031600.0 and 1448031634.0 <= end <= 1448031640.0
    dom, stderr = dump(tmp_path, page.as_uri() + "#day")  # "fit day"
    no_script_errors(stderr)
    # the real GT bag (one session of its own, 2015-10-23) and the sample's 8 readable bags
    # in its 2 sessions (answers file)
    assert len(dom.bars) == 1 + 8
    assert len(dom.bands) == 3 == len(tl.sessions)
    labels = [t for t in dom.titles if t.startswith("session ")]
    assert labels[0] == "session 1, 14:15:40-14:16:37, 1 bag"
    assert labels[1:] == [
        "session 2, 15:00:00-15:00:34, 6 bags",
        "session 3, 15:00:40-15:00:46, 1 bag",
    ]
    tips = "\n".join(dom.titles)
    for b in tl.bags:
        if b.readable:
            for problem in b.problems:
                assert problem in tips, problem
    start, end = float(dom.svg["data-view-start"]), float(dom.svg["data-view-end"])
    assert start <= 1445609740.0 and end >= 1448031646.0  # fit day: October to November
    # a month across: tick labels are dates, not times, and none repeats
    dates = dom.ticks[:-1]
    assert dates and all(len(d) == 10 and d.startswith("2015-1") for d in dates)
    assert len(set(dates)) == len(dates)
