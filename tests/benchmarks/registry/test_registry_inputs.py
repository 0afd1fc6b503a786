"""Every declared input is an option of ``ertools score NAME`` and reaches the options.

A declaration is the single source of a benchmark's options: each :class:`Input` must show in
``--help``, parse back to the value given, and change what ``make_options`` returns (an input
that changes nothing would be an option that silently does nothing).
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

import pytest

from ertools.benchmarks import registry
from ertools.benchmarks.base import Input, resolve_values
from ertools.cli import score as score_cli
from ertools.cli.main import build_parser, main
from ertools.errors import UsageError

ITEMS = """\
items:
  - {id: 1, class: container, instance: can, transform: [[0, 0, 0], [0, 0, 0, 1]]}
"""
# Inputs whose value needs another to be valid (given together with them).
TOGETHER: dict[tuple[str, str], dict[str, Any]] = {
    ("trajectory", "ties"): {"association": "hold"},
    ("trajectory", "gt_order"): {"association": "hold", "ties": "before"},
    ("trajectory", "apply_offset"): {"offset": "auto"},
    ("trajectory", "t_max_diff"): {"association": "nearest"},
    ("fbm2h", "transforms"): {"team": "homer"},
}
# A value for the inputs whose kind alone does not say what a valid one is.
VALUES: dict[tuple[str, str], Any] = {
    ("fbm3w", "d_min_sweep"): "0.0001:0.0003:3",
    ("fbm3w", "run"): ("line:1:2:3",),
    ("fbm3w", "d_min"): 0.0005,
    ("trajectory", "offset"): "-0.25",
    ("trajectory", "ties"): "before",
    ("fbm2h", "reached"): ("timing", "timing.yaml"),
    ("fbm2h", "namespace"): "other",
    ("fbm1w", "rules"): "2015",  # no 2016-17 @Work node (refused below)
}


def _value(name: str, declared: Input, tmp_path: Path) -> Any:
    """A valid value other than the default."""
    if (name, declared.name) in VALUES:
        return VALUES[name, declared.name]
    if declared.name == "confidence":
        return 0.9  # a level: three times the default 0.95 is none (issue 28's --confidence)
    if declared.kind == "flag":
        return True
    if declared.kind == "choice":
        return [c for c in declared.choices if c != declared.default][-1]
    if declared.kind in ("float", "int"):
        base = declared.default if declared.default is not None else 1
        return type(base)(base * 3) if declared.kind == "float" else int(base) + 2
    if declared.kind == "path":
        path = tmp_path / f"{declared.name}.yaml"
        path.write_text(_file_text(name, declared.name), encoding="utf-8")
        return path
    return "some_value_3"


def _file_text(name: str, input_name: str) -> str:
    if input_name == "items":
        return ITEMS
    if input_name == "config":
        return "runs_specifications: [line]\n"
    if input_name == "runs_file":
        return "- {spec: line, reference: 1, start: 2, end: 3}\n"
    if input_name == "results":
        return "[]\n"
    return "{}\n"


def _base(name: str, tmp_path: Path) -> dict[str, Any]:
    """The values every make_options needs (FBM1's item list)."""
    bench = registry.get(name)
    if any(i.name == "items" for i in bench.inputs):
        items = tmp_path / "base_items.yaml"
        items.write_text(ITEMS, encoding="utf-8")
        return {"items": items}
    return {}


CASES = [
    (name, declared.name) for name in registry.names() for declared in registry.get(name).inputs
]


@pytest.mark.parametrize("name", registry.names())
def test_every_input_is_in_help(name: str) -> None:
    parser, _ = build_parser(f"ertools score {name}", "ertools.cli.score")
    text = parser.format_help()
    bench = registry.get(name)
    for declared in bench.inputs:
        assert declared.option in text, f"{name}: {declared.option} not in --help"
    assert bench.description.splitlines()[0] in text
    assert "examples:" in text


@pytest.mark.parametrize(("name", "input_name"), CASES, ids=[f"{n}-{i}" for n, i in CASES])
def test_every_input_parses_back_and_changes_the_options(
    name: str, input_name: str, tmp_path: Path
) -> None:
    bench = registry.get(name)
    declared = bench.input(input_name)
    base = _base(name, tmp_path)
    together = TOGETHER.get((name, input_name), {})
    value = _value(name, declared, tmp_path)
    # The command line gives the same value back (as make_options takes it).
    argv = ["run.bag", *_argv(declared, value)]
    for other, v in together.items():
        argv += _argv(bench.input(other), v)
    parser, _ = build_parser(f"ertools score {name}", "ertools.cli.score")
    values = score_cli._values(bench, parser.parse_args(argv))
    expected = resolve_values(bench.inputs, {input_name: value})[input_name]
    parsed = resolve_values(bench.inputs, {input_name: values[input_name]})[input_name]
    assert parsed == expected
    # ...and the value reaches the options.
    reference = bench.make_options({**base, **together})
    changed = bench.make_options({**base, **together, input_name: value})
    assert changed != reference, f"{name} {declared.option} {value!r} changes nothing"


def _argv(declared: Input, value: Any) -> list[str]:
    if declared.kind == "flag":
        return [declared.option]
    if declared.repeat:
        return [a for v in value for a in (declared.option, str(v))]
    if isinstance(value, tuple):
        return [declared.option, *map(str, value)]
    return [declared.option, str(value)]


@pytest.mark.parametrize(
    ("name", "values", "message"),
    [
        ("fbm3w", {"d_min": -0.001}, "--d-min must be >= 0 m, got -0.001"),
        ("fbm3w", {"d_min": 0.2}, "larger than 5 cm"),
        ("fbm3w", {"still_speed": 0.0}, "--still-speed must be positive"),
        ("fbm2h", {"gt_tolerance": -1}, "--gt-tolerance must be positive"),
        ("fbm2h", {"hits": 1.5}, "--hits must be a whole number"),
        ("fbm2h", {"reached": ("timing",)}, "--reached timing needs exactly one FILE"),
        ("trajectory", {"offset": "soon"}, "--offset takes seconds or 'auto'"),
        ("trajectory", {"association": "cubic"}, "choose from linear, nearest, hold"),
        ("trajectory", {"apply_offset": True}, "--apply-offset needs --offset auto"),
        ("fbm1w", {"rules": "2016"}, "--rules 2016"),
        ("fbm1h", {"no_such_input": 1}, "unknown input(s) no_such_input"),
    ],
)
def test_make_options_refuses_bad_values(
    name: str, values: dict[str, Any], message: str, tmp_path: Path
) -> None:
    with pytest.raises(UsageError, match=".*".join(map(_escape, message.split("*")))):
        registry.get(name).make_options({**_base(name, tmp_path), **values})


def _escape(text: str) -> str:
    return re.escape(text)


def test_d_min_negative_is_a_usage_error_on_the_command_line(
    capsys: pytest.CaptureFixture[str],
) -> None:
    """Issue 16: `--d-min -0.001` exits 2 (it used to be a config error, exit 1)."""

    assert main(["score", "fbm3w", "nonexistent.bag", "--d-min", "-0.001"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == ["ertools: error: --d-min must be >= 0 m, got -0.001"]
