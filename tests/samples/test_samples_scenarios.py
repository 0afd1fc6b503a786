"""Scenarios: the stationary log's answers hold for the bag, regeneration reproduces the
committed samples (byte for byte, but for the last bits of floating-point maths)."""

from __future__ import annotations

import dataclasses
import math
import os
import subprocess
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml
from rosbags.highlevel import AnyReader

from ertools.benchmarks import registry
from ertools.samples import scenario
from ertools.samples.__main__ import main
from ertools.samples.scenario import ScenarioMissingError, load_scenario, scenarios, seed_of
from ertools.simulator.answers import (
    RunAnswers,
    answers_path,
    log_name,
    read_answers,
    write_layout_answers,
)
from tests.helpers.floats import FLOAT_ATOL, FLOAT_RTOL, same_text

REPO = Path(__file__).resolve().parents[2]
SAMPLE_BAGS = REPO / "sample_bags"


def _files(root: Path) -> dict[str, bytes]:
    return {
        str(p.relative_to(root)): p.read_bytes()
        for p in sorted(root.rglob("*"))
        if p.is_file() and p.name != "README.md"
    }


@pytest.mark.slow
def test_stationary_answers_match_the_bag(tmp_path: Path) -> None:
    paths = load_scenario("stationary")(tmp_path, seed=11)
    bag = next(p for p in paths if p.suffix == ".bag")
    answers = yaml.safe_load(answers_path(bag).read_text())
    assert answers_path(bag) in paths
    assert list(answers) == ["benchmark", "bag", "generator", "truth", "expected", "tolerance"]
    assert answers["bag"] == bag.name and answers["generator"]["seed"] == 11
    topic = answers["generator"]["parameters"]["topic"]
    xyz = []
    with AnyReader([bag]) as reader:
        conns = [c for c in reader.connections if c.topic == topic]
        for _, _, raw in reader.messages(connections=conns):
            p = reader.deserialize(raw, "geometry_msgs/msg/PoseStamped").pose.position
            xyz.append((p.x, p.y, p.z))
    pos = np.array(xyz)
    exp, tol = answers["expected"], answers["tolerance"]
    assert len(pos) == exp["samples"]
    d = np.diff(pos, axis=0)
    moved = np.any(d != 0, axis=1)
    assert int((~moved).sum()) == exp["repeats"] == 3 + 5 + 4  # the scenario's LOSSES
    assert exp["dropped"] == 12 + 30
    epsilon = float(np.linalg.norm(d[moved], axis=1).mean())
    assert epsilon == pytest.approx(exp["epsilon"], abs=tol["epsilon"]["abs"])
    # The formula 4*sigma/sqrt(pi), written out here independently of the scenario.
    sigma = answers["generator"]["parameters"]["sigma_m"]
    assert exp["epsilon_formula"] == pytest.approx(4 * sigma / math.sqrt(math.pi), rel=1e-12)
    assert epsilon == pytest.approx(exp["epsilon_formula"], abs=tol["epsilon_formula"]["abs"])
    # The 2015 tool's (x, y) distance; chi-2 mean sqrt(pi/2) -> sigma*sqrt(pi).
    eps_xy = float(np.hypot(d[moved, 0], d[moved, 1]).mean())
    assert eps_xy == pytest.approx(exp["epsilon_xy"], abs=1e-12)
    assert exp["epsilon_xy_formula"] == pytest.approx(sigma * math.sqrt(math.pi), rel=1e-12)
    assert eps_xy == pytest.approx(exp["epsilon_xy_formula"], abs=tol["epsilon_xy_formula"]["abs"])
    assert exp["lost"] == exp["repeats"] and exp["pairs"] == len(pos) - 1
    assert pos.std(axis=0, ddof=1) == pytest.approx(exp["sigma_xyz"], abs=1e-12)
    truth = np.array(answers["truth"]["position"])
    assert np.all(np.abs(pos.mean(axis=0) - truth) < tol["mean_position_vs_truth"]["abs"])
    w = answers["truth"]["window"]
    assert w["start"] == pytest.approx(w["start_ns"] / 1e9) and w["end_ns"] > w["start_ns"]
    assert bag.stat().st_size < 2_600_000


@pytest.mark.slow
def test_stationary_is_byte_identical_on_rerun(tmp_path: Path) -> None:
    assert main([str(tmp_path / "a"), "--only", "stationary"]) == 0
    assert main([str(tmp_path / "b"), "--only", "stationary"]) == 0
    a, b = _files(tmp_path / "a"), _files(tmp_path / "b")
    assert len(a) == 2 and a == b
    # A different seed changes the noise, so the comparison above can fail.
    assert main([str(tmp_path / "c"), "--only", "stationary", "--seed", "3"]) == 0
    assert _files(tmp_path / "c") != a


