"""The 2015-rule catalogue: complete, documented, and every rule's option exercised by a test."""

from __future__ import annotations

import importlib
import pickle
import re
from pathlib import Path

import pytest

from ertools.benchmarks import registry
from ertools.benchmarks.catalogue import SHARED_RULES
from ertools.benchmarks.catalogue import rules as all_rules
from ertools.benchmarks.catalogue import versions as all_versions
from ertools.benchmarks.fbm1.config import NODE_2015, NODE_2016, NODE_2017
from ertools.benchmarks.fbm2h.config import NODES as FBM2H_NODES
from ertools.cli.main import main
from ertools.fidelity import (
    BEGIN,
    END,
    VERSIONS_BEGIN,
    VERSIONS_END,
    Deviation,
    Rule,
    markdown_table,
    replace_table,
    version_table,
)
from ertools.serialize import dump_yaml, jsonable
from tests.fidelity.rulescan import rule_declarations

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


def test_docs_table_is_the_catalogue() -> None:
    expected = markdown_table(all_rules(), full=True).strip("\n")
    assert _generated_section(ROOT / "docs" / "fidelity.md") == expected, (
        "docs/fidelity.md is out of date with the rules in the code: "
        "run python -m ertools.benchmarks.catalogue --write"
    )


def test_docs_version_table_is_the_code() -> None:
    text = (ROOT / "docs" / "fidelity.md").read_text(encoding="utf-8")
    section = text[text.index(VERSIONS_BEGIN) + len(VERSIONS_BEGIN) : text.index(VERSIONS_END)]
    assert section.strip("\n") == version_table(all_versions()).strip("\n"), (
        "docs/fidelity.md's version table is out of date: "
        "run python -m ertools.benchmarks.catalogue --write"
    )
    assert text.index(VERSIONS_BEGIN) < text.index(BEGIN), "the version table opens the doc"


# What each option reproduces (issue 35, from rockin-robot-challenge/benchmark_and_scoring_fbm
# read at these commits): (file, commit, competition, the option).
REPRODUCED = (
    ("src/rockin_scoring/BmBox.py", "7628309", "RoCKIn 2015 Lisbon", "--2015"),
    ("scripts/fbm1h", "e373be0", "RoCKIn 2015 Lisbon", "--rules 2015"),
    ("scripts/fbm1w", "7628309", "RoCKIn 2015 Lisbon", "--rules 2015"),
    ("scripts/fbm1h", "40ba68b", "Lisbon 2016 second local", "--rules 2016"),
    ("scripts/fbm1h", "89dfa75", "Lisbon 2017 major tournament", "--rules 2017"),
    ("scripts/fbm2h", "50b173b", "RoCKIn 2015 Lisbon", "--rules 2015"),
    ("scripts/fbm2h", "40ba68b", "Lisbon 2016 second local", "--rules 2016"),
    ("scripts/fbm2h", "89dfa75", "Lisbon 2017 major tournament", "--rules 2017"),
    ("scripts/fbm3w", "50b173b", "RoCKIn 2015 Lisbon", "--2015"),
)


# What the outputs say each option reproduces (the `reference` of FBM1, FBM2@Home's notes).
SAID = {
    ("scripts/fbm1h", "--rules 2015"): NODE_2015,
    ("scripts/fbm1w", "--rules 2015"): NODE_2015,
    ("scripts/fbm1h", "--rules 2016"): NODE_2016,
    ("scripts/fbm1h", "--rules 2017"): NODE_2017,
    **{("scripts/fbm2h", f"--rules {k}"): v for k, v in FBM2H_NODES.items()},
}


@pytest.mark.parametrize(("file", "commit", "event", "option"), REPRODUCED)
def test_each_option_names_its_node_version(
    file: str, commit: str, event: str, option: str
) -> None:
    rows = [v for v in all_versions() if (v.file, v.commit) == (file, commit)]
    assert len(rows) == 1, (file, commit)
    assert event in rows[0].event and option in rows[0].restores
    if (file, option) in SAID:
        assert commit in SAID[file, option], (file, option)


def test_version_rows_are_in_order_and_unique() -> None:
    seen: set[tuple[str, str]] = set()
    last: dict[str, str] = {}
    for v in all_versions():
        assert v.changes and v.restores and v.event, v
        assert (v.file, v.commit) not in seen, v
        seen.add((v.file, v.commit))
        assert v.date >= last.get(v.file, ""), f"{v.file}: {v.commit} out of date order"
        last[v.file] = v.date
        # the 2015-17 RoCKIn/ERL competitions; the ERL @Home seasons 2017-19 (the RSBB scripts)
        competed = any(e in v.event for e in ("RoCKIn", "Lisbon", "Peccioli", "ERL @Home"))
        assert competed or v.event.startswith("development"), v
        # a version no competition ran is restored by nothing, and says why
        assert competed or v.restores.startswith(("not restorable:", "`--rules")), v


