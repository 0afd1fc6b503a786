"""A 2019 season folder in the RSBB layout (sample_bags/season2019) from ``rescore --init`` to
its results site: every run placed with its result and side files, the FBMs scored, the task
benchmarks' referee items on their leaderboards ranked by the ERL rule (answers.yaml, from
the scenario's plans); a 2015 folder beside it in the same site; ``ertools timeline``'s view
of the layout."""

from __future__ import annotations

import json
import shutil
from pathlib import Path
from typing import Any

import pytest
import yaml

from ertools.cli.main import main
from ertools.simulator.answers import read_answers

pytestmark = pytest.mark.slow  # scores a season (~20 s)

SAMPLES = Path(__file__).resolve().parents[2] / "sample_bags"
SEASON = SAMPLES / "season2019"


@pytest.fixture(scope="module")
def season(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, dict[str, Any], str]:
    """The season copied, its manifest drafted, rescored with the draft as written."""
    root = tmp_path_factory.mktemp("season")
    folder = root / "season2019"
    shutil.copytree(SEASON, folder)
    manifest = root / "season.yaml"
    assert main(["rescore", str(folder), "--init", str(manifest)]) == 0
    draft = manifest.read_text(encoding="utf-8")
    out = root / "results"
    code = main(["rescore", str(folder), "--config", str(manifest), "--out", str(out), "-j", "1"])
    assert code == 0
    doc: dict[str, Any] = json.loads((out / "results.json").read_text(encoding="utf-8"))
    return out, doc, draft


@pytest.fixture(scope="module")
def answers() -> dict[str, Any]:
    text = (SAMPLES / "season2019.answers.yaml").read_text(encoding="utf-8")
    data: dict[str, Any] = yaml.safe_load(text)
    return data


def _board(doc: dict[str, Any], name: str) -> dict[str, Any]:
    return next(b for b in doc["leaderboards"] if b["benchmark"] == name)


def test_the_draft_places_every_run_result_and_side_file(season: Any) -> None:
    _, doc, draft = season
    manifest = yaml.safe_load(draft)
    assert set(manifest["benchmarks"]) == {"hgmf", "hgtkmh", "hwv", "hcfgac", "stb"}
    assert manifest["benchmarks"]["hgmf"]["inputs"]["config"].endswith("HGMF.yaml")
    assert manifest["benchmarks"]["hwv"]["inputs"]["description"].endswith(
        "rsbb_etc/config/benchmarks_description.yaml"
    )
    listed = {(e["benchmark"], e["team"]): e for e in manifest["executions"]}
    assert set(listed) == {("hgmf", "simbot"), ("hgmf", "homebot"), ("stb", "simbot")}
    assert "results/HGMF/homebot/result_run_1_" in listed[("hgmf", "homebot")]["inputs"]["result"]
    places = {f["path"]: f["place"] for f in doc["files"]}
    for path, place in places.items():
        if path.endswith(".bag"):
            assert place == "execution", path
        elif path.startswith(("results/", "rsbb_etc/", "rsbb_bmbox/")):
            assert place == "input", path
    # the answers are beside the folder, as an organiser's folder holds none: no problem
    assert all(place != "problem" for place in places.values()), places
    assert doc["problems"] == []
    assert len(doc["executions"]) == 9 and all(e["status"] == "scored" for e in doc["executions"])
    # the folders name the teams; the draft lists the runs with a result file by name
    sources = {(e["benchmark"], e["team_source"]) for e in doc["executions"]}
    assert sources == {
        ("hgmf", "manifest"),
        ("stb", "manifest"),
        ("hgtkmh", "RSBB layout"),
        ("hwv", "RSBB layout"),
        ("hcfgac", "RSBB layout"),
    }


def test_the_fbm_leaderboard(season: Any, answers: dict[str, Any]) -> None:
    _, doc, _ = season
    expected = answers["expected"]["leaderboards"]["hgmf"]
    tol = answers["tolerance"]["Avg distance error"]["abs"]
    rows = _board(doc, "hgmf")["rows"]
    assert [r["team"] for r in rows] == [e["team"] for e in expected]
    for row, e in zip(rows, expected, strict=True):
        assert row["value"] == pytest.approx(e["Avg distance error"], abs=tol)
    # each row compared with the live score the RSBB published: the same but for ertools'
    # reading (none of it applies to these runs)
    hgmf = [e for e in doc["executions"] if e["benchmark"] == "hgmf"]
    assert all(e["live_score"] and e["live_differences"] == [] for e in hgmf)


