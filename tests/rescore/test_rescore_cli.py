"""`ertools rescore` on a toy competition: scores through the registry, results.json/csv,
leaderboards, failure isolation, cache, exit codes."""

from __future__ import annotations

import csv
import hashlib
import io
import json
import re
import shutil
import sys
from pathlib import Path
from typing import Any

import pytest

from ertools.benchmarks import registry
from ertools.benchmarks.document import score_json
from ertools.benchmarks.scoring import score_execution
from ertools.cli.main import main
from ertools.competition import cache
from tests.rescore.rescore_competition import (
    LOGS,
    OFFSETS,
    expected_value,
    make_competition,
    use_toy_registry,
    write_offsets,
)


@pytest.fixture(autouse=True)
def _toy(monkeypatch: pytest.MonkeyPatch) -> None:
    use_toy_registry(monkeypatch)


def rescore(*argv: str) -> int:
    return main(["rescore", *argv])


def load(out: Path) -> dict[str, Any]:
    data: dict[str, Any] = json.loads((out / "results.json").read_text())
    return data


def by_id(doc: dict[str, Any]) -> dict[str, dict[str, Any]]:
    return {row["id"]: row for row in doc["executions"]}


def test_scores_every_execution_through_the_registry(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    comp = make_competition(tmp_path / "comp")
    out = tmp_path / "out"
    assert rescore("--config", str(comp.manifest), "--out", str(out), "--jobs", "1") == 0
    doc = load(out)
    rows = by_id(doc)
    assert list(rows) == sorted(LOGS, key=lambda i: LOGS[i][1])  # time order, ids from start
    for ident, (team, start, numbers) in LOGS.items():
        row = rows[ident]
        # by hand: mean x 2.0 + the team's offset (4.25, 12.0, 10.25)
        value = sum(numbers) / len(numbers) * 2.0 + OFFSETS[team]
        assert row["status"] == "scored" and row["reason"] is None
        assert row["score"] == {
            "toy": {"value": value, "count": len(numbers), "offset": OFFSETS[team]}
        }
        assert row["rank_value"] == value
        assert row["team"] == team and row["title"] == "Toy@Test"
        assert row["start"] == start.replace("Z", ".000000+00:00")
        assert row["bags"] == [str(comp.log(ident))]
        transform = comp.transform(team)

        assert {
            "name": "transform",
            "path": str(transform),
            "sha256": hashlib.sha256(transform.read_bytes()).hexdigest(),
        } in row["inputs"]
        assert {"name": "scale", "value": 2.0} in row["inputs"]
        assert row["report"] == f"executions/{ident}/index.html"
        assert (out / row["report"]).is_file()
        assert not row["cached"]
    assert rows["toy-alpha-20151120T091000"]["rank_value"] == 4.25
    # leaderboard: each team's best, lowest first
    (board,) = doc["leaderboards"]
    assert board["benchmark"] == "toy" and board["lower_is_better"] is True
    assert board["rule"] == "the lowest value wins"
    assert [(r["rank"], r["team"], r["value"], r["execution"]) for r in board["rows"]] == [
        (1, "alpha", 4.25, "toy-alpha-20151120T091000"),
        (2, "beta", 12.0, "toy-beta-20151120T093000"),
    ]
    assert doc["schema_version"] == 1 and doc["problems"] == []
    assert doc["manifest"]["path"] == str(comp.manifest.resolve())
    provenance = {p["path"]: p for p in doc["inputs"]}
    assert provenance[str(comp.log("toy-beta-20151120T093000"))]["size"] == len("0.5\n1.5\n")
    with (out / "results.csv").open() as fh:
        table = list(csv.DictReader(fh))
    assert [(r["id"], r["status"], float(r["rank_value"])) for r in table] == [
        (i, "scored", expected_value(i)) for i in rows
    ]
    assert "3 executions: 3 scored, 0 unscoreable, 0 failed" in capsys.readouterr().err


def test_score_is_the_score_commands_json(tmp_path: Path) -> None:
    """The row's score is score_json (what `ertools score NAME --format json` prints) of the
    benchmark's own result for the same bags and values."""
    comp = make_competition(tmp_path / "comp")
    out = tmp_path / "out"
    rescore("--config", str(comp.manifest), "--out", str(out), "--jobs", "1", "--no-reports")
    toy = registry.get("toy")
    for ident, row in by_id(load(out)).items():
        team = LOGS[ident][0]
        values = {"scale": 2.0, "transform": comp.transform(team)}
        result = score_execution(toy, [comp.log(ident)], values, check_logs=False).result
        assert row["score"] == score_json(result)
        assert row["report"] is None


@pytest.mark.slow
def test_a_failure_costs_one_row(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    comp = make_competition(
        tmp_path / "comp",
        {
            "toy-alpha-20151120T110000": ("alpha", "2015-11-20T11:00:00Z", "1\nbad\n"),
            "toy-alpha-20151120T111000": ("alpha", "2015-11-20T11:10:00Z", "1\nboom\n"),
            "toy-alpha-20151120T112000": ("alpha", "2015-11-20T11:20:00Z", "1\ndie\n"),
        },
    )
    out = tmp_path / "out"
    code = rescore("--config", str(comp.manifest), "--out", str(out), "--jobs", "2", "--no-reports")
    assert code == 1
    rows = by_id(load(out))
    for ident in LOGS:
        assert rows[ident]["status"] == "scored"
        assert rows[ident]["rank_value"] == expected_value(ident)
    bad, boom, die = (rows[f"toy-alpha-20151120T11{m}000"] for m in ("0", "1", "2"))
    assert bad["status"] == "unscoreable" and "no toy values can be scored here" in bad["reason"]
    assert boom["status"] == "failed"
    assert "RuntimeError: the toy scorer has a bug at rescore_toy.py" in boom["reason"]
    assert die["status"] == "failed" and "died (exit code 7)" in die["reason"]
    err = capsys.readouterr().err
    assert "6 executions: 3 scored, 1 unscoreable, 2 failed" in err
    assert "Traceback" not in err
    with (out / "results.csv").open() as fh:
        statuses = [r["status"] for r in csv.DictReader(fh)]
    assert statuses.count("failed") == 2


def test_second_run_recomputes_only_what_changed(tmp_path: Path) -> None:
    comp = make_competition(tmp_path / "comp")
    out = tmp_path / "out"
    args = ("--config", str(comp.manifest), "--out", str(out), "--jobs", "1")
    assert rescore(*args) == 0
    first = by_id(load(out))
    assert rescore(*args) == 0
    second = by_id(load(out))
    assert all(row["cached"] for row in second.values())
    for ident in LOGS:
        assert second[ident]["score"] == first[ident]["score"]
        assert second[ident]["report"] == first[ident]["report"]
    # beta's transform fixed: only beta's execution is scored again, with the new offset
    fixed = {**OFFSETS, "beta": 7.5}
    write_offsets(comp.root, fixed)
    assert rescore(*args) == 0
    third = by_id(load(out))
    assert {i: r["cached"] for i, r in third.items()} == {i: LOGS[i][0] != "beta" for i in LOGS}
    assert third["toy-beta-20151120T093000"]["rank_value"] == 1.0 * 2.0 + 7.5
    # --no-cache scores everything again
    assert rescore(*args, "--no-cache") == 0
    assert not any(r["cached"] for r in load(out)["executions"])


def test_cache_key_has_the_ertools_version(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    comp = make_competition(tmp_path / "comp")
    out = tmp_path / "out"
    args = ("--config", str(comp.manifest), "--out", str(out), "--jobs", "1", "--no-reports")
    rescore(*args)

    monkeypatch.setattr(cache, "__version__", "9.9.9")
    rescore(*args)
    assert not any(r["cached"] for r in load(out)["executions"])


def test_removed_report_folder_is_written_again(tmp_path: Path) -> None:
    comp = make_competition(tmp_path / "comp")
    out = tmp_path / "out"
    args = ("--config", str(comp.manifest), "--out", str(out), "--jobs", "1")
    rescore(*args)

    shutil.rmtree(out / "executions" / "toy-beta-20151120T093000")
    rescore(*args)
    rows = by_id(load(out))
    assert [i for i, r in rows.items() if not r["cached"]] == ["toy-beta-20151120T093000"]
    assert (out / rows["toy-beta-20151120T093000"]["report"]).is_file()


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["--out", "x"], "--config FILE is needed"),
        (["--config", "c.yaml"], "--out DIR is needed"),
        (["--config", "c.yaml", "--out", "x", "--jobs", "0"], "--jobs 0"),
        (["nowhere/", "--config", "c.yaml", "--out", "x"], "nowhere: no such file or folder"),
        (["--config", "c.yaml", "--out", "x", "--jobs", "two"], "invalid int value"),
    ],
)
def test_usage_errors_exit_2(
    argv: list[str],
    message: str,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    monkeypatch.chdir(tmp_path)
    assert rescore(*argv) == 2
    err = capsys.readouterr().err
    assert message in err and err.count("\n") == 1 and err.startswith("ertools: error:")


def test_scheduler_without_dask_installed_is_one_line(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    comp = make_competition(tmp_path / "comp")
    monkeypatch.setitem(sys.modules, "distributed", None)  # import distributed -> ImportError
    code = rescore(
        "--config", str(comp.manifest), "--out", str(tmp_path / "out"), "--scheduler", "local"
    )
    assert code == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert err == [
        "ertools: error: --scheduler needs Dask distributed: pip install 'ertools[dask]'"
    ]


class _Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


@pytest.mark.slow
def test_progress_bar_on_a_terminal(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    comp = make_competition(
        tmp_path / "comp",
        {
            "toy-alpha-20151120T110000": ("alpha", "2015-11-20T11:00:00Z", "1\nsleep\n"),
            "toy-alpha-20151120T111000": ("alpha", "2015-11-20T11:10:00Z", "1\nbad\n"),
        },
    )
    terminal = _Terminal()
    monkeypatch.setattr(sys, "stderr", terminal)
    args = ["--config", str(comp.manifest), "--out", str(tmp_path / "out"), "--no-reports"]
    assert rescore(*args, "--jobs", "1") == 1
    text = terminal.getvalue()
    # drawn after the bar's delay (the sleeping execution), counting executions and failures
    assert "\rertools: rescoring (1 not scored) [" in text
    assert re.search(r"\] [1-5]/5 executions", text)
    assert "ertools: 5 executions: 4 scored, 1 unscoreable, 0 failed" in text
    # -q: none
    quiet = _Terminal()
    monkeypatch.setattr(sys, "stderr", quiet)
    assert rescore(*args, "--jobs", "1", "--no-cache", "-q") == 1
    assert "\r" not in quiet.getvalue()
