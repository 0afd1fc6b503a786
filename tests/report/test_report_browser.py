"""The report page in a real browser: headless Chromium opens index.html from disk.

Skipped, saying why, where Chromium is not installed (Debian: ``apt-get install chromium``).
"""

from __future__ import annotations

import base64
import re
import shutil
import subprocess
import xml.etree.ElementTree as ET
from html.parser import HTMLParser
from pathlib import Path

import numpy as np
import pytest
from matplotlib.image import imread

from ertools.auditing.analyse import audit_states
from ertools.auditing.compare import attach
from ertools.report.folder import write_report
from ertools.states import Machine
from tests.helpers.audit_streams import BMBOX, CLIENT, REFBOX, heartbeat
from tests.helpers.fakes import BROWSER, CHROMIUM_FLAGS
from tests.helpers.report_fakes import EVIL, fbm3w_like

pytestmark = [pytest.mark.browser, pytest.mark.slow]

FLAGS = list(CHROMIUM_FLAGS)
# EXECUTING_GOAL in the timeline figure (ertools.report.plots_audit: Okabe-Ito's bluish
# green, #009E73): its presence in the screenshot proves the SVG beside the page was loaded
# and painted.
EXECUTING_GOAL_RGB = (0x00, 0x9E, 0x73)


class _Dom(HTMLParser):
    def __init__(self) -> None:
        super().__init__()
        self.imgs: list[str] = []
        self.tables = 0
        self.cells: list[str] = []
        self.scripts = 0
        self._in_cell = False

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        if tag == "img":
            self.imgs.append(dict(attrs).get("src") or "")
        elif tag == "table":
            self.tables += 1
        elif tag == "script":
            self.scripts += 1
        elif tag in ("td", "th"):
            self._in_cell = True
            self.cells.append("")

    def handle_endtag(self, tag: str) -> None:
        if tag in ("td", "th"):
            self._in_cell = False

    def handle_data(self, data: str) -> None:
        if self._in_cell:
            self.cells[-1] += data


def _chromium(tmp_path: Path, url: str, *extra: str) -> subprocess.CompletedProcess[str]:
    profile = tmp_path / f"profile{len(list(tmp_path.glob('profile*')))}"
    return subprocess.run(
        [BROWSER or "chromium", *FLAGS, f"--user-data-dir={profile}", *extra, url],
        capture_output=True,
        text=True,
        timeout=90,
        check=False,
    )


@pytest.fixture(scope="module")
def report(tmp_path_factory: pytest.TempPathFactory) -> Path:
    tmp = tmp_path_factory.mktemp("browser")
    audit = audit_states(
        heartbeat(Machine.BMBOX, BMBOX, 20.0, drop=(5.0, 7.0)),
        heartbeat(Machine.REFBOX, REFBOX, 20.0),
        heartbeat(Machine.CLIENT, CLIENT, 20.0),
        benchmark="fbm3w",
    )
    audit = attach(audit, fbm3w_like())
    return write_report(audit, tmp / "report", inputs=[], argv=["ertools", "audit"])  # type: ignore[arg-type]


@pytest.mark.skipif(BROWSER is None, reason="chromium not installed (apt-get install chromium)")
def test_dom_has_tables_and_images(report: Path, tmp_path: Path) -> None:
    proc = _chromium(tmp_path, report.as_uri(), "--dump-dom")
    assert proc.returncode == 0, proc.stderr[-2000:]
    dom = _Dom()
    dom.feed(proc.stdout)
    assert dom.scripts == 0  # the hostile payloads stayed text
    assert EVIL in dom.cells  # ...shown as text in the runs table
    assert dom.tables >= 5  # score, runs, comparison, audit tables, timeline
    # The page shows lengths in mm: 0.0123 m (fbm3w_like) is 12.3 mm, with its unit.
    # To 0.01 mm, the resolution mocap data has (docs/reports.md).
    assert "best_distance_error (mm)" in dom.cells and "12.30" in dom.cells
    assert dom.imgs, "no figure in the page"
    for src in dom.imgs:
        if src.startswith("data:"):
            assert base64.b64decode(src.split(",", 1)[1])[:8] == b"\x89PNG\r\n\x1a\n"
        elif src.endswith(".svg"):  # the reports' vector figures (issue 29)
            root = ET.fromstring((report.parent / src).read_text(encoding="utf-8"))
            assert root.tag == "{http://www.w3.org/2000/svg}svg", src
        else:
            assert (report.parent / src).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n", src
    assert "figures/audit_timeline.svg" in dom.imgs


@pytest.mark.skipif(BROWSER is None, reason="chromium not installed (apt-get install chromium)")
def test_screenshot_shows_the_page_and_its_figure(report: Path, tmp_path: Path) -> None:
    shot = tmp_path / "shot.png"
    proc = _chromium(tmp_path, report.as_uri(), f"--screenshot={shot}", "--window-size=1280,2400")
    assert proc.returncode == 0 and shot.exists(), proc.stderr[-2000:]
    pixels = (imread(shot)[..., :3] * 255).round().astype(int)
    assert pixels.shape[:2] == (2400, 1280)
    # Not blank: the dark header, white body and many colours of the tables and figure.
    packed = (pixels[..., 0] << 16) | (pixels[..., 1] << 8) | pixels[..., 2]
    assert np.unique(packed).size > 200
    header = pixels[:40, :, :].mean(axis=(0, 1))
    assert header.max() < 80  # #14233c
    close = np.abs(pixels - np.array(EXECUTING_GOAL_RGB)).max(axis=2) <= 3
    assert close.sum() > 500, "the timeline figure was not painted"


# Measures the laid-out page: the widest figure or table, and the document's width (a page
# wider than the window would scroll sideways). The report itself has no script (its CSP
# forbids them); this copy of it, in the test's folder, gets one.
_MEASURE = """<script>
const widths = [...document.querySelectorAll("main img, main table")]
  .map(e => e.getBoundingClientRect().width);
document.body.setAttribute("data-widest", String(Math.max(0, ...widths)));
document.body.setAttribute("data-page", String(document.documentElement.scrollWidth));
document.body.setAttribute("data-window", String(window.innerWidth));
</script>"""


class _Body(HTMLParser):
    def __init__(self) -> None:
        super().__init__()
        self.attrs: dict[str, str | None] = {}

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        if tag == "body":
            self.attrs = dict(attrs)


@pytest.mark.skipif(BROWSER is None, reason="chromium not installed (apt-get install chromium)")
def test_report_uses_the_window_width(report: Path, tmp_path: Path) -> None:
    copy = tmp_path / "copy"
    shutil.copytree(report.parent, copy)
    page = (copy / "index.html").read_text(encoding="utf-8")
    page, n = re.subn(r'<meta http-equiv="Content-Security-Policy"[^>]*>', "", page)
    assert n == 1
    (copy / "index.html").write_text(page.replace("</body>", _MEASURE + "</body>"), "utf-8")
    proc = _chromium(
        tmp_path,
        (copy / "index.html").as_uri(),
        "--dump-dom",
        "--window-size=1600,1000",
        "--virtual-time-budget=5000",
    )
    assert proc.returncode == 0, proc.stderr[-2000:]
    body = _Body()
    body.feed(proc.stdout)
    window = float(body.attrs["data-window"] or 0)
    assert window == 1600
    # The timeline figure spans the main column: all but its 2 x 32 px padding.
    assert float(body.attrs["data-widest"] or 0) > 1200
    assert float(body.attrs["data-page"] or 0) <= window  # no sideways scrolling