@pytest.mark.parametrize("name", ["hgtkmh", "hwv", "hcfgac", "stb"])
def test_the_task_leaderboards(season: Any, answers: dict[str, Any], name: str) -> None:
    _, doc, _ = season
    expected = answers["expected"]["leaderboards"][name]
    board = _board(doc, name)
    assert [r["team"] for r in board["rows"]] == [e["team"] for e in expected["ranked"]]
    assert [r["rank"] for r in board["rows"]] == list(range(1, len(expected["ranked"]) + 1))
    for row, e in zip(board["rows"], expected["ranked"], strict=True):
        cells = row["columns"]
        assert cells["achievements"] == e["achievements"]
        assert cells["penalized"] == e["penalized_behaviors"]
        assert cells["time (s)"] == pytest.approx(e["execution_time"], abs=1e-9)
    unranked = [u["note"].split(":")[0] for u in board["unranked"]]
    assert unranked == expected["unranked"]
    headers = [c["header"] for c in board["columns"]]
    assert headers[:3] == ["achievements", "penalized", "time (s)"]
    assert all(h[0] in "APD" for h in headers[3:])  # each item shown


def test_the_site_shows_the_items(season: Any) -> None:
    out, _, _ = season
    page = (out / "index.html").read_text(encoding="utf-8")
    assert "HWV (Task Benchmark 2: Welcoming visitors): leaderboard" in page
    assert "homebot: disqualified (hits a visitor)" in page
    assert '<th title="Achievements: carries out the command of phase 2">A4</th>' in page
    assert "HCFGAC (Task Benchmark 3: Catering for Granny Annie&#39;s Comfort): leaderboard" in page
    assert '<th title="Penalized Behaviors: drops an object">P2</th>' in page


