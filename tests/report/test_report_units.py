"""What a person reads on the report pages: one unit per kind of number, named in every
header, values converted from the SI units that score.json and the CSV files keep; a layout
that uses the window's width.

The reports are written by the CLI from the sample bags (generated with known ground truth,
``python -m ertools.samples``); the expected page values are computed here from score.json.
"""

from __future__ import annotations

import csv
import json
import math
import re
from datetime import UTC, datetime
from html.parser import HTMLParser
from pathlib import Path

import pytest
import yaml

from ertools.cli.main import main
from ertools.competition import site_text
from ertools.report.folder import write_report
from ertools.views import units
from tests.helpers.report_fakes import fbm3w_like
from tests.helpers.yaml_rounding import YAML_ROUNDING

pytestmark = pytest.mark.slow

ROOT = Path(__file__).resolve().parents[2]
S = ROOT / "sample_bags"
COMMANDS = {
    "fbm2h": [
        "score", "fbm2h", str(S / "fbm2h/log_fbm2h_mocap_2015-11-20-12-00-00_0.bag"),
        "--goal", str(S / "fbm2h/fbm2h_goal.yaml"),
        "--transform", str(S / "fbm2h/transform-simbot.yaml"),
    ],
    "fbm3w": ["score", "fbm3w", str(S / "fbm3w/log_fbm3w_mocap_2015-11-20-12-00-00_0.bag")],
    "fbm1h": [
        "score", "fbm1h", str(S / "fbm1h/log_fbm1h_2015-11-20-12-00-00_0.bag"),
        "--items", str(S / "fbm1h/fbm1h.yaml"),
    ],
}  # fmt: skip
UNIT = re.compile(r"\((mm|deg|s|bytes)\)$")
# Numbers that have no unit: indices, counts, ratios and scores (seed 7.x).
UNITLESS = {
    "run", "segment", "best_run", "hits", "timeout_segments", "messages", "samples",
    "kept_samples", "tracking_losses", "gt_samples", "states", "class_accuracy",
    "instance_accuracy", "pose_score", "warnings", "failures", "audit findings", "item_id",
    "i", "sample", "l_norm", "count", "pairs", "lost", "transitions", "refbox_timeout",
    "timeout", "id", "compared", "gaps", "valid_fraction", "path_coverage",
    "share", "confidence", "draws", "seed",  # the uncertainty table: fractions and counts
    "share_mocap_noise", "share_transform", "share_time_association",
}  # fmt: skip


class _Page(HTMLParser):
    """Tables (caption, headers, rows of cell texts) and the style sheet of a page."""

    def __init__(self) -> None:
        super().__init__()
        self.tables: list[dict[str, list]] = []
        self.style = ""
        self._in: str | None = None

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        if tag == "table":
            self.tables.append({"caption": [""], "headers": [], "rows": []})
        elif tag == "tr" and self.tables:
            self.tables[-1]["rows"].append([])
        elif tag in ("th", "td", "caption", "style"):
            self._in = tag
            if tag == "th":
                self.tables[-1]["headers"].append("")
            elif tag == "td":
                self.tables[-1]["rows"][-1].append("")

    def handle_endtag(self, tag: str) -> None:
        if tag in ("th", "td", "caption", "style"):
            self._in = None

    def handle_data(self, data: str) -> None:
        if self._in == "style":
            self.style += data
        elif self._in == "th":
            self.tables[-1]["headers"][-1] += data
        elif self._in == "td":
            self.tables[-1]["rows"][-1][-1] += data
        elif self._in == "caption":
            self.tables[-1]["caption"][0] += data


