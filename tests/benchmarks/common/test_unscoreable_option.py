"""One option scores unscoreable runs as 2015 did: ``--unscoreable 2015`` (manifest key and
keyword ``unscoreable``) in every benchmark, declared once
(:data:`ertools.benchmarks.common.validity.UNSCOREABLE`). Each benchmark's former spelling
gives the options the new one gives, with one deprecation line naming the new spelling; and
the options it gives score an unscoreable run as 2015 did where the default does not
(tests/benchmarks/fbm3w/test_fbm3w_validity.py scores one under both spellings)."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

import pytest

from ertools.api import _values as api_values
from ertools.benchmarks import registry
from ertools.benchmarks.common.inputs import UNSCOREABLE
from ertools.cli import score as score_cli
from ertools.cli.main import build_parser
from ertools.competition.manifest import load_manifest

# what each benchmark needs besides the option (make_options reads no file)
# The 2015 benchmarks (their unscoreable GT has a 2015 reading); the RSBB ones have no such
# option: their scripts read tf, whose interpolation is their own rule (hnf.gt-gaps).
WITH_2015 = [n for n in registry.names() if any(r.season == "2015" for r in registry.get(n).rules)]
REQUIRED = {"fbm1h": ["--items", "items.yaml"], "fbm1w": ["--items", "items.yaml"]}
# benchmark -> (former spelling on the command line, former manifest key, its value there)
FORMER = {
    "fbm1h": (["--score-unscoreable"], "score_unscoreable", True),
    "fbm1w": (["--score-unscoreable"], "score_unscoreable", True),
    "fbm2h": (["--unscoreable-segments", "2015"], "unscoreable_segments", "2015"),
    "fbm3w": (["--unscoreable-runs", "2015"], "unscoreable_runs", "2015"),
}
NOTE = "ertools: note: {old} is deprecated, use --unscoreable 2015"


def _options(name: str, argv: list[str]) -> Any:
    parser, _ = build_parser(f"ertools score {name}", "ertools.cli.score")
    args: argparse.Namespace = parser.parse_args(["log.bag", *REQUIRED.get(name, []), *argv])
    bench = registry.get(name)
    return bench.make_options(score_cli._values(bench, args))


@pytest.mark.parametrize("name", WITH_2015)
def test_every_benchmark_declares_the_one_option(name: str) -> None:
    (declared,) = [i for i in registry.get(name).inputs if i.name == "unscoreable"]
    assert (declared.option, declared.help, declared.choices) == (
        "--unscoreable",
        UNSCOREABLE.help,
        ("null", "2015"),
    )
    # no other input of the benchmark says "unscoreable" in its name
    assert [i.name for i in registry.get(name).inputs if "unscoreable" in i.name] == ["unscoreable"]


@pytest.mark.parametrize("name", WITH_2015)
def test_the_new_spelling_changes_the_options_and_2015_implies_it(
    name: str, capsys: pytest.CaptureFixture[str]
) -> None:
    default = _options(name, [])
    null = _options(name, ["--unscoreable", "null"])
    new = _options(name, ["--unscoreable", "2015"])
    assert capsys.readouterr().err == ""
    assert null == default
    assert new != default
    # --2015 (--rules 2015 in FBM1) scores them as 2015 did: the option adds nothing to it
    all_2015 = _options(name, ["--2015"])
    assert _options(name, ["--2015", "--unscoreable", "2015"]) == all_2015


@pytest.mark.parametrize("name", sorted(FORMER))
def test_the_former_spelling_gives_the_same_options_and_one_note(
    name: str, capsys: pytest.CaptureFixture[str]
) -> None:
    argv, _, _ = FORMER[name]
    new = _options(name, ["--unscoreable", "2015"])
    capsys.readouterr()
    old = _options(name, argv)
    assert old == new
    err = capsys.readouterr().err
    assert err == NOTE.format(old=" ".join(argv)) + "\n"


@pytest.mark.parametrize("name", sorted(FORMER))
def test_the_api_and_the_manifest_take_the_new_name_and_the_former_one(
    name: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    _, key, value = FORMER[name]
    new = api_values(name, {"unscoreable": "2015"})
    assert new["unscoreable"] == "2015"
    assert capsys.readouterr().err == ""
    assert api_values(name, {key: value}) == new
    err = capsys.readouterr().err
    assert err == f"ertools: note: {key}={value!r} is deprecated, use unscoreable='2015'\n"
    manifest = tmp_path / "competition.yaml"
    manifest.write_text(f"benchmarks:\n  {name}:\n    inputs: {{unscoreable: 2015}}\n")
    assert load_manifest(manifest).benchmarks[name].values == {"unscoreable": "2015"}
    assert capsys.readouterr().err == ""
    yaml_value = "true" if value is True else value
    manifest.write_text(f"benchmarks:\n  {name}:\n    inputs: {{{key}: {yaml_value}}}\n")
    assert load_manifest(manifest).benchmarks[name].values == {"unscoreable": "2015"}
    where = f"benchmarks.{name}.inputs"
    assert capsys.readouterr().err == (
        f"ertools: note: {where}.{key} is deprecated, use {where}.unscoreable: 2015\n"
    )
