"""The 2015-rule catalogue: complete, documented, and every rule's option exercised by a test."""

from __future__ import annotations

import pickle
import re
from pathlib import Path

import pytest

from ertools.benchmarks.base import dump_yaml, jsonable
from ertools.fidelity import (
    BEGIN,
    END,
    RULE_MODULES,
    Deviation,
    Rule,
    all_rules,
    markdown_table,
    replace_table,
)

ROOT = Path(__file__).resolve().parents[2]
OPTION = re.compile(r"--[a-z0-9][a-z0-9-]*")

TOY = Rule(
    key="toy.rounding",
    benchmark="toy",
    title="rounding",
    rulebook="seed 0.0: round half up",
    node_2015="round() (toy.py)",
    ertools="exact",
    option="--round-2015",
)


def test_a_deviation_is_its_text_and_knows_its_rule() -> None:
    dev = TOY.deviation("2.5 kept as 2.5; 2015 gave 2")
    assert dev == "2.5 kept as 2.5; 2015 gave 2; --round-2015 restores 2015 [toy.rounding]"
    assert dev.rule is TOY
    assert pickle.loads(pickle.dumps(dev)).rule == TOY
    # Serialised as plain text by every output path.
    assert dump_yaml({"d": [dev]}) == f"d:\n- {dev}\n"
    assert type(jsonable([dev])[0]) in (str, Deviation)


def test_the_option_is_not_repeated_when_the_detail_names_it() -> None:
    assert str(TOY.deviation("use --round-2015 for 2")) == "use --round-2015 for 2 [toy.rounding]"


def test_rules_are_complete_and_keyed_by_benchmark() -> None:
    rules = all_rules()
    for rule in rules:
        assert rule.key.startswith(f"{rule.benchmark}."), rule.key
        for name in ("title", "rulebook", "node_2015", "ertools"):
            assert getattr(rule, name).strip(), f"{rule.key}: empty {name}"
    assert len({r.key for r in rules}) == len(rules)


def _generated_section(path: Path) -> str:
    text = path.read_text(encoding="utf-8")
    assert BEGIN in text and END in text, f"{path.name} lost its generated-table markers"
    return text[text.index(BEGIN) + len(BEGIN) : text.index(END)].strip("\n")


@pytest.mark.parametrize(("doc", "full"), [("docs/fidelity.md", True), ("README.md", False)])
def test_docs_tables_are_the_catalogue(doc: str, full: bool) -> None:
    expected = markdown_table(all_rules(), full=full).strip("\n")
    assert _generated_section(ROOT / doc) == expected, (
        f"{doc} is out of date with the rules in the code: run python -m ertools.fidelity --write"
    )


def test_replace_table_keeps_the_rest_of_the_document() -> None:
    doc = f"intro\n{BEGIN}\nold\n{END}\noutro\n"
    assert replace_table(doc, "new\n") == f"intro\n{BEGIN}\nnew\n{END}\noutro\n"
    with pytest.raises(ValueError, match="markers"):
        replace_table("no markers", "x")


def test_every_rule_option_is_exercised_by_a_test() -> None:
    sources = "\n".join(
        p.read_text(encoding="utf-8")
        for p in (ROOT / "tests").rglob("*.py")
        if p.name != Path(__file__).name
    )
    missing = [
        f"{rule.key}: {flag}"
        for rule in all_rules()
        for flag in OPTION.findall(rule.option)
        if flag not in sources
    ]
    assert not missing, f"options no test runs: {missing}"


def test_rule_modules_exist_and_declare_rules_at_module_level() -> None:
    import importlib

    for name in RULE_MODULES:
        importlib.import_module(name)