@pytest.fixture(scope="module")
def reports(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    out = tmp_path_factory.mktemp("units")
    folders = {}
    for name, argv in COMMANDS.items():
        assert main([*argv, "--report", str(out / name)]) == 0
        folders[name] = out / name
    return folders


def _page(folder: Path) -> _Page:
    page = _Page()
    page.feed((folder / "index.html").read_text(encoding="utf-8"))
    return page


def _number(text: str) -> float | None:
    try:
        return float(text)
    except ValueError:
        return None


def _column(table: dict[str, list], header: str) -> list[str]:
    i = table["headers"].index(header)
    return [r[i] for r in table["rows"] if r]


def _table(page: _Page, *headers: str) -> dict[str, list]:
    return next(t for t in page.tables if set(headers) <= set(t["headers"]))


def _metric(page: _Page, name: str) -> float:
    table = _table(page, "metric", "value")
    value = dict((r[0], r[1]) for r in table["rows"] if r)[name]
    return float(value)


def _close(shown: float, expected: float, decimals: int = 2) -> bool:
    # The page prints lengths and angles (mm, deg) to 2 decimals and times (s) to 3: what the
    # data resolves (0.01 mm, 0.01 deg, 1 ms). Rounding moves a value by half the last digit.
    return abs(shown - expected) <= 0.5 * 10.0**-decimals * (1 + 1e-9)


@pytest.mark.parametrize("name", sorted(COMMANDS))
def test_every_numeric_column_names_its_unit(reports: dict[str, Path], name: str) -> None:
    page = _page(reports[name])
    assert len(page.tables) >= 3
    checked = 0
    for table in page.tables:
        headers = table["headers"]
        rows = [r for r in table["rows"] if len(r) == len(headers)]
        if headers in (["metric", "value"], ["key", "live", "recomputed", "difference",
                                             "status", "explanation"]):  # fmt: skip
            # Mixed columns: the unit is in each row's name (a score key).
            for row in rows:
                if any(_number(c) is not None for c in row[1:4]) and row[0] != "\u2014":
                    key = row[0].rsplit(".", 1)[-1]
                    assert UNIT.search(row[0]) or key in UNITLESS or key.isdigit(), row
                    checked += 1
            continue
        for i, header in enumerate(headers):
            cells = [r[i] for r in rows if r[i] != "\u2014"]
            if cells and all(_number(c) is not None for c in cells):
                # an interval's bound has its score's unit (or none, as pose_score)
                bare = re.sub(r"_(low|high)$", "", header)
                assert UNIT.search(header) or bare in UNITLESS, (table["caption"], header)
                checked += 1
    assert checked >= 8


def test_fbm2h_lengths_in_mm_and_angles_in_degrees(reports: dict[str, Path]) -> None:
    folder = reports["fbm2h"]
    page = _page(folder)
    score = json.loads((folder / "score.json").read_text())
    # Headline: metres and radians in score.json, mm and degrees on the page.
    assert _close(_metric(page, "position_accuracy (mm)"), score["position_accuracy"] * 1000.0)
    assert _close(
        _metric(page, "orientation_accuracy (deg)"),
        score["orientation_accuracy"] * 180.0 / math.pi,
    )
    assert _close(_metric(page, "execution_time (s)"), score["execution_time"], 3)
    segments = _table(page, "segment", "distance_error (mm)")
    details = score["details"]["segments_details"]
    shown = [float(v) for v in _column(segments, "distance_error (mm)")]
    # "dinstance_error": the seed's spelling (Listing 13).
    expected = [details[str(i)]["dinstance_error"] * 1000.0 for i in range(len(details))]
    assert len(shown) == len(expected) == 5
    assert all(_close(a, b) for a, b in zip(shown, expected, strict=True))
    angles = [float(v) for v in _column(segments, "orientation_error (deg)")]
    expected = [math.degrees(details[str(i)]["orientation_error"]) for i in range(5)]
    assert all(_close(a, b) for a, b in zip(angles, expected, strict=True))
    # A millimetre-scale error reads as one: the sample's first waypoint is ~49 mm off.
    assert 40.0 < shown[0] < 60.0
    # The files keep the seed's units: the CSV column in metres equals score.json.
    with (folder / "segments.csv").open(newline="") as fh:
        csv_rows = list(csv.DictReader(fh))
    assert float(csv_rows[0]["distance_error_m"]) == pytest.approx(
        details["0"]["dinstance_error"], rel=1e-12
    )
    seed = yaml.safe_load((folder / "score.yaml").read_text())
    # metres; the YAML value is the JSON one written to 9 decimals (tests/helpers/yaml_rounding.py)
    assert abs(seed["position_accuracy"] - score["position_accuracy"]) <= YAML_ROUNDING
    assert seed["position_accuracy"] < 1.0


def test_fbm3w_distance_errors_in_mm(reports: dict[str, Path]) -> None:
    folder = reports["fbm3w"]
    page = _page(folder)
    score = json.loads((folder / "score.json").read_text())
    assert _close(_metric(page, "best_distance_error (mm)"), score["best_distance_error"] * 1000.0)
    runs = _table(page, "run", "distance_error (mm)")
    scored = 0
    for run, value in zip(_column(runs, "run"), _column(runs, "distance_error (mm)"), strict=True):
        metres = score["runs_details"][run]["distance_error"]
        if value == "\u2014":  # a run with no score (timed out)
            assert metres is None
            continue
        assert _close(float(value), metres * 1000.0)
        scored += 1
    assert scored >= 3
    assert "d_min (mm)" in runs["headers"] and "path_length (mm)" in runs["headers"]


def test_fbm1_errors_in_mm_whatever_the_stored_unit(reports: dict[str, Path]) -> None:
    # FBM1's rows mix trans_error_m (m), gt_spread_mm (mm) and theta_deg (deg).
    folder = reports["fbm1h"]
    page = _page(folder)
    score = json.loads((folder / "score.json").read_text())
    runs = _table(page, "run", "trans_error (mm)", "gt_spread (mm)", "theta_error (deg)")
    compared = 0
    for run, trans, spread, theta in zip(
        _column(runs, "run"),
        _column(runs, "trans_error (mm)"),
        _column(runs, "gt_spread (mm)"),
        _column(runs, "theta_error (deg)"),
        strict=True,
    ):
        detail = score["runs"].get(run)
        if detail is None or "error" not in detail or trans == "\u2014":
            continue
        assert _close(float(trans), detail["error"]["translation"] * 1000.0)
        assert _close(float(spread), detail["ground_truth"]["spread_m"] * 1000.0)
        assert _close(float(theta), detail["error"]["theta"])  # stored in degrees
        compared += 1
    assert compared >= 5


@pytest.mark.parametrize("name", sorted(COMMANDS))
def test_layout_is_fluid(reports: dict[str, Path], name: str) -> None:
    style = re.sub(r"/\*.*?\*/", "", _page(reports[name]).style, flags=re.S)
    rules = dict((sel.strip(), body) for sel, body in re.findall(r"([^{}]+)\{([^}]*)\}", style))
    assert "max-width" not in rules["main"] and "width: 100%" in rules["main"]
    assert "max-width" not in rules.get("body", "")
    assert "max-width" not in rules[".figs"]
    assert "width: 100%" in rules["figure img"]
    assert "overflow-x: auto" in rules[".wrap"]  # wide tables scroll in their box


def test_instants_read_as_utc(tmp_path: Path) -> None:
    index = write_report(fbm3w_like(), tmp_path / "r", inputs=[], argv=[])
    page = _page(index.parent)
    runs = _table(page, "run", "start_time (UTC)")
    # fbm3w_like's start times: 1.4e9 s and 1.4e9 + 30.5 s after the epoch.
    expected = [
        datetime.fromtimestamp(t, tz=UTC).strftime("%Y-%m-%dT%H:%M:%S.%fZ")
        for t in (1.4e9, 1.4e9 + 30.5)
    ]
    assert (
        _column(runs, "start_time (UTC)")
        == expected
        == [
            "2014-05-13T16:53:20.000000Z",
            "2014-05-13T16:53:50.500000Z",
        ]
    )
    with (index.parent / "runs.csv").open(newline="") as fh:  # the CSV keeps epoch seconds
        assert [float(r["start_time"]) for r in csv.DictReader(fh)] == [1.4e9, 1.4e9 + 30.5]


def test_rsbb_keys_state_their_unit() -> None:
    """The RSBB scripts' keys carry their unit in brackets (HNF's ``position_accuracy[m]``,
    HGMF's ``segment_time [s]``): shown in the page's units, the bracket dropped."""
    assert site_text.with_unit("position_accuracy[m]", 0.05) == "50.00 mm"
    assert site_text.with_unit("orientation_accuracy[rad]", math.pi / 4) == "45.00 deg"
    assert site_text.with_unit("goal_1.segment_time [s]", 3.0) == "3.000 s"
    assert units.without_unit("goal_1.segment_time [s]") == "goal_1.segment_time"
    assert units.without_unit("Objects grasped") == "Objects grasped"
    # HNF's live robot_pose, a PyYAML dump of a Pose2D: x, y in mm, theta in degrees
    dump = "!!python/object/new:geometry_msgs.msg._Pose2D.Pose2D\nstate: [1.5, -0.25, 0.5]"
    assert site_text.shown("segment_1.robot_pose", dump) == (
        f"x 1500.00 mm, y -250.00 mm, theta {math.degrees(0.5):.2f} deg"
    )
