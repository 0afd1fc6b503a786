"""The pipeline as a library: executions found elsewhere (not listed in the manifest), the
progress it reports, leaderboard ties."""

from __future__ import annotations

from pathlib import Path

import pytest

from ertools.benchmarks import registry
from ertools.competition.manifest import load_manifest
from ertools.competition.pipeline import (
    Scoring,
    leaderboards,
    listed_executions,
    rescore,
    score_argv,
)
from tests.rescore.rescore_competition import (
    LOGS,
    expected_value,
    make_competition,
    use_toy_registry,
)


@pytest.fixture(autouse=True)
def _toy(monkeypatch: pytest.MonkeyPatch) -> None:
    use_toy_registry(monkeypatch)


class Recorder:
    def __init__(self) -> None:
        self.calls: list[tuple[str, int, str, int]] = []

    def task(self, label: str, total: int, unit: str) -> None:
        self.calls.append((label, total, unit, 0))

    def advance(self, n: int) -> None:
        label, total, unit, done = self.calls[-1]
        self.calls[-1] = (label, total, unit, done + n)


def test_a_team_without_its_transform_is_one_unscoreable_row(tmp_path: Path) -> None:
    comp = make_competition(tmp_path / "comp")
    manifest = load_manifest(comp.manifest)
    found = Scoring(
        benchmark="toy",
        team="gamma",  # found in the logs; the manifest has no transform for it
        bags=(comp.log("toy-beta-20151120T093000"),),
        start_ns=1448013600 * 10**9,  # 2015-11-20T10:00:00Z
        team_source="log name",
    )
    progress = Recorder()
    doc = rescore(
        [*listed_executions(manifest), found],
        manifest,
        tmp_path / "out",
        reports=False,
        progress=progress,
        problems=[{"kind": "truncated", "path": "x.bag", "message": "x.bag: truncated"}],
    )
    rows = {r["id"]: r for r in doc["executions"]}
    gamma = rows["toy-gamma-20151120T100000"]
    assert gamma["status"] == "unscoreable" and gamma["score"] is None
    assert gamma["reason"] == (
        "toy: no transform for team gamma in the manifest (benchmarks.toy.teams.gamma.transform)"
    )
    assert gamma["team_source"] == "log name"
    assert doc["problems"] == [
        {"kind": "truncated", "path": "x.bag", "message": "x.bag: truncated"},
        {
            "kind": "missing-input",
            "path": None,
            "message": f"toy-gamma-20151120T100000: {gamma['reason']}",
        },
    ]
    for ident in LOGS:
        assert rows[ident]["rank_value"] == expected_value(ident)
    # the bar: 4 executions, the unscoreable one counted at once and named in the label
    assert progress.calls[0] == ("rescoring (1 not scored)", 4, "executions", 1)
    assert progress.calls[-1] == ("rescoring (1 not scored)", 4, "executions", 4)
    assert [c[3] for c in progress.calls] == [1, 2, 3, 4]


def test_ids_are_unique(tmp_path: Path) -> None:
    comp = make_competition(tmp_path / "comp")
    manifest = load_manifest(comp.manifest)
    twice = [*listed_executions(manifest)] * 2
    doc = rescore(twice, manifest, tmp_path / "out", reports=False)
    ids = [r["id"] for r in doc["executions"]]
    assert len(set(ids)) == 6
    assert "toy-alpha-20151120T091000-2" in ids


def test_leaderboard_ties_share_a_rank() -> None:
    def row(
        ident: str, team: str, value: float | None, status: str = "scored"
    ) -> dict[str, object]:
        return {
            "id": ident,
            "benchmark": "toy",
            "title": "Toy@Test",
            "team": team,
            "status": status,
            "rank_value": value,
        }

    rows = [
        row("a1", "a", 3.0),
        row("a2", "a", 1.0),
        row("b1", "b", 1.0),
        row("c1", "c", 2.0),
        row("d1", "d", None, "unscoreable"),
        row("e1", "e", 0.5, "failed"),
    ]
    (board,) = leaderboards(rows)
    assert [(r["rank"], r["team"], r["execution"]) for r in board["rows"]] == [
        (1, "a", "a2"),
        (1, "b", "b1"),
        (3, "c", "c1"),
    ]


def test_score_argv_is_the_score_command(tmp_path: Path) -> None:
    """The command line a report shows: the score command's own options, from the declarations
    (the team through FBM2H's own --team; a choice with its file as one option)."""

    bench = registry.get("toy")
    argv = score_argv(bench, [Path("a.txt")], {"scale": 2.0, "transform": Path("t.yaml")}, "x")
    assert argv == [
        "ertools",
        "score",
        "toy",
        "a.txt",
        "--transform",
        "t.yaml",
        "--scale",
        "2.0",
        "--team",
        "x",
    ]
    fbm2h = registry.load("ertools.benchmarks.fbm2h.declare:BENCHMARK")
    values = {"reached": ("timing", Path("t.yaml")), "team": "homer", "orientation_2015": True}
    assert score_argv(fbm2h, [Path("r.bag")], values, "homer") == [
        "ertools",
        "score",
        "fbm2h",
        "r.bag",
        "--team",
        "homer",
        "--reached",
        "timing",
        "t.yaml",
        "--orientation-2015",
    ]
