"""Inputs that must never become output (issue 25, items 5 and 7): a manifest naming
`../../../../etc/passwd`, a symlink `x.bag` to a secret, a folder named `javascript:...`. The
bytes of a file that is no bag are never quoted anywhere: messages say which format was
expected."""

from __future__ import annotations

import json
import re
from pathlib import Path
from urllib.parse import unquote

import pytest

from ertools.cli.main import main
from ertools.competition.site import write_site
from tests.helpers.stderr_text import joined_lines

ROOT = Path(__file__).resolve().parents[2]
FBM3W_BAG = ROOT / "sample_bags" / "fbm3w" / "log_fbm3w_mocap_2015-11-20-12-00-00_0.bag"
SECRET = "root:x:0:0:SECRET-4711:/root:/bin/bash\n"


def secret_file(tmp_path: Path) -> Path:
    path = tmp_path / "elsewhere" / "passwd"
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(SECRET)
    return path


def manifest(folder: Path, bags: str) -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / "competition.yaml"
    path.write_text(
        f"version: 1\nexecutions:\n  - {{benchmark: fbm3w, team: robotto, bags: [{bags}]}}\n"
    )
    return path


def test_check_refuses_a_path_out_of_the_manifest_folder(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    secret_file(tmp_path)
    config = manifest(tmp_path / "comp", "../elsewhere/passwd")
    assert main(["rescore", "--config", str(config), "--check"]) == 1
    err = capsys.readouterr().err
    assert "executions[0].bags: ../elsewhere/passwd leads out of the manifest's folder" in err
    assert "SECRET" not in err and "root:x" not in err


def test_check_verifies_every_listed_bag_is_a_bag(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    secret = secret_file(tmp_path)
    config = manifest(tmp_path / "comp", str(secret))  # absolute: allowed, but no bag
    assert main(["rescore", "--config", str(config), "--check"]) == 1
    err = capsys.readouterr().err
    assert "not a ROS1 bag, rosbag2 bag or MCAP file: it does not begin with" in err
    assert "SECRET" not in err and "root:x" not in err
    # and the real bag beside it passes
    good = manifest(tmp_path / "good", str(FBM3W_BAG))
    assert main(["rescore", "--config", str(good), "--check"]) == 0


@pytest.mark.slow
def test_a_symlinked_non_bag_leaks_nothing_into_any_output(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    secret = secret_file(tmp_path)
    logs = tmp_path / "logs"
    logs.mkdir()
    (logs / "x.bag").symlink_to(secret)
    (logs / "log_fbm3w.bag").symlink_to(FBM3W_BAG)
    config = tmp_path / "competition.yaml"
    config.write_text("version: 1\ntitle: Leak Cup\n")
    out = tmp_path / "out"
    main(["rescore", str(logs), "--config", str(config), "--out", str(out), "-j", "1"])
    err = capsys.readouterr().err
    assert "SECRET" not in err and "root:x" not in err
    written = [p for p in out.rglob("*") if p.is_file()]
    assert any(p.name == "results.json" for p in written)
    for path in written:
        data = path.read_bytes()
        assert b"SECRET" not in data and b"root:x" not in data, path
    doc = json.loads((out / "results.json").read_text())
    said = json.dumps(doc["problems"])
    assert "x.bag" in said and "not a ROS1 bag, rosbag2 bag or MCAP file" in said


def test_info_says_which_format_was_expected(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = tmp_path / "x.bag"
    path.write_text(SECRET)
    assert main(["info", str(path)]) == 1
    err = " ".join(joined_lines(capsys.readouterr().err))
    assert err.strip() == (
        f"ertools: error: {path}: not a ROS1 bag, rosbag2 bag or MCAP file: it does not "
        "begin with '#ROSBAG V2.0' (ROS1) or MCAP's magic bytes; a text file (if it is a "
        "TUM, KITTI or EuRoC trajectory, `score trajectory` and `export` read it)"
    )


FBM2H = ROOT / "sample_bags" / "fbm2h"
HREF = re.compile(r'(?:href|src)="([^"]*)"')


def assert_relative_links(page: str) -> list[str]:
    links = HREF.findall(page)
    for link in links:
        assert not re.match(r"[A-Za-z][A-Za-z0-9+.-]*:", link), link  # no scheme at all
        assert not link.startswith(("/", "\\\\")), link
    return links


@pytest.mark.slow
def test_report_links_a_folder_named_like_a_url_as_a_relative_path(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    folder = tmp_path / "javascript:alert(document.domain)"
    score = [
        "score",
        "fbm2h",
        str(FBM2H / "log_fbm2h_mocap_2015-11-20-12-00-00_0.bag"),
        "--transform",
        str(FBM2H / "transform-simbot.yaml"),
        "--goal",
        str(FBM2H / "fbm2h_goal.yaml"),
    ]
    assert main([*score, "--report", str(folder)]) == 0
    out = tmp_path  # the page beside the folder: its relative path begins with the name
    assert main(["report", str(folder / "result.json"), "--report", str(out)]) == 0
    page = (out / "index.html").read_text()
    links = assert_relative_links(page)
    expected = "javascript%3Aalert%28document.domain%29/index.html"
    assert expected in links
    # the encoded link still opens the report: the browser decodes it to the folder's name
    assert (out / unquote(expected)).resolve() == (folder / "index.html").resolve()
    capsys.readouterr()


def test_the_results_page_links_only_relative_paths(tmp_path: Path) -> None:
    out = tmp_path / "out"
    evil = out / "javascript:alert(1)"
    evil.mkdir(parents=True)
    (evil / "index.html").write_text("report")
    doc = {
        "schema_version": 1,
        "executions": [
            {
                "id": "e1",
                "benchmark": "fbm3w",
                "team": "t",
                "status": "scored",
                "report": "javascript:alert(1)/index.html",
                "rank_value": 1.0,
            },
            {
                "id": "e2",
                "benchmark": "fbm3w",
                "team": "u",
                "status": "scored",
                "report": "/etc/passwd",
                "rank_value": 2.0,
            },
        ],
        "leaderboards": [],
        "timeline": {"figure": "javascript:alert(1)/index.html"},
    }
    page = write_site(doc, out).read_text()
    links = assert_relative_links(page)
    assert "javascript%3Aalert%281%29/index.html" in links
    assert not any("passwd" in link for link in links)


def test_a_rosbag2_metadata_that_is_no_yaml_is_not_quoted(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """PyYAML's own message quotes the offending line: ertools says where, not what."""
    folder = tmp_path / "bag2"
    folder.mkdir()
    (folder / "metadata.yaml").write_text("key: [unclosed\n\tSECRET-4711: x\n")
    assert main(["info", str(folder)]) == 1
    err = capsys.readouterr().err
    assert "SECRET" not in err
    assert "metadata.yaml" in err and "at line" in err


def test_check_accepts_text_trajectories_only_where_a_benchmark_reads_them(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    folder = tmp_path / "comp"
    folder.mkdir()
    # Two TUM trajectories (t x y z qx qy qz qw), the format `score trajectory` reads.
    rows = "".join(f"{1.0 + i / 10:.1f} {i / 100:.2f} 0 0 0 0 0 1\n" for i in range(5))
    (folder / "robot.txt").write_text(rows)
    (folder / "gt.txt").write_text(rows)
    config = folder / "competition.yaml"
    config.write_text(
        "version: 1\nexecutions:\n"
        "  - {benchmark: trajectory, team: robotto, bags: [robot.txt, gt.txt]}\n"
    )
    assert main(["rescore", "--config", str(config), "--check"]) == 0, capsys.readouterr().err
    # FBM3W reads bags only: the same text file is refused, by the format expected.
    config.write_text(
        "version: 1\nexecutions:\n  - {benchmark: fbm3w, team: robotto, bags: [robot.txt]}\n"
    )
    assert main(["rescore", "--config", str(config), "--check"]) == 1
    assert "not a ROS1 bag, rosbag2 bag or MCAP file" in capsys.readouterr().err
