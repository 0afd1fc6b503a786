"""Report folders: files, hashes, CSV round trips and escaping of hostile bag content."""

from __future__ import annotations

import csv
import hashlib
import json
from html.parser import HTMLParser
from pathlib import Path

import pytest
import yaml

from ertools.auditing.analyse import audit_states
from ertools.errors import ConfigError
from ertools.report.folder import write_report
from ertools.report.records import sha256_file
from ertools.states import Machine
from tests.helpers import svg_figure
from tests.helpers.audit_streams import BMBOX, CLIENT, REFBOX, heartbeat, write_bag
from tests.helpers.report_fakes import EVIL, fbm3w_like

BAG_BYTES = b"#ROSBAG V2.0\n" + bytes(range(256)) * 50


@pytest.fixture
def bag(tmp_path: Path) -> Path:
    path = tmp_path / "in" / "run.bag"
    path.parent.mkdir()
    path.write_bytes(BAG_BYTES)
    return path


def test_folder_contents(bag: Path, tmp_path: Path) -> None:
    config = tmp_path / "in" / "fbm3w.yaml"
    config.write_text(f"runs_specifications: ['line']  # {EVIL}\n", encoding="utf-8")
    result = fbm3w_like()
    out = tmp_path / "report"
    output = tmp_path / "in" / "score-out.yaml"  # written by ertools before the report
    output.write_text("best_run: 1\n", encoding="utf-8")
    argv = ["ertools", "score", "fbm3w", str(bag), "--config", str(config), "--team", "b<it>"]
    argv += ["-o", str(output), f"--plot={output}"]
    index = write_report(result, out, inputs=[bag], argv=argv)
    assert index == out / "index.html"
    names = {p.name for p in out.iterdir()}
    assert {"index.html", "score.yaml", "score.json", "result.json", "runs.csv"} <= names

    assert yaml.safe_load((out / "score.yaml").read_text()) == result.data
    assert json.loads((out / "score.json").read_text()) == result.data
    with (out / "runs.csv").open(newline="") as fh:
        rows = list(csv.DictReader(fh))
    assert [r["spec"] for r in rows] == [EVIL, "spline"]  # CSV keeps the data as it is
    assert float(rows[1]["distance_error"]) == pytest.approx(0.0123, abs=1e-15)

    meta = json.loads((out / "result.json").read_text())
    expected_sha = hashlib.sha256(BAG_BYTES).hexdigest()  # the known bytes, hashed here
    assert meta["inputs"] == [
        {"name": "run.bag", "path": str(bag), "sha256": expected_sha, "size": len(BAG_BYTES)}
    ]
    assert [c["name"] for c in meta["configs"]] == ["fbm3w.yaml"]  # not the -o output
    assert meta["configs"][0]["sha256"] == hashlib.sha256(config.read_bytes()).hexdigest()
    assert meta["team"] == "b<it>"
    assert meta["benchmark"] == "fbm3w"
    assert meta["headline"] == {
        "best_distance_error": 0.0123,
        "best_run": 1,
        "execution_time": 41.5,
    }

    page = index.read_text(encoding="utf-8")
    assert expected_sha in page
    assert "d_min" in page and "0.00033 m" in page  # every parameter
    assert "ertools estimates the noise" in page  # every deviation
    assert "0.1.0" in page  # the version


class _Tags(HTMLParser):
    def __init__(self) -> None:
        super().__init__()
        self.names: list[str] = []
        self.attrs: list[str] = []
        self.img_src: list[str] = []
        self.text = ""

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        self.names.append(tag)
        self.attrs += [k for k, _ in attrs]
        if tag == "img":
            self.img_src.append(dict(attrs).get("src") or "")

    def handle_data(self, data: str) -> None:
        self.text += data


