"""Small faults (issue 36, finding 20): each one a wrong or misleading output, fixed where all
its variants pass (every output path, every result read, every name printed)."""

from __future__ import annotations

import csv
import json
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path
from typing import Any

import pytest

from ertools.cli.main import main
from tests.helpers import inprocess
from tests.helpers.stderr_text import error_messages

ROOT = Path(__file__).resolve().parents[2]
SAMPLES = ROOT / "sample_bags"
FBM3W_BAG = SAMPLES / "fbm3w" / "log_fbm3w_mocap_2015-11-20-12-00-00_0.bag"


def _strict_json(text: str) -> Any:
    def refuse(word: str) -> float:
        raise AssertionError(f"{word} is not JSON")

    return json.loads(text, parse_constant=refuse)


# --- report: a result holding Infinity ---------------------------------------------------------


def _result(folder: Path, team: str, best: str) -> Path:
    """A result.json as `score --report` writes it, the score spelled as given (JSON text)."""
    folder.mkdir(parents=True)
    score = f'"best_distance_error": {best}, "best_run": 0'
    (folder / "result.json").write_text(
        f'{{"benchmark": "fbm3w", "team": "{team}", "inputs": [], "headline": {{{score}}}, '
        f'"score": {{{score}, "best_distance_error_interval": [0.0004, 0.0006], '
        '"uncertainty": {"confidence": 0.95}}}'
    )
    return folder