def test_one_command_from_the_folder_to_the_site(
    season: Any, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """No --config: the manifest is drafted from the logs, kept in the results folder, and the
    site is the one of --init then --config; an edited draft is never overwritten."""
    _, two_steps, draft = season
    folder = tmp_path / "season2019"
    shutil.copytree(SEASON, folder)
    out = tmp_path / "results"
    assert main(["rescore", str(folder), "--out", str(out), "-j", "1", "--no-reports"]) == 0
    doc = json.loads((out / "results.json").read_text(encoding="utf-8"))
    assert doc["leaderboards"] == two_steps["leaderboards"]
    kept = out / "manifest.yaml"
    assert doc["manifest"]["path"] == str(kept)
    drafted, by_init = yaml.safe_load(kept.read_text(encoding="utf-8")), yaml.safe_load(draft)
    assert [(e["benchmark"], e["team"]) for e in drafted["executions"]] == [
        (e["benchmark"], e["team"]) for e in by_init["executions"]
    ]
    assert drafted["benchmarks"].keys() == by_init["benchmarks"].keys()
    capsys.readouterr()

    edited = kept.read_text(encoding="utf-8") + "# a referee's note\n"
    kept.write_text(edited, encoding="utf-8")
    assert main(["rescore", str(folder), "--out", str(out), "-j", "1", "--no-reports"]) == 2
    err = capsys.readouterr().err
    # one message (usage errors are wrapped at the terminal's width: this path is long)
    assert err.startswith("ertools: error:") and err.count("ertools:") == 1
    assert "is not the manifest drafted from these logs" in " ".join(err.split())
    assert kept.read_text(encoding="utf-8") == edited


def test_a_2015_folder_beside_a_2019_one(tmp_path: Path) -> None:
    shutil.copytree(SEASON, tmp_path / "season2019")
    shutil.copytree(SAMPLES / "fbm2h", tmp_path / "lisbon2015")
    manifest = tmp_path / "both.yaml"
    paths = [str(tmp_path / "lisbon2015"), str(tmp_path / "season2019")]
    assert main(["rescore", *paths, "--init", str(manifest)]) == 0
    out = tmp_path / "results"
    main(["rescore", *paths, "--config", str(manifest), "--out", str(out), "-j", "1"])
    doc = json.loads((out / "results.json").read_text(encoding="utf-8"))
    names = [b["benchmark"] for b in doc["leaderboards"]]
    assert "fbm2h" in names and "hgmf" in names and "hwv" in names
    assert {e["benchmark"] for e in doc["executions"]} >= {"fbm2h", "hgmf", "hgtkmh"}


# Each FBM sample's ranked value in ertools' reading, and the tolerance key of its answers.
FBM_SAMPLES = {
    "hnf": ("position_accuracy", "distance"),
    "hpff": ("Average deviation from desired distance", "deviation"),
    "hopf": ("pose_score", "pose"),
    "hppf": ("Distance error", "position"),
}


def test_every_fbm_in_one_season(tmp_path: Path) -> None:
    """The season with the HNF, HPFF, HOPF and HPPF samples' runs, side files and result files
    merged into its layout: one draft places them all, each FBM gets its leaderboard, each
    board's value is the best run's answer (from the sample's noiseless truth)."""
    folder = tmp_path / "season"
    for name in ("season2019", *FBM_SAMPLES):
        # hnf and hpff share rsbb_etc/transforms/transform-simbot.yaml (the same file)
        shutil.copytree(SAMPLES / name, folder, dirs_exist_ok=True)
    manifest = tmp_path / "season.yaml"
    assert main(["rescore", str(folder), "--init", str(manifest)]) == 0
    draft = manifest.read_text(encoding="utf-8")
    out = tmp_path / "results"
    code = main(["rescore", str(folder), "--config", str(manifest), "--out", str(out), "-j", "1"])
    assert code == 0
    doc = json.loads((out / "results.json").read_text(encoding="utf-8"))
    for name, (key, tol_key) in FBM_SAMPLES.items():
        runs = sorted((SAMPLES / name / "rsbb_logs").glob("*/simbot/*.bag"))
        answers = [read_answers(bag) for bag in runs]  # <name>.answers.yaml beside the folder
        values = [a["expected"]["ertools"][key] for a in answers]
        board = _board(doc, name)
        (row,) = board["rows"]
        best = min(values) if board["lower_is_better"] else max(values)
        assert row["team"] == "simbot"
        assert row["value"] == pytest.approx(best, abs=answers[0]["tolerance"][tol_key]["abs"])
        for bag in (SAMPLES / name / "rsbb_logs").glob("*/simbot/*.bag"):
            assert bag.name in draft
        for side in (SAMPLES / name / "results").glob("*/simbot/*.yaml"):
            assert side.name in draft
    scripted = [e for e in doc["executions"] if e["benchmark"] in FBM_SAMPLES]
    # every run's live score found (HPFF's run 2, stopped while sampling, published an empty one)
    assert len(scripted) == 6 and all(e["live_score"] is not None for e in scripted)
    assert {b["benchmark"] for b in doc["leaderboards"]} >= {*FBM_SAMPLES, "hgmf", "hwv"}


def test_timeline_shows_the_runs(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["timeline", str(SEASON), "--no-clock-check", "--format", "json"]) == 0
    data = json.loads(capsys.readouterr().out)
    runs = {(r["code"], r["team"]): r for r in data["rsbb"]["runs"]}
    assert len(runs) == 9
    assert runs[("HGMF", "simbot")]["result"].endswith(".yaml")
    assert runs[("HGMF", "simbot")]["config"].endswith("HGMF.yaml")
    assert runs[("HWV", "homebot")]["result"] is None  # a task benchmark: no script
    bags = {b["path"]: b for b in data["bags"]}
    assert all(b["kind"] == "benchmark" for b in bags.values())
    assert {tuple(b["benchmarks"]) for b in bags.values()} == {
        ("hgmf",),
        ("hgtkmh",),
        ("hwv",),
        ("hcfgac",),
        ("stb",),
    }
    assert main(["timeline", str(SEASON), "--no-clock-check"]) == 0
    text = capsys.readouterr().out
    assert "RSBB runs (9, docs/rsbb.md):" in text and "no GT file covers it" not in text


def test_the_sample_season_rescores_in_one_command_without_a_warning(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # the README's command on the committed folder: what an organiser has, nothing unused
    out = tmp_path / "out"
    code = main(["rescore", str(SEASON), "--out", str(out), "--no-reports", "-j", "1"])
    assert code == 0
    err = capsys.readouterr().err
    assert "warning" not in err, err
    doc: dict[str, Any] = json.loads((out / "results.json").read_text(encoding="utf-8"))
    assert doc["problems"] == []
    assert len(doc["executions"]) == 9
