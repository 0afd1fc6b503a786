"""The sample competition (``python -m ertools.samples --competition DIR``): deterministic,
its answers name real files, and every scored execution's ``ertools score`` matches them.

The expected scores in ``answers.json`` come from each scenario's noiseless truth (the same
``expected`` the single-benchmark samples have); the tolerances are the scenarios' own,
justified by the mocap noise there: FBM2H 2 mm / 3 mrad per waypoint (a mean of five stays
within it), FBM3W 0.4 mm per run, FBM1H 5e-4 on a pose score, transition times 1 us, counts
exact.
"""

from __future__ import annotations

import contextlib
import io
import itertools
import json
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest

from ertools.benchmarks.common.teams import parse_robot_log_name
from ertools.cli.main import main
from ertools.samples.__main__ import main as samples_main
from ertools.samples.competition_schedule import MISSING_TRANSFORM, SCHEDULE, TRUNCATED
from tests.helpers.simd_paths import baseline_env

pytestmark = pytest.mark.slow

SEED = 2015_11_20
UNSCOREABLE = sorted(
    s.id
    for s in SCHEDULE
    if s.id == TRUNCATED or (s.benchmark, s.team) == ("fbm2h", MISSING_TRANSFORM)
)
SCORED = [s.id for s in SCHEDULE if s.id not in UNSCOREABLE]


@pytest.fixture(scope="module")
def competition(sample_competition: Path) -> Path:
    return sample_competition  # generated once per session (tests/conftest.py), seed SEED


@pytest.fixture(scope="module")
def answers(competition: Path) -> dict[str, Any]:
    data: dict[str, Any] = json.loads((competition / "answers.json").read_text())
    return data


def _files(root: Path) -> dict[str, bytes]:
    return {
        str(p.relative_to(root)): p.read_bytes() for p in sorted(root.rglob("*")) if p.is_file()
    }


def test_two_generations_are_byte_identical(competition: Path, tmp_path: Path) -> None:
    """What docs/samples.md claims of ``python -m ertools.samples --competition``: the same
    bytes from run to run and on every x86-64 CPU. The first generation (tests/conftest.py)
    ran the command as users do (NumPy's AVX-512 targets pinned off where the CPU has them),
    the second runs it with every target this CPU has off (NumPy's baseline code, the C
    library's maths) and another string-hash seed (nothing may depend on set or dict order
    of strings)."""
    env = {**baseline_env(), "PYTHONHASHSEED": "4242"}
    out = tmp_path / "again"
    proc = subprocess.run(
        [sys.executable, "-m", "ertools.samples", "--competition", str(out), "--seed", str(SEED)],
        env=env,
        capture_output=True,
        text=True,
        check=False,
        timeout=120,
    )
    assert proc.returncode == 0, proc.stderr
    first, second = _files(competition), _files(out)
    assert sorted(first) == sorted(second)
    differ = [name for name in first if first[name] != second[name]]
    assert not differ, f"files differ between two generations: {differ}"


