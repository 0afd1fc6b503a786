"""The competition manifest: safe-loaded, validated, every problem listed at once."""

from __future__ import annotations

from pathlib import Path

import pytest

from ertools.benchmarks import registry
from ertools.cli.main import main
from ertools.competition.manifest import ManifestError, load_manifest
from ertools.errors import ConfigError
from tests.helpers.stderr_text import joined_lines
from tests.rescore.rescore_competition import make_competition, use_toy_registry


@pytest.fixture(autouse=True)
def _toy(monkeypatch: pytest.MonkeyPatch) -> None:
    use_toy_registry(monkeypatch)


def test_values_are_converted_and_resolved(tmp_path: Path) -> None:
    comp = make_competition(tmp_path / "comp")
    manifest = load_manifest(comp.manifest)
    assert manifest.title == "Toy Cup"
    entry = manifest.benchmarks["toy"]
    assert entry.values == {"scale": 2.0}
    assert entry.teams["beta"] == {"transform": comp.transform("beta")}
    assert comp.transform("beta").is_absolute()
    first = manifest.executions[0]
    assert first.bags == (comp.log("toy-alpha-20151120T091000"),)
    assert first.start_ns == 1448010600 * 10**9  # 2015-11-20T09:10:00Z by hand
    values, missing = manifest.values_for("toy", "beta", {"mode": "max"})
    assert values == {"scale": 2.0, "transform": comp.transform("beta"), "mode": "max"}
    assert missing == []
    # a team the manifest does not know has no transform: the execution is unscoreable
    _, missing = manifest.values_for("toy", "gamma")
    assert missing == [
        "toy: no transform for team gamma in the manifest (benchmarks.toy.teams.gamma.transform)"
    ]


BROKEN = """\
version: 1
venue: Lisbon
benchmarks:
  toy:
    inputs:
      scale: fast
      mode: median
      colour: red
    teams:
      alpha: {transform: configs/transform-alpha.yaml, scale: 3.0}
      beta: {transform: configs/nowhere.yaml}
      gamma: {}
  fbm9x:
    inputs: {}
executions:
  - benchmark: toy
    team: alpha
    bags: [logs/missing.txt]
    start: yesterday
    extra: 1
  - team: alpha
"""

EXPECTED = [
    "venue: unknown key (known: version, title, benchmarks, executions)",
    "benchmarks.toy.inputs.scale: expected a number, got str 'fast'",
    "benchmarks.toy.inputs.mode: 'median' is not one of mean, max",
    "benchmarks.toy.inputs.colour: not an input of toy (its inputs: transform, scale, mode)",
    "benchmarks.toy.teams.alpha.scale: not a per-team input of toy (set it under "
    "benchmarks.toy.inputs; per-team: transform)",
    "benchmarks.toy.teams.beta.transform: file not found: {root}/configs/nowhere.yaml",
    "benchmarks.fbm9x: unknown benchmark 'fbm9x' (one of toy)",
    "executions[0].extra: unknown key (known: benchmark, team, bags, start, end, inputs)",
    "executions[0].bags: file not found: {root}/logs/missing.txt",
    "executions[0].start: 'yesterday' is not an ISO 8601 time (2015-11-20T12:31:05Z)",
    "executions[1]: missing key 'benchmark'",
    "executions[1]: missing key 'bags'",
    "benchmarks.toy.teams.beta: no transform for team beta in the manifest "
    "(benchmarks.toy.teams.beta.transform)",
    "benchmarks.toy.teams.gamma: no transform for team gamma in the manifest "
    "(benchmarks.toy.teams.gamma.transform)",
]


def test_every_problem_at_once(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    comp = make_competition(tmp_path / "comp")
    comp.manifest.write_text(BROKEN)
    root = str(comp.root.resolve())
    expected = [line.format(root=root) for line in EXPECTED]
    with pytest.raises(ManifestError) as caught:
        load_manifest(comp.manifest)
    assert sorted(caught.value.problems) == sorted(expected)
    # the command: one line each, nothing scored, exit 1
    code = main(["rescore", "--config", str(comp.manifest), "--out", str(tmp_path / "out")])
    assert code == 1
    lines = joined_lines(capsys.readouterr().err)
    assert sorted(lines[:-1]) == sorted(f"ertools: error: {comp.manifest}: {p}" for p in expected)
    assert lines[-1] == f"ertools: error: 14 problem(s) in {comp.manifest}; nothing was scored"
    assert not (tmp_path / "out").exists()


def test_check_only_validates(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    comp = make_competition(tmp_path / "comp")
    assert main(["rescore", "--config", str(comp.manifest), "--check"]) == 0
    assert "no problems (3 listed executions)" in capsys.readouterr().err


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("benchmarks: [1, 2\n", "malformed manifest at line 2"),
        ("!!python/object/apply:os.system ['true']\n", "malformed manifest"),  # safe-loaded
        ("- just\n- a list\n", "the manifest: expected a mapping, got list"),
        ("version: 2\n", "version: 2: this ertools reads manifest version 1"),
    ],
)
def test_malformed_manifests(tmp_path: Path, text: str, message: str) -> None:
    path = tmp_path / "competition.yaml"
    path.write_text(text)
    with pytest.raises(ConfigError, match=message):
        load_manifest(path)


def test_missing_manifest_is_one_line(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code = main(["rescore", "--config", str(tmp_path / "no.yaml"), "--out", str(tmp_path / "o")])
    assert code == 1
    assert (
        capsys.readouterr().err == f"ertools: error: {tmp_path / 'no.yaml'}: manifest not found\n"
    )


def test_a_choice_that_takes_a_file(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """FBM2H's `--reached timing FILE`: `[timing, FILE]` in a manifest, the file checked."""

    fbm2h = registry.Entry("fbm2h", ".fbm2h.declare", "FBM2@Home")  # besides the toy's
    monkeypatch.setattr(registry, "ENTRIES", (fbm2h,))
    (tmp_path / "timing.yaml").write_text("[]\n")
    path = tmp_path / "competition.yaml"
    path.write_text("benchmarks:\n  fbm2h:\n    inputs: {reached: [timing, timing.yaml]}\n")
    assert load_manifest(path).benchmarks["fbm2h"].values == {
        "reached": ("timing", tmp_path / "timing.yaml")
    }
    path.write_text("benchmarks:\n  fbm2h:\n    inputs: {reached: states}\n")
    assert load_manifest(path).benchmarks["fbm2h"].values == {"reached": ("states",)}
    for bad in ("[timing]", "[states, timing.yaml]", "sometimes", "[timing, nowhere.yaml]"):
        path.write_text(f"benchmarks:\n  fbm2h:\n    inputs: {{reached: {bad}}}\n")
        with pytest.raises(ManifestError) as caught:
            load_manifest(path)
        (problem,) = caught.value.problems
        assert problem.startswith("benchmarks.fbm2h.inputs.reached: ")
        if bad == "[timing, nowhere.yaml]":
            assert problem.endswith(f"file not found: {tmp_path / 'nowhere.yaml'}")
        else:
            assert "expected states | [timing, FILE] | auto" in problem
