"""The results site in a real browser: headless Chromium opens index.html from disk, offline.

``--dump-dom`` gives the DOM as the browser built it (the leaderboards, problems, timeline
frame and links are read from it); a screenshot shows that the framed timeline page loaded and
its script drew the chart. Chromium's console lines (uncaught errors, refused loads) are
errors. Skipped, saying why, where Chromium is not installed (``apt-get install chromium``).
"""

from __future__ import annotations

import subprocess
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from matplotlib.image import imread

from ertools.competition.site import write_site
from ertools.report.timeline_page import write_timeline_page
from ertools.report.timeline_style import KIND_COLORS
from tests.helpers.fakes import BROWSER, CHROMIUM_FLAGS
from tests.helpers.timeline_day import day_timeline
from tests.rescore.site_results import (
    EVIL,
    Page,
    assert_links_resolve,
    expected_board,
    ranked_document,
    results,
    write_folder,
)

pytestmark = [
    pytest.mark.browser,
    pytest.mark.slow,
    pytest.mark.skipif(BROWSER is None, reason="chromium not installed (apt-get install chromium)"),
]

FLAGS = [
    *CHROMIUM_FLAGS,
    "--window-size=1400,3000",
    # No proxy can be reached: anything the page tried to fetch would fail.
    "--proxy-server=127.0.0.1:9",
    "--enable-logging=stderr",
    "--v=0",
]


def chromium(tmp_path: Path, url: str, *extra: str) -> subprocess.CompletedProcess[str]:
    profile = tmp_path / f"profile{len(list(tmp_path.glob('profile*')))}"
    proc = subprocess.run(
        [BROWSER or "chromium", *FLAGS, f"--user-data-dir={profile}", *extra, url],
        capture_output=True,
        text=True,
        timeout=90,
        check=False,
    )
    assert proc.returncode == 0, proc.stderr[-2000:]
    # Chromium logs uncaught exceptions and CSP refusals (of the page or its frame) as
    # console lines.
    bad = [
        line
        for line in proc.stderr.splitlines()
        if "CONSOLE" in line or "Refused" in line or "Uncaught" in line
    ]
    assert not bad, bad
    return proc


@pytest.fixture(scope="module")
def site(tmp_path_factory: pytest.TempPathFactory) -> tuple[dict[str, Any], Path]:
    out = tmp_path_factory.mktemp("site")
    doc = results()
    write_folder(out, doc)
    write_timeline_page(day_timeline(), out / "timeline.html")
    return doc, write_site(doc, out)


def test_dom_has_leaderboards_problems_and_timeline(
    site: tuple[dict[str, Any], Path], tmp_path: Path
) -> None:
    doc, index = site
    page = Page(chromium(tmp_path, index.as_uri(), "--dump-dom").stdout)
    for bench in ("fbm3w", "fbm1h", "fbm2h"):
        shown = page.board(f"lb-{bench}")
        assert shown == expected_board(doc, bench), bench
    # the two equal values are one tie group: "=2" on both rows
    assert [r[0] for r in page.boards["lb-fbm3w"]] == ["1", "=2", "=2", "4"]
    assert page.scripts == 0  # the hostile team name stayed text...
    assert EVIL in page.sections["lb-fbm3w"]  # ...shown as such
    for p in doc["problems"]:
        assert p["message"] in page.sections["problems"]
    assert page.frames == ["timeline.html"]
    assert page.executions.count("failed") == page.executions.count("unscoreable") == 1
    assert_links_resolve(page, index)


def test_timeline_frame_draws_its_chart(site: tuple[dict[str, Any], Path], tmp_path: Path) -> None:
    _, index = site
    shot = tmp_path / "shot.png"
    chromium(tmp_path, index.as_uri(), f"--screenshot={shot}", "--virtual-time-budget=5000")
    pixels = (imread(shot)[..., :3] * 255).round().astype(int)
    assert pixels.shape[:2] == (3000, 1400)

    def rows_of(colour: str) -> np.ndarray:
        rgb = np.array([int(colour[i : i + 2], 16) for i in (1, 3, 5)])
        return np.unique(np.nonzero(np.abs(pixels - rgb).max(axis=2) <= 3)[0])

    # The frame's page loaded: its dark header (#14233c) appears again below the site's own.
    header = rows_of("#14233c")
    assert header.min() == 0 and (header > 200).sum() > 20
    # Its script drew the chart: GT-logger bars (blue) in several lanes, not only the
    # legend's swatch (one line of ~10 px, which is static HTML).
    gt = rows_of(KIND_COLORS["gt"])
    assert gt.size and gt.max() - gt.min() > 40


def test_rank_stability_plot_is_drawn(tmp_path: Path) -> None:
    """With intervals: the browser builds the inline SVG plot (a dot per team, the tie band)
    and the tied rows; nothing is refused by the page's content policy."""
    out = tmp_path / "site"
    doc = ranked_document()
    write_folder(out, doc)
    index = write_site(doc, out)
    dom = chromium(tmp_path, index.as_uri(), "--dump-dom").stdout
    page = Page(dom)
    assert [r[0] for r in page.boards["lb-fbm3w"]] == ["=1", "=1", "3", "4"]
    svg = dom[dom.index("<svg") : dom.index("</svg>")]
    assert svg.count("<circle") == 4 and svg.count('class="tie"') == 1