def test_command_line_refuses_mixed_modes(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    with pytest.raises(SystemExit) as exc:
        samples_main([str(tmp_path / "x"), "--competition", str(tmp_path / "y")])
    assert exc.value.code == 2
    assert "--competition" in capsys.readouterr().err


def test_every_named_file_exists_and_every_file_is_named(
    competition: Path, answers: dict[str, Any]
) -> None:
    named: set[str] = {"answers.json", answers["manifest"]}
    missing_transform = [p for p in answers["problems"] if p["kind"] == "missing-input"]
    absent = {p["path"] for p in missing_transform}
    assert len(absent) == 1
    for e in answers["executions"]:
        named |= {e["bmbox_log"], *e["gt_files"], *e["inputs"].values()}
        if e["robot_log"] is not None:
            named.add(e["robot_log"])
    named |= {g["path"] for g in answers["gt_logger"]}
    named |= {r["path"] for r in answers["robot_logs"]}
    named |= set(answers["copies"])
    named |= {p["path"] for p in answers["problems"] if p["path"] is not None}
    for rel in sorted(named - absent):
        assert (competition / rel).is_file(), rel
    for rel in absent:
        assert not (competition / rel).exists(), rel
    on_disk = set(_files(competition))
    assert on_disk == named - absent, on_disk ^ (named - absent)


def test_a_realistic_day(competition: Path, answers: dict[str, Any]) -> None:
    execs = answers["executions"]
    assert 10 <= len(execs) <= 15
    assert len({e["team"] for e in execs}) >= 3
    assert {e["benchmark"] for e in execs} == {"fbm1h", "fbm2h", "fbm3w"}
    starts = [e["start_ns"] for e in execs]
    assert len(set(starts)) == len(starts) and starts == sorted(starts)
    # spread over the day: more than three hours from first to last, no two within 10 min
    assert starts[-1] - starts[0] > 3 * 3600 * 10**9
    assert min(b - a for a, b in itertools.pairwise(starts)) > 600 * 10**9
    # GT hour files: contiguous one-hour splits of one recording, the last still recording
    gt = answers["gt_logger"]
    assert [Path(g["path"]).name.rsplit("_", 1)[1].split(".")[0] for g in gt] == [
        str(i) for i in range(len(gt))
    ]
    assert gt[-1]["path"].endswith(".bag.active")
    for a, b in itertools.pairwise(gt):
        assert 0 < b["start_ns"] - a["end_ns"] <= 100_000_000  # the 10 Hz tf: no gap
    # every execution inside the GT files it names, one straddling an hour boundary
    spans = {g["path"]: (g["start_ns"], g["end_ns"]) for g in gt}
    for e in execs:
        covered = [spans[p] for p in e["gt_files"]]
        assert covered[0][0] <= e["start_ns"] and e["end_ns"] <= covered[-1][1], e["id"]
    assert any(len(e["gt_files"]) == 2 for e in execs)
    size = sum(len(b) for b in _files(competition).values())
    assert size < 30_000_000, size


def _get(d: Any, field: str) -> Any:
    for key in field.split("."):
        d = d[key]
    return d


def _score(root: Path, e: dict[str, Any]) -> tuple[int, dict[str, Any]]:
    opt = {"items": "--items", "goal": "--goal", "transform": "--transform", "config": "--config"}
    args = ["score", e["benchmark"], str(root / e["bmbox_log"])]
    args += [str(root / g) for g in e["gt_files"]]
    for key, rel in sorted(e["inputs"].items()):
        args += [opt[key], str(root / rel)]
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        # the answers hold scores, not intervals: no Monte Carlo draws
        code = main([*args, "--format", "json", "--draws", "0"])
    return code, json.loads(out.getvalue()) if out.getvalue() else {}


@pytest.mark.parametrize("slot", SCORED)
def test_each_scored_execution_scores_as_its_answers(
    competition: Path, answers: dict[str, Any], slot: str
) -> None:
    (e,) = [x for x in answers["executions"] if x["id"] == slot]
    assert e["status"] == "scored"
    code, result = _score(competition, e)
    assert code == 0
    assert e["score"], "an execution with no expected fields tests nothing"
    for field, want in e["score"].items():
        got = _get(result, field)
        tol = e["tolerance"][field]["abs"]
        if isinstance(want, float):
            assert abs(got - want) <= tol, f"{slot} {field}: {got} vs {want} (+-{tol})"
        else:
            assert got == want, f"{slot} {field}: {got} vs {want}"
    # the live 2015 score the BmBox sent, read back from the log (FBM1H reports it)
    assert e["live_score"] is not None
    if e["benchmark"] == "fbm1h":
        assert result["logged_2015_score"] == e["live_score"]


def test_unscoreable_executions(competition: Path, answers: dict[str, Any]) -> None:
    bad = {e["id"]: e for e in answers["executions"] if e["status"] != "scored"}
    skuba_id, trunc_id = "fbm2h-skuba-20151120T111450", "fbm3w-b-it-bots-20151120T113715"
    assert sorted(bad) == UNSCOREABLE == [skuba_id, trunc_id]
    skuba = bad[skuba_id]
    assert "transform" in skuba["reason"]
    assert not (competition / skuba["inputs"]["transform"]).exists()
    trunc = bad[trunc_id]
    assert trunc["truncated"] and "truncated" in trunc["reason"]
    # cut at 60 %: shorter than any complete FBM3W benchmark log of the day
    whole = [
        (competition / e["bmbox_log"]).stat().st_size
        for e in answers["executions"]
        if e["benchmark"] == "fbm3w" and not e["truncated"]
    ]
    size = (competition / trunc["bmbox_log"]).stat().st_size
    assert size < 0.65 * min(whole)


def test_robot_logs_and_problems(competition: Path, answers: dict[str, Any]) -> None:
    for r in answers["robot_logs"]:
        parsed = parse_robot_log_name(r["path"])
        assert parsed is not None and parsed.team == r["team"]
        assert parsed.benchmark == r["benchmark"]
    kinds = {p["kind"] for p in answers["problems"]}
    assert kinds == {
        "truncated",
        "active",
        "duplicate",
        "clock-offset",
        "unpaired",
        "missing-input",
        "no-team",
    }
    ((copy, original),) = answers["copies"].items()
    assert (competition / copy).read_bytes() == (competition / original).read_bytes()
    (clock,) = [p for p in answers["problems"] if p["kind"] == "clock-offset"]
    (robot,) = [r for r in answers["robot_logs"] if r["path"] == clock["path"]]
    assert robot["header_minus_record_s"] == pytest.approx(clock["offset_s"] - 0.002)


@pytest.mark.parametrize("slot", [s.id for s in SCHEDULE if s.benchmark == "fbm2h"])
def test_each_fbm2h_robot_log_scores_as_its_answers(
    competition: Path, answers: dict[str, Any], slot: str
) -> None:
    # The robots' marker pose estimates against the GT hour files (ertools score trajectory,
    # the robot's clock offset applied): the answers are the robotlog scenario's plain loop
    # over the same arrays, so counts are exact and errors agree to float rounding.
    (r,) = [x for x in answers["robot_logs"] if x["execution"] == slot]
    traj = r["trajectory"]
    args = ["score", "trajectory", str(competition / r["path"])]
    args += [str(competition / g) for g in r["gt_files"]]
    args += ["--robot-topic", traj["robot_topic"], "--gt-topic", traj["gt_topic"]]
    args += ["--offset", repr(traj["offset_s"]), "--format", "json", "--draws", "0"]
    out = io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(io.StringIO()):
        assert main(args) == 0
    result = json.loads(out.getvalue())
    assert traj["score"]["compared"] > 400
    for field, want in traj["score"].items():
        assert abs(result[field] - want) <= traj["tolerance"][field]["abs"], (slot, field)