@pytest.mark.parametrize("spelling", ["Infinity", "-Infinity", "NaN"])
def test_report_ranks_no_result_whose_score_is_not_a_number(
    spelling: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Python's json reads `Infinity`; ranked, -Infinity came first (lower is better) and
    Infinity second of two. Such a score is no score: listed unranked, with the reason."""
    folders = [
        _result(tmp_path / "a", "alpha", "0.0005"),
        _result(tmp_path / "b", "bravo", spelling),
        _result(tmp_path / "c", "charlie", "0.0009"),
    ]
    out = tmp_path / "site"
    assert main(["report", *map(str, folders), "--report", str(out)]) == 0
    rows = {r["team"]: r for r in _strict_json((out / "results.json").read_text())}
    assert rows["alpha"]["rank"] == 1 and rows["charlie"]["rank"] == 2
    assert rows["bravo"]["rank"] is None
    assert rows["bravo"]["best_distance_error"] is None
    assert "not a finite number" in rows["bravo"]["rank_note"]
    with (out / "results.csv").open() as f:
        table = {r["team"]: r for r in csv.DictReader(f)}
    assert table["bravo"]["rank"] == "" and table["bravo"]["best_distance_error"] == ""


# --- output paths: a full disk, a read-only folder ----------------------------------------------

INFO = ["info", str(FBM3W_BAG), "--format", "json"]


def test_a_full_device_is_named(capsys: pytest.CaptureFixture[str]) -> None:
    """Before: `ertools: error: No space left on device: cannot read or write there`."""
    assert main([*INFO, "-o", "/dev/full"]) == 1
    err = capsys.readouterr().err
    assert err == "ertools: error: /dev/full: No space left on device: cannot read or write there\n"


def test_a_full_stdout_is_named() -> None:
    """Writes that go through no temporary (stdout here) name what was being written."""
    code = f"import sys\nfrom ertools.cli.main import main\nsys.exit(main({INFO!r}))\n"
    with open("/dev/full", "w") as full:
        ran = subprocess.run(
            [sys.executable, "-c", code],
            stdout=full,
            stderr=subprocess.PIPE,
            text=True,
            check=False,
        )
    assert ran.returncode == 1
    assert ran.stderr == (
        "ertools: error: writing stdout: No space left on device: cannot read or write there\n"
    )


def test_a_full_disk_names_the_output_and_leaves_no_temporary(tmp_path: Path) -> None:
    """A file size limit (RLIMIT_FSIZE, as a full disk: the write fails, naming no file) on a
    process writing its output through a temporary: the error names the output."""
    out = tmp_path / "out" / "info.json"
    out.parent.mkdir()
    code = (
        "import resource, signal, sys\n"
        "signal.signal(signal.SIGXFSZ, signal.SIG_IGN)\n"
        "resource.setrlimit(resource.RLIMIT_FSIZE, (200, 200))\n"
        "from ertools.cli.main import main\n"
        f"sys.exit(main({[*INFO, '-o', str(out)]!r}))\n"
    )
    ran = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=False)
    assert ran.returncode == 1, ran.stderr
    assert ran.stderr == f"ertools: error: {out}: File too large: cannot read or write there\n"
    assert list(out.parent.iterdir()) == []  # no output, no temporary


def test_a_read_only_folder_names_the_output(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """The tests run as root, whom no mode stops: the refusal is made as the OS makes it to
    anyone else (mkstemp's PermissionError names the temporary it could not create)."""
    out = tmp_path / "score.json"

    def refuse(dir: str, prefix: str, suffix: str) -> tuple[int, str]:
        raise PermissionError(13, "Permission denied", f"{dir}/{prefix}abc123{suffix}")

    monkeypatch.setattr(tempfile, "mkstemp", refuse)
    assert main([*INFO, "-o", str(out)]) == 1
    err = capsys.readouterr().err
    assert err == f"ertools: error: {out}: Permission denied: cannot read or write there\n"


# --- `--` before a bag whose name starts with a dash ---------------------------------------------


@pytest.mark.parametrize(
    "argv",
    [
        ["score", "fbm3w", "--", "-h.bag"],
        ["score", "-v", "fbm3w", "--", "-h.bag"],
        ["score", "--", "fbm3w", "-h.bag"],
        ["score", "fbm3w", "--draws", "0", "--", "-h.bag"],
    ],
)
def test_a_bag_named_like_an_option_after_a_double_dash(
    argv: list[str], tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Before: `score fbm3w -- -h.bag` printed "argument -h/--help: ignored explicit argument
    '.bag'", exit 2 (the group's parser dropped the `--` before handing the rest on)."""
    shutil.copy(FBM3W_BAG, tmp_path / "-h.bag")
    monkeypatch.chdir(tmp_path)
    ran = inprocess.run(argv)
    assert ran.code == 0, ran.stderr
    assert "best_distance_error" in ran.stdout


# --- a file name holding a newline or an escape sequence -----------------------------------------

FORGED = "evil\nertools: error: forged.bag"


def test_a_file_name_cannot_forge_lines_of_the_timeline(tmp_path: Path) -> None:
    """Before: the path's newline started a line `ertools: error: forged.bag` of its own in
    the table (and of the pairing below it)."""
    folder = tmp_path / "logs"
    folder.mkdir()
    shutil.copy(FBM3W_BAG, folder / FORGED)
    shutil.copy(FBM3W_BAG, folder / "\x1b[2Jclear.bag")
    (folder / "broken\nertools: error: forged too.bag").write_bytes(b"#ROSBAG V2.0\n")
    ran = inprocess.run(["timeline", str(folder)])
    assert ran.code == 0, ran.stderr
    for stream in (ran.stdout, ran.stderr):
        assert "\x1b" not in stream
        assert not any(line.startswith("ertools: error: forged") for line in stream.splitlines())
    assert all(line.startswith("ertools: ") for line in ran.stderr.splitlines()), ran.stderr
    assert "evil\\nertools: error: forged.bag" in ran.stdout
    assert "\\x1b[2Jclear.bag" in ran.stdout
    assert "broken\\nertools: error: forged too.bag" in ran.stderr  # its problem, on one line


def test_a_file_name_cannot_forge_lines_of_info_or_score(tmp_path: Path) -> None:
    bag = tmp_path / FORGED
    shutil.copy(FBM3W_BAG, bag)
    info = inprocess.run(["info", str(bag)])
    assert info.code == 0 and "evil\\nertools: error: forged.bag" in info.stdout
    score = inprocess.run(
        ["score", "fbm3w", str(bag), "--draws", "0", "-o", str(tmp_path / "s.yaml")]
    )
    assert score.code == 0, score.stderr
    assert all(line.startswith("ertools: ") for line in score.stderr.splitlines()), score.stderr
    assert not any(line.startswith("ertools: error: forged") for line in score.stderr.splitlines())


# --- rescore: its own results folder inside the scanned one; a topic missing -------------------


def test_a_results_folder_inside_the_logs_is_not_listed_as_unused(tmp_path: Path) -> None:
    """Before: the second run listed the first run's results, pages and cache (30 files) as
    `unused` problems of the logs' folder."""
    logs = tmp_path / "logs"
    logs.mkdir()
    shutil.copy(FBM3W_BAG, logs / FBM3W_BAG.name)
    manifest = tmp_path / "competition.yaml"
    manifest.write_text("version: 1\n")
    argv = ["rescore", str(logs), "--config", str(manifest), "--out", str(logs / "results")]
    for _ in range(2):
        ran = inprocess.run([*argv, "--jobs", "1"])
        assert ran.code == 0, ran.stderr
    doc = json.loads((logs / "results" / "results.json").read_text())
    assert [f["path"] for f in doc["files"]] == [FBM3W_BAG.name]
    assert not [p for p in doc["problems"] if p["kind"] == "unused"]


def test_an_execution_unscoreable_for_a_missing_topic_is_said_on_stderr(tmp_path: Path) -> None:
    """Before: its row said `unscoreable` in results.json, and stderr nothing but the count."""
    manifest = tmp_path / "competition.yaml"
    manifest.write_text(
        "version: 1\nbenchmarks:\n  fbm3w:\n    inputs: {topic: /no/such/topic}\n"
        f"executions:\n- {{benchmark: fbm3w, team: a, bags: [{FBM3W_BAG}]}}\n"
    )
    ran = inprocess.run(
        ["rescore", "--config", str(manifest), "--out", str(tmp_path / "out"), "--jobs", "1"]
    )
    assert ran.code == 1
    lines = error_messages(ran.stderr)
    assert len(lines) == 1, ran.stderr
    assert lines[0].startswith("ertools: error: fbm3w-a-20151120T120000: unscoreable: ")
    assert "/no/such/topic: no such topic" in lines[0]


# --- a report folder reused for another benchmark --------------------------------------------

FBM2H_BAG = SAMPLES / "fbm2h" / "log_fbm2h_mocap_2015-11-20-12-00-00_0.bag"


def test_a_reused_report_folder_keeps_nothing_of_the_previous_report(tmp_path: Path) -> None:
    """Before: runs.csv, points.csv, noise.csv and the fbm3w figures stayed beside the fbm2h
    report written into the same folder. Only files the previous report listed go: the
    user's own stay, and a listed path leading out of the folder is never touched."""
    report = tmp_path / "report"
    first = inprocess.run(["score", "fbm3w", str(FBM3W_BAG), "--report", str(report)])
    assert first.code == 0, first.stderr
    (report / "notes.txt").write_text("the referee's own notes\n")
    outside = tmp_path / "outside.txt"
    outside.write_text("not the report's\n")
    meta = json.loads((report / "result.json").read_text())
    meta["files"].append("../outside.txt")
    (report / "result.json").write_text(json.dumps(meta))
    second = inprocess.run(["score", "fbm2h", str(FBM2H_BAG), "--report", str(report)])
    assert second.code == 0, second.stderr
    names = {p.relative_to(report).as_posix() for p in report.rglob("*") if p.is_file()}
    listed = set(json.loads((report / "result.json").read_text())["files"])
    assert names == listed | {"notes.txt", "result.json"}
    assert not any("fbm3w" in n for n in names) and "runs.csv" not in names
    assert outside.exists()