def test_hostile_content_is_escaped(bag: Path, tmp_path: Path) -> None:
    config = tmp_path / "in" / "c.yaml"
    config.write_text(EVIL, encoding="utf-8")
    index = write_report(fbm3w_like(), tmp_path / "r", inputs=[bag], argv=["ertools", str(config)])
    page = index.read_text(encoding="utf-8").lower()
    # No element from the data: no script at all, no injected img, no event handler.
    assert "<script" not in page
    # The quotes are escaped (Jinja2/markupsafe spell them &#34; and &#39;), so the
    # attribute text stays inside the element's text.
    assert "onerror=" not in page.replace("onerror=&#34;", "")
    assert "<img src=x" not in page
    assert "&lt;script&gt;alert(&#39;x&#39;)&lt;/script&gt;" in page
    assert page.count("&lt;script&gt;") >= 4  # table cell, warning, deviation, config text
    # The same as a browser's parser sees it: no script element, no event handler
    # attribute, every image a figure of the report; the payloads are text.
    tags = _Tags()
    tags.feed(index.read_text(encoding="utf-8"))
    assert "script" not in tags.names
    assert not [a for a in tags.attrs if a.startswith("on")]
    assert all(src.startswith("figures/") for src in tags.img_src)
    assert tags.text.count(EVIL) >= 4


def test_sha256_of_a_rosbag2_directory(tmp_path: Path) -> None:
    d = tmp_path / "bag2"
    d.mkdir()
    (d / "metadata.yaml").write_bytes(b"a")
    (d / "bag2_0.mcap").write_bytes(b"bc")
    lines = (
        f"bag2_0.mcap {hashlib.sha256(b'bc').hexdigest()}\n"
        f"metadata.yaml {hashlib.sha256(b'a').hexdigest()}\n"
    )
    assert sha256_file(d) == hashlib.sha256(lines.encode()).hexdigest()


@pytest.mark.slow
def test_audit_report_has_timeline_figure(tmp_path: Path) -> None:
    audit = audit_states(
        heartbeat(Machine.BMBOX, BMBOX, 20.0, drop=(5.0, 7.0)),
        heartbeat(Machine.REFBOX, REFBOX, 20.0),
        heartbeat(Machine.CLIENT, CLIENT, 20.0),
        benchmark="fbm2h",
    )
    out = tmp_path / "audit"
    index = write_report(audit, out, inputs=[], argv=[])  # type: ignore[arg-type]
    figure = svg_figure.read(out / "figures" / "audit_timeline.svg")
    # The 2 s heartbeat silence, hatched on the BmBox lane, as long as the audit says.
    (silence,) = figure.series("silence").findall("s:g/s:rect", svg_figure.NS)
    ax, _ = figure.scale("x")
    assert ax * float(silence.get("width", "nan")) == pytest.approx(2.0, abs=abs(ax) * 0.2)
    assert figure.texts("xlabel") == ["time from the first state message (s)"]
    assert not (out / "score.yaml").exists()  # an audit with no re-score has no score
    assert yaml.safe_load((out / "audit.yaml").read_text())["runs"]["1"]["outcome"] == "timeout"
    with (out / "audit_silences.csv").open(newline="") as fh:
        (row,) = list(csv.DictReader(fh))
    assert float(row["duration"]) == pytest.approx(2.0, abs=1e-12)
    page = index.read_text(encoding="utf-8")
    assert 'src="figures/audit_timeline.svg"' in page
    assert "EXECUTING_GOAL" in page and "TRANSMITTING_GOAL" in page


@pytest.mark.slow
def test_report_of_score_bag_includes_its_audit(tmp_path: Path) -> None:
    """A score report whose bag has the state topics audits them by itself."""

    bag = write_bag(
        tmp_path / "fbm3w.bag",
        [heartbeat(Machine.BMBOX, BMBOX, 20.0, topic="/fbm3w/bmbox_state")],
    )
    out = tmp_path / "r"
    write_report(fbm3w_like(), out, inputs=[bag], argv=[])
    meta = json.loads((out / "result.json").read_text())
    assert meta["audit"]["illegal_transitions"] == 1 and meta["audit"]["runs"] == 2
    assert (out / "figures" / "audit_timeline.svg").exists()


def test_report_dir_that_is_a_file(tmp_path: Path) -> None:
    target = tmp_path / "taken"
    target.write_text("not a folder")
    with pytest.raises(ConfigError, match="cannot write the report folder"):
        write_report(fbm3w_like(), target, inputs=[], argv=[])
    assert target.read_text() == "not a folder"
