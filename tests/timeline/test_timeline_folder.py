"""`ertools timeline` on the generated folder vs its answers, output formats, bad input."""

from __future__ import annotations

import csv
import io
import json
import random
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import ertools.timelines.scan as ts
from ertools.cli.main import main
from ertools.geometry import quat_from_yaw
from ertools.io.clock import ClockCheck
from ertools.io.formats import find_bags
from ertools.progress import reporting
from ertools.simulator.writer import BagWriter
from ertools.timelines.scan import scan
from tests.helpers.summaries import BAG_KEYS


def rel(root: Path, path: str) -> str:
    return str(Path(path).relative_to(root))


@pytest.mark.slow
def test_scan_matches_the_answers(folder: dict[str, Any]) -> None:
    root, ans = folder["root"], folder["answers"]
    tl = scan([root])
    exp, truth = ans["expected"], ans["truth"]
    tol = ans["tolerance"]["times"]["abs"]
    readable = {rel(root, b.path): b for b in tl.bags if b.readable}
    assert tl.readable_count == exp["readable"] == len(readable)
    copies = {rel(root, b.path): rel(root, b.copy_of) for b in tl.bags if b.copy_of}
    assert copies == exp["copies"]
    for name, b in readable.items():
        t = truth["bags"][name]
        assert b.start_ns / 1e9 == pytest.approx(t["start"], abs=tol), name
        assert b.end_ns / 1e9 == pytest.approx(t["end"], abs=tol), name
        assert b.kind == t["kind"], name
        assert sorted(rel(root, o) for o in b.overlaps) == exp["overlaps"].get(name, []), name
        assert sorted(rel(root, c) for c in b.copies) == sorted(
            c for c, original in exp["copies"].items() if original == name
        )
    starts = [b.start_ns for b in tl.bags if b.readable]
    assert starts == sorted(starts)
    sessions = [sorted(rel(root, p) for p in s.paths) for s in tl.sessions]
    assert sessions == exp["sessions"]


def test_pairings_match_the_answers(folder: dict[str, Any]) -> None:
    root, ans = folder["root"], folder["answers"]
    tl = scan([root])
    pairs = {rel(root, p.path): p for p in tl.pairings}
    assert set(pairs) == set(ans["expected"]["pairings"])
    for name, exp in ans["expected"]["pairings"].items():
        p = pairs[name]
        assert sorted(rel(root, g) for g in p.gt) == exp["gt"]
        assert p.basis == exp["basis"] and p.other_benchmark == ()
        # 1 ms grid in the answers: tolerance from the answers file.
        assert p.coverage == pytest.approx(exp["coverage"], abs=ans["tolerance"]["coverage"]["abs"])
        got = [[a / 1e9, b / 1e9] for a, b in p.uncovered]
        assert len(got) == len(exp["uncovered"])
        for g, e in zip(got, exp["uncovered"], strict=True):
            assert g == pytest.approx(e, abs=2e-3)  # grid step 1 ms, both ends


@pytest.mark.slow
def test_problems_match_the_answers(folder: dict[str, Any]) -> None:
    root, ans = folder["root"], folder["answers"]
    tl = scan([root])
    by_path: dict[str, list[str]] = {}
    for p in tl.problems:
        by_path.setdefault(rel(root, p.path), []).append(p.problem)
    for name, word in ans["expected"]["problems"].items():
        assert name in by_path, name
        if word != "any":
            assert any(word in text.lower() for text in by_path[name]), (name, by_path[name])
    # Nothing else is flagged.
    assert set(by_path) == set(ans["expected"]["problems"])
    words = ans["expected"]["problems"]
    gap_file = next(k for k, v in words.items() if v == "gap")
    gap = next(t for t in by_path[gap_file] if "gap of" in t)
    assert f"gap of {ans['expected']['split_gap_s']:.3f} s" in gap
    clock = next(
        t for k, v in ans["expected"]["problems"].items() if v == "clock" for t in by_path[k]
    )
    assert f"{ans['expected']['clock_offset_s']:+.3f} s" in clock


