"""Wrong types given to the public API (issue 36, finding 19): every parameter of every function
of ertools/api.py, and every benchmark input taken by keyword, refuses a value of the wrong type
with a UsageError naming the parameter, before anything is read; never a raw TypeError,
IndexError or ValueError from deep inside, and never a quiet answer (``timeline({'a': 1})``).

The table is checked against the functions' signatures: a parameter added to the API without a
row here fails the test."""

from __future__ import annotations

import inspect
import math
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

import ertools
from ertools import api
from ertools.benchmarks import registry
from ertools.errors import UsageError

ROOT = Path(__file__).resolve().parents[2]
BAG = str(ROOT / "sample_bags" / "fbm3w" / "log_fbm3w_mocap_2015-11-20-12-00-00_0.bag")


class Thing:
    """An object of no type the API knows."""


PATH_WRONG = [b"run.bag", {"a": 1}, 123, 2.5, True, Thing(), "", ["run.bag"]]
PATHS_WRONG = [b"run.bag", {"a": 1}, 123, Thing(), "", [b"run.bag"], ["run.bag", 3], ("",)]
TEXT_WRONG = [b"/x", {"a": 1}, 123, ("a",), Thing(), ""]
BOOL_WRONG = [1, "yes", None, {"a": 1}, Thing(), 0.0]

# parameter -> values of the wrong type (or shape) for it
WRONG: dict[str, list[Any]] = {
    "path": PATH_WRONG,
    "paths": PATHS_WRONG,
    "bags": PATHS_WRONG,
    "topic": TEXT_WRONG,
    "tf": [b"a:b", {"a": 1}, 123, ("a",), ("a", "b", "c"), ("a", 1), "ab", ":b", Thing()],
    "time_source": ["clock", b"header", 1, {"a": 1}, Thing(), None],
    "name": [b"fbm3w", {"a": 1}, 123, ["fbm3w"], Thing(), "", "fbm9x"],
    "benchmark": TEXT_WRONG,
    "recompute": BOOL_WRONG,
    "check_clocks": BOOL_WRONG,
    "reports": BOOL_WRONG,
    "use_cache": BOOL_WRONG,
    "result": [{"a": 1}, "result.json", 123, None, Thing(), [1, 2]],
    "format": ["evo", b"tum", 1, {"a": 1}, None, Thing()],
    "out": PATH_WRONG,
    "config": PATH_WRONG,
    "jobs": [0, -1, 1.5, "2", True, None, {"a": 1}, math.nan],
}

# valid values for every parameter (the call is refused before any is used)
VALID: dict[str, Any] = {
    "path": BAG,
    "paths": [BAG],
    "bags": BAG,
    "topic": "/fbm3w/robot_at_work/pose",
    "time_source": "header",
    "name": "fbm3w",
    "format": "tum",
    "config": "competition.yaml",
    "out": "results",
}


def _call(function: Callable[..., Any], name: str, value: Any) -> None:
    """``function`` with valid values for its required parameters and ``value`` for ``name``."""
    signature = inspect.signature(function)
    kwargs = {
        p.name: VALID[p.name]
        for p in signature.parameters.values()
        if p.default is inspect.Parameter.empty and p.kind is not p.VAR_KEYWORD and p.name != name
    }
    kwargs[name] = value
    function(**kwargs)


def _parameters() -> list[tuple[str, str]]:
    return [
        (function, parameter.name)
        for function in ertools.API
        for parameter in inspect.signature(getattr(api, function)).parameters.values()
        if parameter.kind is not parameter.VAR_KEYWORD
    ]


def test_every_parameter_has_a_row() -> None:
    assert sorted({name for _, name in _parameters()}) == sorted(WRONG)


CASES = [
    pytest.param(function, name, value, id=f"{function}-{name}-{i}")
    for function, name in _parameters()
    for i, value in enumerate(WRONG[name])
]


@pytest.mark.parametrize(("function", "name", "value"), CASES)
def test_a_wrong_type_is_a_usage_error_naming_the_parameter(
    function: str, name: str, value: Any, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(tmp_path)  # nothing may be written, but never in the repository
    with pytest.raises(UsageError) as refused:
        _call(getattr(api, function), name, value)
    assert f"{name}=" in str(refused.value), str(refused.value)
    assert "\n" not in str(refused.value)


def test_positional_and_unknown_arguments() -> None:
    with pytest.raises(UsageError, match="info"):
        api.info()  # type: ignore[call-arg]
    with pytest.raises(UsageError, match="speed"):
        api.timeline(BAG, speed=2)  # type: ignore[call-arg]
    with pytest.raises(UsageError, match="read_poses: too many positional arguments"):
        api.read_poses(BAG, "/fbm3w/robot_at_work/pose")  # type: ignore[misc]


# a benchmark input's kind -> values of the wrong type for it
INPUT_WRONG: dict[str, list[Any]] = {
    "path": [b"x.yaml", {"a": 1}, 123, "", Thing(), ["x.yaml"]],
    "paths": [b"x.yaml", {"a": 1}, 123, "", [1], Thing()],
    "float": ["0.5", b"1", {"a": 1}, True, [0.5], Thing(), 1 + 2j],
    "int": ["3", 2.5, True, {"a": 1}, [3], Thing()],
    "str": [123, b"x", {"a": 1}, ["x"], Thing()],
    "choice": [123, "no-such-choice", b"x", {"a": 1}, Thing()],
    "flag": ["yes", 1, {"a": 1}, Thing()],
}


def _inputs() -> list[Any]:
    cases = []
    for name in registry.names():
        for declared in registry.get(name).inputs:
            wrong = INPUT_WRONG[declared.kind]
            if declared.repeat:  # one value or a list of them: a list of wrong ones
                wrong = [v for v in wrong if not isinstance(v, list)]
                wrong += [[w] for w in wrong]
            for i, value in enumerate(wrong):
                ident = f"{name}-{declared.name}-{i}"
                cases.append(pytest.param(name, declared.name, value, id=ident))
    return cases


@pytest.mark.parametrize(("benchmark", "name", "value"), _inputs())
def test_a_benchmark_input_of_the_wrong_type_is_a_usage_error(
    benchmark: str, name: str, value: Any, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """``score`` and ``audit`` take the benchmark's inputs by keyword: ``config=dict`` is
    refused naming ``config``, as ``--config`` would be by the command line."""
    monkeypatch.chdir(tmp_path)
    with pytest.raises(UsageError) as refused:
        api.score(benchmark, BAG, **{name: value})
    assert f"{name}=" in str(refused.value), str(refused.value)
    with pytest.raises(UsageError) as refused:
        api.audit(BAG, benchmark=benchmark, **{name: value})
    assert f"{name}=" in str(refused.value), str(refused.value)