def test_readme_summarises_and_links_the_table() -> None:
    """The table lives in docs/fidelity.md only; the README says what it is and links it."""
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    assert BEGIN not in readme and END not in readme
    assert "(docs/fidelity.md)" in readme
    for rule in all_rules():
        assert f"| {rule.title} |" not in readme, f"README still holds the row {rule.key}"


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


@pytest.mark.slow  # parses every module of ertools (~1 s of CPU)
def test_rules_are_declared_at_module_level_and_reach_the_catalogue() -> None:
    """Every ``Rule(...)`` in ertools is a module constant listed in its module's ``RULES``,
    and the catalogue is exactly those constants, the same objects: a rule made anywhere else,
    or left out of ``RULES``, would be in no table and no check. (Checked by hand once: a
    Rule made in a function of fbm3w/rules.py, and a constant left out of trajectory's RULES, each
    failed this test with its file named.)"""
    constants, problems = rule_declarations(ROOT)
    assert not problems, "\n".join(sorted(problems))
    declared = [
        getattr(importlib.import_module(module), name)
        for module, names in constants.items()
        for name in names
    ]
    assert all(isinstance(rule, Rule) for rule in declared)
    caught = all_rules()
    assert sorted(r.key for r in caught) == sorted(r.key for r in declared)
    assert all(any(c is d for d in declared) for c in caught)
    # a module's rules reach the catalogue through a registered benchmark or as the BmBox's
    shared = {id(r) for r in SHARED_RULES}
    carried = {id(r) for name in registry.names() for r in registry.get(name).rules}
    assert all(id(r) in shared | carried for r in declared)


# Benchmarks whose declaration does not carry its package's rules: none may be added.
RULES_NOT_CARRIED: frozenset[str] = frozenset()


@pytest.mark.slow  # imports every benchmark (~1 s of CPU)
def test_each_benchmark_carries_the_rules_of_its_package() -> None:
    """A registered benchmark's ``rules`` are the constants of its package's ``rules.py``, the
    catalogue's own objects (what its outputs list as its deviations)."""
    constants, _ = rule_declarations(ROOT)
    catalogue = all_rules()
    short = set()
    for name in registry.names():
        package = registry.entry(name).absolute.partition(":")[0].rpartition(".")[0]
        module = importlib.import_module(f"{package}.rules")
        own = [getattr(module, n) for n in constants.get(module.__name__, ())]
        carried = registry.get(name).rules
        assert all(any(r is c for c in catalogue) for r in carried), f"{name}: not the catalogue's"
        if [r.key for r in carried] != [r.key for r in own]:
            short.add(name)
    new, fixed = sorted(short - RULES_NOT_CARRIED), sorted(RULES_NOT_CARRIED - short)
    assert not new, f"benchmarks whose rules are not their package's: {new}"
    assert not fixed, f"these carry their rules now: remove them from RULES_NOT_CARRIED: {fixed}"


def test_a_rule_declared_elsewhere_is_refused(tmp_path: Path) -> None:
    """The check above, on a planted tree: a rule made in a function, in a class or inside a
    list is refused, and so are constants their module's RULES leaves out, lists in another
    order, or a module without RULES."""
    rule = 'Rule("toy.{0}", "toy", "t", "r", "n", "e")'
    files = {
        "ertools/benchmarks/toy/rules.py": (
            "from ertools.fidelity import Rule\n"
            f"RULE_A = {rule.format('a')}\n"
            f"RULE_B: Rule = {rule.format('b')}\n"
            f"def later() -> Rule:\n    return {rule.format('c')}\n"
            f"class Kept:\n    RULE_D = {rule.format('d')}\n"
            f"OTHERS = [{rule.format('e')}]\n"
            "RULES = (RULE_A, RULE_X)\n"
        ),
        "ertools/benchmarks/toy/other.py": (
            f"import ertools.fidelity\nRULE_F = ertools.fidelity.{rule.format('f')}\n"
        ),
        "ertools/benchmarks/toy2/rules.py": (
            "RULE_G = Rule('g')\nRULE_H = Rule('h')\nRULES: tuple[Rule, ...] = (RULE_H, RULE_G)\n"
        ),
        "ertools/benchmarks/none/rules.py": "RULES = ()\n",
    }
    for rel, text in files.items():
        (tmp_path / rel).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / rel).write_text(text, encoding="utf-8")
    constants, problems = rule_declarations(tmp_path)
    assert constants == {
        "ertools.benchmarks.toy.rules": ("RULE_A", "RULE_B"),
        "ertools.benchmarks.toy.other": ("RULE_F",),
        "ertools.benchmarks.toy2.rules": ("RULE_G", "RULE_H"),
    }
    toy = "ertools/benchmarks/toy/rules.py"
    assert problems == {
        f"{toy}: a Rule made in function later, not a module constant",
        f"{toy}: a Rule made in class Kept, not a module constant",
        f"{toy}: a Rule made in an expression at module level, not a module constant",
        f"{toy}: RULES leaves out RULE_B",
        f"{toy}: RULES lists RULE_X, not a Rule constant here",
        "ertools/benchmarks/toy/other.py: Rule constants and no RULES tuple listing them",
        "ertools/benchmarks/toy2/rules.py: RULES lists its constants in another order than "
        "declared",
    }


