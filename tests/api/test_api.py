"""The public Python API (ertools/api.py, docs/api.md): its examples run, the page is
generated from them, ``import ertools`` stays light, and each function answers as its command
does (same numbers, same errors)."""

from __future__ import annotations

import doctest
import importlib.util
import json
import re
import subprocess
import sys
from pathlib import Path

import pytest
import yaml

import ertools
from ertools import api
from ertools.benchmarks.document import score_json
from ertools.cli.main import main
from ertools.errors import BagError, ConfigError, TopicError, UsageError

ROOT = Path(__file__).resolve().parents[2]
SAMPLES = ROOT / "sample_bags"
FBM2H = SAMPLES / "fbm2h"
FBM2H_BAG = FBM2H / "log_fbm2h_mocap_2015-11-20-12-00-00_0.bag"
FBM3W_BAG = SAMPLES / "fbm3w" / "log_fbm3w_mocap_2015-11-20-12-00-00_0.bag"


def _build_api() -> object:
    spec = importlib.util.spec_from_file_location("build_api", ROOT / "docs" / "build_api.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.mark.slow
def test_every_example_runs(monkeypatch: pytest.MonkeyPatch) -> None:
    """The docstrings' examples, as doctests from the repository root (they read sample_bags/)."""
    monkeypatch.chdir(ROOT)
    results = doctest.testmod(api, optionflags=doctest.ELLIPSIS, verbose=False)
    assert results.failed == 0
    # every public function shows an example
    for name in ertools.API:
        assert ">>> " in (getattr(api, name).__doc__ or ""), name


def test_docs_api_md_is_generated_from_the_docstrings() -> None:
    build = _build_api()
    assert build.main(["--check"]) == 0, "run python docs/build_api.py"  # type: ignore[attr-defined]
    page = (ROOT / "docs" / "api.md").read_text(encoding="utf-8")
    for name in ertools.API:
        assert f"## `ertools.{name}`" in page
    # Markdown for users: no Sphinx role (:class:`...`) left as text
    assert not re.findall(r":[a-z]+:`", page)


@pytest.mark.slow
def test_import_ertools_is_light_and_names_resolve_on_use() -> None:
    code = (
        "import sys, ertools\n"
        "heavy = [m for m in ('numpy', 'pandas', 'ertools.api') if m in sys.modules]\n"
        "assert not heavy, heavy\n"
        "assert callable(ertools.score) and callable(ertools.audit)\n"
        "import ertools.auditing.model  # an internal package, its own name: the API's stays\n"
        "assert ertools.audit is ertools.api.audit and ertools.auditing.model.Audit\n"
        "print(sorted(set(ertools.API) & set(dir(ertools))) == sorted(ertools.API))\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "True"


def test_unknown_name_is_an_attribute_error() -> None:
    with pytest.raises(AttributeError, match="no attribute 'scores'"):
        _ = ertools.scores  # type: ignore[attr-defined]


def test_score_equals_the_command_and_the_samples_truth(
    capsys: pytest.CaptureFixture[str],
) -> None:
    goal, transform = FBM2H / "fbm2h_goal.yaml", FBM2H / "transform-simbot.yaml"
    result = ertools.score("fbm2h", str(FBM2H_BAG), goal=str(goal), transform=transform)
    argv = ["score", "fbm2h", str(FBM2H_BAG), "--goal", str(goal), "--transform", str(transform)]
    assert main([*argv, "--format", "json"]) == 0
    cli = json.loads(capsys.readouterr().out)
    assert json.loads(json.dumps(score_json(result))) == cli
    # the generator's truth (noiseless): 0.2 mm of mocap noise moves the mean by < 1 mm
    answers = yaml.safe_load(FBM2H_BAG.with_suffix(".answers.yaml").read_text())
    truth = answers["expected"]["position_accuracy"]
    assert result.to_dict()["position_accuracy"] == pytest.approx(truth, abs=1e-3)
    frames = result.to_frames()
    segments = frames["segments"]
    assert len(segments) == len(answers["truth"]["segments"]) == 5
    assert segments["distance_error_m"].mean() == pytest.approx(truth, abs=1e-3)


def test_score_options_by_keyword_with_choice_and_file() -> None:
    """``reached=("timing", FILE)`` is ``--reached timing FILE``; a flag is ``True``."""
    timing = FBM2H / "log_fbm2h_mocap_2015-11-20-12-00-00_0_reached_waypoint_timing.yaml"
    common = {"goal": FBM2H / "fbm2h_goal.yaml", "transform": FBM2H / "transform-simbot.yaml"}
    by_states = ertools.score("fbm2h", FBM2H_BAG, **common).to_dict()
    by_timing = ertools.score("fbm2h", FBM2H_BAG, reached=("timing", timing), **common)
    # the sample's timing file holds the same reached moments as its states (answers.yaml)
    assert by_timing.to_dict()["position_accuracy"] == pytest.approx(
        by_states["position_accuracy"], abs=1e-9
    )
    wrapped_2015 = ertools.score("fbm2h", FBM2H_BAG, orientation_2015=True, **common).to_dict()
    answers = yaml.safe_load(FBM2H_BAG.with_suffix(".answers.yaml").read_text())
    truth_2015 = answers["expected"]["orientation_accuracy_2015"]
    assert wrapped_2015["orientation_accuracy"] == pytest.approx(truth_2015, abs=2e-3)


@pytest.mark.parametrize(
    ("kwargs", "cli", "message"),
    [
        ({"d_min": -1.0}, ["--d-min", "-1"], "d-min"),
        ({"runs": "sideways"}, ["--runs", "sideways"], "sideways"),
    ],
)
def test_score_refuses_what_the_command_refuses(
    kwargs: dict[str, object], cli: list[str], message: str, capsys: pytest.CaptureFixture[str]
) -> None:
    with pytest.raises(UsageError) as raised:
        ertools.score("fbm3w", FBM3W_BAG, **kwargs)
    code = main(["score", "fbm3w", str(FBM3W_BAG), *cli])
    err = capsys.readouterr().err
    assert code == 2 and message in str(raised.value) and message in err


def test_score_errors_name_the_inputs() -> None:
    with pytest.raises(UsageError, match="fbm2h takes no input speed; its inputs: goal"):
        ertools.score("fbm2h", FBM2H_BAG, speed=1)
    with pytest.raises(UsageError, match=r"name='fbm4' \(str\): give the name of a benchmark"):
        ertools.score("fbm4", FBM2H_BAG)
    with pytest.raises(BagError, match=r"nope\.bag"):
        ertools.score("fbm3w", "nope.bag")


@pytest.mark.slow
def test_read_poses_topic_and_tf() -> None:
    poses = ertools.read_poses(FBM3W_BAG, topic="/fbm3w/robot_at_work/pose")
    with ertools.open_bag(FBM3W_BAG) as bag:
        count = len(list(bag.raw(bag.topic_conns("/fbm3w/robot_at_work/pose"))))
    assert len(poses) == count  # every message, one pose each
    with pytest.raises(UsageError, match="one of them"):
        ertools.read_poses(FBM3W_BAG)
    with pytest.raises(TopicError):
        ertools.read_poses(FBM3W_BAG, tf="world:nothing_here")


@pytest.mark.slow
def test_export_writes_what_the_command_writes(tmp_path: Path) -> None:
    out = tmp_path / "api.tum"
    text = ertools.export(FBM3W_BAG, topic="/fbm3w/robot_at_work/pose", out=out)
    assert main(["export", str(FBM3W_BAG), "--topic", "/fbm3w/robot_at_work/pose",
                 "-o", str(tmp_path / "cli.tum")]) == 0  # fmt: skip
    assert out.read_text() == text == (tmp_path / "cli.tum").read_text()
    with pytest.raises(UsageError, match="never overwrites its inputs"):
        ertools.export(FBM3W_BAG, topic="/fbm3w/robot_at_work/pose", out=FBM3W_BAG)


@pytest.mark.slow
def test_audit_and_timeline() -> None:
    audited = ertools.audit(FBM2H_BAG, goal=FBM2H / "fbm2h_goal.yaml", speed=3)
    assert audited.benchmark == "fbm2h" and audited.recomputed is not None
    assert any("--speed is not used by fbm2h" in w for w in audited.warnings)
    t = ertools.timeline(SAMPLES / "fbm3w")
    # the ROS1 log and its MCAP copy: one recording in two files
    assert len(t.bags) == 2
    assert [len(f.axes) > 0 for f in ertools.figures(audited)][:1] == [True]


def test_rescore_names_every_manifest_problem(tmp_path: Path) -> None:
    manifest = tmp_path / "competition.yaml"
    manifest.write_text("benchmarks:\n  fbm9: {}\n  fbm8: {}\n", encoding="utf-8")
    with pytest.raises(ConfigError, match="2 problem") as raised:
        ertools.rescore([], config=manifest, out=tmp_path / "out")
    assert "'fbm9'" in str(raised.value) and "'fbm8'" in str(raised.value)
    assert not (tmp_path / "out").exists()  # nothing scored, nothing written