@pytest.mark.slow
def test_rerun_replaces_a_scenario_folder(tmp_path: Path) -> None:
    assert main([str(tmp_path), "--only", "stationary"]) == 0
    (tmp_path / "stationary" / "stale.txt").write_text("old")
    assert main([str(tmp_path), "--only", "stationary"]) == 0
    assert not (tmp_path / "stationary" / "stale.txt").exists()
    assert not list(tmp_path.glob(".*partial"))


def test_an_unknown_scenario_is_an_error_naming_it(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    with pytest.raises(ScenarioMissingError, match=r"'ghost'.*stationary"):
        load_scenario("ghost")
    with pytest.raises(SystemExit) as exit_:
        main([str(tmp_path / "x"), "--only", "ghost", "stationary"])
    assert exit_.value.code == 2  # argparse: not one of the choices
    assert "ghost" in capsys.readouterr().err
    assert not (tmp_path / "x").exists()  # nothing written


def test_the_scenarios_are_the_benchmarks_then_the_samples_own() -> None:
    """Each benchmark's scenario comes through the registry (fbm1's under fbm1h, the
    trajectory's under robotlog, noise's under stationary), the two of no benchmark last; the
    seeds are those sample_bags/ was written with (its answers files say which)."""
    names = list(scenarios())
    assert names[-2:] == ["timeline", "season2019"]
    assert {"fbm1h", "fbm2h", "fbm3w", "robotlog", "stationary"} <= set(names[:-2])
    declared = {s.folder for s in registry.scenarios() if s.seed}  # each benchmark's own
    assert set(names) == set(scenario.SEEDS) | declared
    assert not declared & set(scenario.SEEDS)
    for name in names:
        if name == "timeline":  # fixed values, no draw: its generate() ignores the seed
            continue
        beside = answers_path(SAMPLE_BAGS / name)  # a folder's own answers (the season's)
        found = sorted((SAMPLE_BAGS / name).rglob("*answers.yaml"))
        for answers in found + ([beside] if beside.exists() else []):
            said = yaml.safe_load(answers.read_text(encoding="utf-8"))["generator"]["seed"]
            assert said == seed_of(name), answers
    assert seed_of("newbench") == seed_of("newbench") != seed_of("newbench2")


def test_log_name_is_the_2015_logger_pattern() -> None:
    assert (
        log_name("fbm3w_mocap", 1_448_013_600 * 10**9)
        == "log_fbm3w_mocap_2015-11-20-10-00-00_0.bag"
    )
    assert answers_path(Path("d/x.bag")) == Path("d/x.answers.yaml")
    assert answers_path(Path("d/x_rosbag2")) == Path("d/x_rosbag2.answers.yaml")


def test_a_layouts_answers_are_beside_it_and_read_per_run(tmp_path: Path) -> None:
    folder = tmp_path / "hnf"
    bags = [folder / f"rsbb_logs/HNF/simbot/run_{n}_x.bag" for n in (1, 2)]
    runs = [
        RunAnswers(bag, parameters={"run": n}, truth={}, expected={"n": n}, tolerance={})
        for n, bag in enumerate(bags, 1)
    ]
    out = write_layout_answers(folder, runs, benchmark="hnf", scenario="hnf", seed=5)
    assert out == tmp_path / "hnf.answers.yaml" and not folder.exists()  # nothing in it
    doc = yaml.safe_load(out.read_text(encoding="utf-8"))
    assert list(doc) == ["benchmark", "bag", "generator", "runs"]
    assert doc["bag"] == [f"rsbb_logs/HNF/simbot/run_{n}_x.bag" for n in (1, 2)]
    # a run's answers in a log's own shape, wherever the bag is given from
    assert read_answers(bags[1]) == {
        "benchmark": "hnf",
        "bag": "rsbb_logs/HNF/simbot/run_2_x.bag",
        "generator": {"scenario": "hnf", "seed": 5, "parameters": {"run": 2}},
        "truth": {},
        "expected": {"n": 2},
        "tolerance": {},
    }
    with pytest.raises(FileNotFoundError, match=r"run_3_x\.bag: no answers file"):
        read_answers(bags[0].with_name("run_3_x.bag"))


def _close(a: Any, b: Any, where: str) -> list[str]:
    """Where two decoded values differ beyond float rounding (recursing into containers)."""
    if isinstance(a, str) and isinstance(b, str):
        return [] if a == b or same_text(a, b) else [where]
    if isinstance(a, float) and isinstance(b, float):
        return [] if math.isclose(a, b, rel_tol=FLOAT_RTOL, abs_tol=FLOAT_ATOL) else [where]
    if isinstance(a, np.ndarray) and isinstance(b, np.ndarray):
        if a.shape != b.shape or a.dtype != b.dtype:
            return [where]
        if a.dtype.kind == "f":
            ok = np.allclose(a, b, rtol=FLOAT_RTOL, atol=FLOAT_ATOL, equal_nan=True)
        else:
            ok = np.array_equal(a, b)
        return [] if ok else [where]
    if isinstance(a, dict) and isinstance(b, dict):
        if sorted(a) != sorted(b):
            return [where]
        return [d for k in a for d in _close(a[k], b[k], f"{where}.{k}")]
    if isinstance(a, list | tuple) and isinstance(b, list | tuple):
        if len(a) != len(b):
            return [where]
        return [
            d
            for i, (x, y) in enumerate(zip(a, b, strict=True))
            for d in _close(x, y, f"{where}[{i}]")
        ]
    # (each reader generates its own message classes: same name, not the same class)
    if dataclasses.is_dataclass(a) and type(a).__name__ == type(b).__name__:
        return [
            d
            for f in dataclasses.fields(a)
            for d in _close(getattr(a, f.name), getattr(b, f.name), f"{where}.{f.name}")
        ]
    return [] if a == b else [where]


def _bag_differences(committed: Path, fresh: Path) -> list[str]:
    """Messages of two bags that differ beyond float rounding: same connections, counts,
    record times and bytes, except float fields within FLOAT_RTOL (decoded by rosbags)."""

    with AnyReader([committed]) as ra, AnyReader([fresh]) as rb:
        conns_a = [(c.topic, c.msgtype, c.msgcount) for c in ra.connections]
        conns_b = [(c.topic, c.msgtype, c.msgcount) for c in rb.connections]
        if conns_a != conns_b:
            return [f"connections {conns_a} != {conns_b}"]
        out: list[str] = []
        for (ca, ta, da), (cb, tb, db) in zip(ra.messages(), rb.messages(), strict=True):
            where = f"{ca.topic}@{ta}"
            if (ca.topic, ta) != (cb.topic, tb):
                out.append(where)
            elif da != db:
                out += _close(ra.deserialize(da, ca.msgtype), rb.deserialize(db, cb.msgtype), where)
            if len(out) > 5:
                break
        return out


def _differences(
    name: str, committed: bytes, fresh: bytes, root_a: Path, root_b: Path
) -> list[str]:
    if committed == fresh:
        return []
    if name.endswith(".yaml"):
        found = _close(yaml.safe_load(committed), yaml.safe_load(fresh), name)
    elif name.endswith((".bag", ".mcap")):
        bag = name if name.endswith(".bag") else str(Path(name).parent)
        found = [f"{name}: {d}" for d in _bag_differences(root_a / bag, root_b / bag)]
    else:
        found = [name]
    return found


@pytest.mark.slow
def test_sample_bags_folder_regenerates_but_for_float_rounding(tmp_path: Path) -> None:
    assert SAMPLE_BAGS.is_dir(), "sample_bags/ missing: run python -m ertools.samples sample_bags"
    # In a subprocess with a fixed string-hash seed other than the one that made sample_bags/:
    # output that depended on set/dict order of strings would differ.
    env = {**os.environ, "PYTHONHASHSEED": "12345"}
    proc = subprocess.run(
        [sys.executable, "-m", "ertools.samples", str(tmp_path)],
        env=env,
        capture_output=True,
        text=True,
        check=False,
        timeout=120,
    )
    assert proc.returncode == 0, proc.stderr
    committed, fresh = _files(SAMPLE_BAGS), _files(tmp_path)
    assert sorted(committed) == sorted(fresh)
    differ = [
        d
        for name in fresh
        for d in _differences(name, committed[name], fresh[name], SAMPLE_BAGS, tmp_path)
    ]
    assert not differ, f"regenerated files differ from sample_bags/: {differ[:10]}"
    total = sum(len(b) for b in fresh.values())
    # the budget of sample_bags/README.md (~17 MB): the 2015 logs and one RSBB sample per
    # 2017-19 benchmark plus a season folder (issue 38), each RSBB bag bz2-compressed
    assert total < 17_000_000, f"sample_bags/ is {total} bytes"