SAMPLES = ROOT / "sample_bags"
FBM3W = str(SAMPLES / "fbm3w" / "log_fbm3w_mocap_2015-11-20-12-00-00_0.bag")
FBM2H = str(SAMPLES / "fbm2h" / "log_fbm2h_mocap_2015-11-20-12-00-00_0.bag")
FBM2H_INPUTS = [
    "--goal",
    str(SAMPLES / "fbm2h" / "fbm2h_goal.yaml"),
    "--transform",
    str(SAMPLES / "fbm2h" / "transform-simbot.yaml"),
]
FBM1H = [
    str(SAMPLES / "fbm1h" / "log_fbm1h_2015-11-20-12-00-00_0.bag"),
    "--items",
    str(SAMPLES / "fbm1h" / "fbm1h.yaml"),
]
ROBOT = [str(SAMPLES / "robotlog" / "FBM2H_201511201200_homer.bag"), str(SAMPLES / "robotlog")]
RUNS = {
    "fbm3w": ["score", "fbm3w", FBM3W],
    "fbm3w-auto-arc": ["score", "fbm3w", FBM3W, "--runs", "auto", "--arc-length"],
    "fbm3w-d-min": ["score", "fbm3w", FBM3W, "--d-min", "0.001"],
    "fbm3w-2015": ["score", "fbm3w", FBM3W, "--2015"],
    "fbm2h": ["score", "fbm2h", FBM2H, *FBM2H_INPUTS],
    "fbm2h-2015": ["score", "fbm2h", FBM2H, *FBM2H_INPUTS, "--2015"],
    "fbm1h": ["score", "fbm1h", *FBM1H],
    "fbm1h-2015": ["score", "fbm1h", *FBM1H, "--rules", "2015"],
    "fbm1h-2016": ["score", "fbm1h", *FBM1H, "--rules", "2016"],
    "trajectory": ["score", "trajectory", *ROBOT],
    "trajectory-2015": ["score", "trajectory", *ROBOT, "--2015"],
    "audit": ["audit", FBM2H, "--transform", str(SAMPLES / "fbm2h" / "transform-simbot.yaml")],
}
PRINTED = re.compile(r"^ertools: differs from 2015: .*\[(?P<key>[a-z0-9]+\.[a-z0-9-]+)\]$")


@pytest.mark.slow_cases("audit", "fbm3w-2015", "fbm3w-auto-arc", "fbm3w-d-min", "fbm3w")
@pytest.mark.parametrize("case", list(RUNS))
def test_every_printed_deviation_has_a_rule(case: str, capsys: pytest.CaptureFixture[str]) -> None:
    """What the commands print on the samples under the default and the 2015 options: each
    ``differs from 2015`` line names a rule of the catalogue (and so a row of the docs)."""

    assert main(RUNS[case]) == 0
    err = capsys.readouterr().err
    lines = [ln for ln in err.splitlines() if "differs from 2015" in ln]
    by_key = {r.key: r for r in all_rules()}
    printed = []
    for line in lines:
        match = PRINTED.match(line)
        assert match is not None, f"a deviation without a rule key: {line}"
        assert match.group("key") in by_key, line
        printed.append(by_key[match.group("key")])
    if case.endswith("-2015"):
        # --2015 / --rules 2015 restore every behaviour an option can restore: what is still
        # printed is what no log can restore (the rule says why)
        assert [r.key for r in printed if r.option] == []
    elif "-" not in case:
        assert printed, "the defaults differ from 2015 on every sample: nothing was printed"
