"""The score layout of seed Listing 16, against golden files (regen_golden.py rewrites them)."""

from __future__ import annotations

import json
import re
from pathlib import Path
from typing import Any

import pytest
import yaml

from ertools.cli.output import dump_json
from tests.benchmarks.fbm3w.golden_case import golden_result
from tests.helpers.floats import YAML_UNIT, tree_difference

GOLDEN = Path(__file__).resolve().parent / "golden"
NUMBER = re.compile(r"-?\d+\.\d+(e-?\d+)?")


# Each YAML value is its float rounded to 9 decimals: at most half a step away.
YAML_ROUNDING = 5e-10 + 1e-15


def _close(a: Any, b: Any, path: str, tol: float) -> None:
    """Same nesting and key order; numbers equal within ``tol`` (float formatting may differ)."""
    assert type(a) is type(b) or {type(a), type(b)} <= {int, float}, path
    if isinstance(a, dict):
        assert list(a) == list(b), path
        for key in a:
            _close(a[key], b[key], f"{path}.{key}", tol)
    elif isinstance(a, list):
        assert len(a) == len(b), path
        for i, (x, y) in enumerate(zip(a, b, strict=True)):
            _close(x, y, f"{path}[{i}]", tol)
    elif isinstance(a, float):
        assert a == pytest.approx(b, abs=tol), path
    else:
        assert a == b, path


def test_yaml_matches_golden() -> None:
    text = golden_result().to_yaml()
    golden = (GOLDEN / "score.yaml").read_text(encoding="utf-8")
    # the text layout (keys, nesting, nulls, lists) is identical; digits may differ in the
    # last place between NumPy/libm builds, so numbers are compared as values
    assert NUMBER.sub("<n>", text) == NUMBER.sub("<n>", golden)
    # each value within what its quantity may move between CPUs, and one in the ninth
    # decimal (tests/helpers/floats.py: a value on a rounding boundary rounds either way)
    where = tree_difference(yaml.safe_load(text), yaml.safe_load(golden), rounded=YAML_UNIT)
    assert where is None, where
    # the YAML is the full-precision JSON rounded to 9 decimals, and nothing coarser
    as_json = json.loads(dump_json(golden_result().to_dict()))
    as_json["runs_details"] = {int(k): v for k, v in as_json["runs_details"].items()}
    _close(yaml.safe_load(text), as_json, "", YAML_ROUNDING)
    best = as_json["best_distance_error"]  # 0.0005436324173035626
    assert f"best_distance_error: {round(best, 9)!r}\n" in text and len(repr(best)) > 12


def test_json_matches_golden() -> None:
    data = json.loads(dump_json(golden_result().to_dict()))
    # every bit of the float64: within what each quantity may move between CPUs (floats.py)
    where = tree_difference(data, json.loads((GOLDEN / "score.json").read_text(encoding="utf-8")))
    assert where is None, where


def test_listing_16_keys() -> None:
    score = yaml.safe_load((GOLDEN / "score.yaml").read_text(encoding="utf-8"))
    assert list(score) == ["best_distance_error", "best_run", "execution_time", "runs_details"]
    assert list(score["runs_details"]) == [0, 1, 2]  # integer run indices, as 2015's yaml.dump
    for run in score["runs_details"].values():
        assert list(run)[:3] == ["spec", "distance_error", "execution_time"]
    data = json.loads((GOLDEN / "score.json").read_text(encoding="utf-8"))
    assert list(data["runs_details"]) == ["0", "1", "2"]  # JSON: string keys
    # best = the smaller error; execution_time = sum of the runs, the timed-out one included
    details = score["runs_details"]
    assert score["best_run"] == 1
    assert score["best_distance_error"] == details[1]["distance_error"]
    assert score["execution_time"] == pytest.approx(
        sum(r["execution_time"] for r in details.values()), abs=1e-9
    )
    assert details[2]["status"] == "timeout"
    assert details[2]["distance_error"] is None