def test_cli_json_layout(folder: dict[str, Any], capsys: pytest.CaptureFixture[str]) -> None:
    root, ans = folder["root"], folder["answers"]
    assert main(["timeline", str(root), "--format", "json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert list(d) == ["bags", "sessions", "problems"]
    keys = BAG_KEYS
    for b in d["bags"]:
        assert list(b) == keys
        assert isinstance(b["overlaps"], list) and isinstance(b["problems"], list)
    trunc = next(b for b in d["bags"] if rel(root, b["path"]) == ans["truth"]["truncated"])
    if trunc["start"] is None:  # unreadable: listed with start null and under problems
        assert trunc["kind"] == "unreadable"
    assert any(rel(root, p["path"]) == ans["truth"]["truncated"] for p in d["problems"])
    assert all(set(p) == {"path", "problem"} for p in d["problems"])
    gt0 = next(b for b in d["bags"] if b["path"].endswith("_0.bag") and "gtlogger/" in b["path"])
    assert gt0["start"] == pytest.approx(
        ans["truth"]["bags"][rel(root, gt0["path"])]["start"], abs=1e-6
    )
    assert gt0["format"] == "ros1"


def test_cli_csv_and_table(folder: dict[str, Any], capsys: pytest.CaptureFixture[str]) -> None:
    root = folder["root"]
    assert main(["timeline", str(root), "--format", "csv"]) == 0
    rows = list(csv.DictReader(io.StringIO(capsys.readouterr().out)))
    assert len(rows) == 9
    assert {"start", "end", "duration", "kind", "path", "overlaps", "problems"} <= set(rows[0])
    assert main(["timeline", str(root)]) == 0
    out = capsys.readouterr().out
    assert "\033[" not in out  # captured stdout is no terminal: no colour
    assert "sessions:" in out and "GT coverage" in out and "problems (" in out


@pytest.mark.slow
def test_cli_plot(
    folder: dict[str, Any], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    for name in ("t.png", "t.svg"):
        assert main(["timeline", str(folder["root"]), "--plot", str(tmp_path / name)]) == 0
        assert (tmp_path / name).stat().st_size > 1000
    assert (tmp_path / "t.svg").read_text(encoding="utf-8").lstrip().startswith("<?xml")
    assert main(["timeline", str(folder["root"]), "--plot", str(tmp_path / "t.pdf")]) == 2


def test_scan_reports_bags_then_recordings(folder: dict[str, Any]) -> None:
    class Recorder:
        def __init__(self) -> None:
            self.tasks: list[tuple[str, int, str, list[int]]] = []

        def task(self, label: str, total: int, unit: str) -> None:
            self.tasks.append((label, total, unit, []))

        def advance(self, n: int) -> None:
            self.tasks[-1][3].append(n)

    rec = Recorder()
    with reporting(rec):  # as on the command line: the clock checks' reads must not report
        timeline = scan([folder["root"]], progress=rec)
    # The scenario's 9 files: gtlogger/ holds one recording split in 4 files (_0.._3), the
    # other 5 files (bmmanager, usb_stick, robots/homer, old, gtlogger_work) are one each.
    assert len(find_bags([folder["root"]]).bags) == 9
    summarising, clocks = rec.tasks
    assert summarising == ("summarising", 9, "bags", [1] * 9)  # one bag at a time
    assert clocks == ("checking clocks", 6, "recordings", [1] * 6)
    assert len(timeline.bags) == 9  # the scan itself unchanged: every file listed


def test_find_bags_walks_and_takes_rosbag2_folders(tmp_path: Path) -> None:
    (tmp_path / "a" / "b").mkdir(parents=True)
    (tmp_path / "a" / "x.bag").write_bytes(b"")
    (tmp_path / "a" / "b" / "y.bag.active").write_bytes(b"")
    (tmp_path / "a" / "z.mcap").write_bytes(b"")
    (tmp_path / "a" / "notes.txt").write_text("no")
    r2 = tmp_path / "a" / "ros2bag"
    r2.mkdir()
    (r2 / "metadata.yaml").write_text("x: 1")
    (r2 / "ros2bag_0.mcap").write_bytes(b"")
    found = find_bags([tmp_path, tmp_path / "missing"])
    assert [str(p.relative_to(tmp_path)) for p in found.bags] == [
        "a/b/y.bag.active",
        "a/ros2bag",
        "a/x.bag",
        "a/z.mcap",
    ]
    assert [p.problem for p in found.problems] == ["no such file or directory"]


def test_bad_files_are_listed_and_the_rest_still_read(
    folder: dict[str, Any], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    (tmp_path / "empty.bag").write_bytes(b"")
    (tmp_path / "random.bag").write_bytes(random.Random(0).randbytes(3000))
    good = next(folder["root"].glob("gtlogger/*_0.bag"))
    args = ["timeline", str(tmp_path), str(good), str(tmp_path / "missing"), "--format", "json"]
    assert main(args) == 0  # one bag was readable
    d = json.loads(capsys.readouterr().out)
    problems = {Path(p["path"]).name: p["problem"] for p in d["problems"]}
    assert "empty" in problems["empty.bag"]
    assert "random.bag" in problems and "missing" in problems
    assert [b["path"] for b in d["bags"] if b["start"] is not None] == [str(good)]


@pytest.mark.parametrize("case", ["empty_dir", "junk_only", "missing"])
def test_nothing_readable_exits_1(
    case: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    target = tmp_path / "x"
    if case == "empty_dir":
        target.mkdir()
    elif case == "junk_only":
        target.mkdir()
        (target / "a.bag").write_bytes(b"#ROSBAG V2.0\n" + b"\x00" * 20)
    assert main(["timeline", str(target)]) == 1
    err = capsys.readouterr().err
    assert err.count("ertools: error:") == 1 and "no readable bag" in err
    assert "Traceback" not in err


def test_real_2015_bag() -> None:
    real = Path(__file__).resolve().parents[2] / ".." / "shared" / "real_bags"
    if not real.is_dir():
        pytest.skip("../shared/real_bags not present")
    tl = scan([real])
    (b,) = tl.bags
    assert b.kind == "gt"  # pose, pose2d, tf, map, rosout: a GT logger (README)
    assert b.duration_ns is not None
    assert b.duration_ns / 1e9 == pytest.approx(57.6, abs=0.05)  # README: 57.6 s
    # The mocap node and the recorder ran on one machine: no clock problem, no other problem.
    assert b.problems == ()


def test_clock_checked_once_per_recording_unless_off(monkeypatch: pytest.MonkeyPatch) -> None:

    @dataclass(frozen=True)
    class S:
        path: str

    calls: list[str] = []
    offsets = {"log_a_2015-11-20-10-00-00": 0, "log_b_2015-11-20-10-00-00": 5_000_000_000}

    def fake(s: Any) -> ClockCheck:
        calls.append(Path(s.path).name)
        return ClockCheck(s.path, "/p", offsets[Path(s.path).name.rsplit("_", 1)[0]], 10)

    monkeypatch.setattr(ts, "clock_check", fake)
    files = [S(f"log_{x}_2015-11-20-10-00-00_{i}.bag") for x in "ab" for i in (2, 0, 1)]
    checks = ts.check_recordings(files, 500_000_000)  # type: ignore[arg-type]
    # a: in sync, only its first file is read; b: off by 5 s, all three are read.
    assert calls == [
        "log_a_2015-11-20-10-00-00_0.bag",
        "log_b_2015-11-20-10-00-00_0.bag",
        "log_b_2015-11-20-10-00-00_1.bag",
        "log_b_2015-11-20-10-00-00_2.bag",
    ]
    assert len(checks) == 4


@pytest.mark.parametrize("fmt", ["mcap", "rosbag2-mcap", "rosbag2-sqlite3"])
def test_other_formats_are_found_and_classified(fmt: str, tmp_path: Path) -> None:
    t0 = 1_448_013_600 * 1_000_000_000
    t = t0 + np.arange(240, dtype=np.int64) * 8_333_333
    name = "gt.mcap" if fmt == "mcap" else "gt_ros2"
    sub = tmp_path / "logs"
    sub.mkdir()
    with BagWriter(sub / name, fmt) as bag:  # type: ignore[arg-type]
        bag.write_pose_stamped(
            "/fbm3w/robot_at_work/pose",
            t + 300_000,
            t,
            "world",
            np.zeros((240, 3)),
            quat_from_yaw(np.zeros(240)),
        )
    tl = scan([tmp_path])
    (b,) = tl.bags
    assert Path(b.path).name == name
    assert (b.format, b.kind) == (fmt, "gt")
    assert (b.start_ns, b.end_ns) == (int(t[0]) + 300_000, int(t[-1]) + 300_000)
    assert b.problems == ()  # 0.3 ms between stamp and record: no clock problem


def test_corrupted_chunk_is_reported_by_the_clock_check(
    folder: dict[str, Any], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # A bz2 GT bag with bytes overwritten in the middle of its (only) chunk: the index is
    # intact, so the summary is fine; decoding the first messages is not.
    src = next(folder["root"].glob("gtlogger/*_0.bag"))
    data = bytearray(src.read_bytes())
    mid = len(data) // 2
    data[mid : mid + 64] = b"\xff" * 64
    bad = tmp_path / src.name
    bad.write_bytes(bytes(data))
    assert main(["timeline", str(bad), "--format", "json"]) == 0
    d = json.loads(capsys.readouterr().out)
    (problem,) = d["problems"]
    assert problem["path"] == str(bad)
    assert "cannot read the first messages of /fbm2h/robot_at_home/pose" in problem["problem"]
