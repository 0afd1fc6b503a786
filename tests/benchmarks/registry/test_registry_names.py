"""Benchmark names live in one place: their own package and the registry (issue 16).

Everything else (the CLI, the report, the audit, the demo) reaches a benchmark through
:mod:`ertools.benchmarks.registry`, so a name written as a string anywhere else is a switch
over names that the next benchmark would have to extend.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

from ertools.benchmarks import registry

ROOT = Path(__file__).resolve().parents[3]
PACKAGE = ROOT / "ertools"
# The package of each benchmark (fbm1h and fbm1w share one).
OWN_PACKAGE = {
    "fbm1h": "fbm1",
    "fbm1w": "fbm1",
    "fbm2h": "fbm2h",
    "fbm3w": "fbm3w",
    "trajectory": "trajectory",
    "noise": "noise",
    "hnf": "hnf",
    "hpff": "hpff",
    "hopf": "hopf",
    "hppf": "hppf",
    "hgmf": "hgmf",
    "hgtkmh": "referee",
    "hwv": "referee",
    "hcfgac": "referee",
    "stb": "referee",
}
# Files (or folders, ending in /) allowed to name benchmarks, and why; each entry must say why.
EXCEPTIONS: dict[str, str] = {
    "ertools/samples/": "the sample generator simulates the 2015 logs of named benchmarks (a "
    "competition's schedule, scenario folders named after them): names there are data, not "
    "a dispatch over benchmarks",
    "ertools/benchmarks/noise/sample.py": "the simulated 2015 noise recording is on FBM3@Work's "
    "topics (/fbm3w/...): a namespace in a log's topic names is data",
    "ertools/benchmarks/trajectory/sample.py": "the simulated 2015 GT logger recorded FBM2@Home's "
    "marker set (/fbm2h/...): a namespace in a log's topic names is data",
}

# "noise" is also a plain word: the files that use it as one (a key of measured or simulated
# noise, a file-name word, the command `ertools noise`), each with why; the name only.
WORDS: dict[tuple[str, str], str] = {
    ("ertools/benchmarks/common/epsilon.py", "noise"): "the noise result is common (every "
    "benchmark's intervals measure the noise of their GT); its default name is the measure's",
    ("ertools/benchmarks/fbm3w/result.py", "noise"): "the result's table of the noise measured "
    "on its own GT",
    ("ertools/benchmarks/fbm3w/sample.py", "noise"): "the answers' noise of the simulated mocap",
    ("ertools/benchmarks/hgmf/sample.py", "noise"): "the answers' noise of the simulated mocap",
    ("ertools/cli/main.py", "noise"): "the command `ertools noise` (docs/cli.md), kept as "
    "documented beside `ertools score noise`",
    ("ertools/demo.py", "noise"): "the demo's step running the command `ertools noise`",
    ("ertools/competition/discover.py", "noise"): "a word of a noise recording's file name",
}


def _string_constants(path: Path) -> list[tuple[int, str]]:
    tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
    return [
        (node.lineno, node.value)
        for node in ast.walk(tree)
        if isinstance(node, ast.Constant) and isinstance(node.value, str)
    ]


def test_the_names_checked_are_the_registry() -> None:
    """The list above is the registry's: a new benchmark is checked too."""
    assert set(OWN_PACKAGE) == set(registry.names())


@pytest.mark.slow
def test_no_benchmark_name_outside_its_package_and_the_registry() -> None:
    offenders = []
    for path in sorted(PACKAGE.rglob("*.py")):
        rel = path.relative_to(ROOT).as_posix()
        if rel == "ertools/benchmarks/registry.py" or any(rel.startswith(e) for e in EXCEPTIONS):
            continue
        for line, value in _string_constants(path):
            package = OWN_PACKAGE.get(value)
            if (rel, value) in WORDS:
                continue
            if package is not None and not rel.startswith(f"ertools/benchmarks/{package}/"):
                offenders.append(f"{rel}:{line}: {value!r}")
    assert not offenders, "benchmark names outside their package:\n" + "\n".join(offenders)


def test_the_check_finds_a_name(tmp_path: Path) -> None:
    """The AST walk sees a name in a plain string, a default argument and a dict key."""
    source = tmp_path / "m.py"
    source.write_text(
        'def f(name="fbm3w"):\n    return {"fbm2h": 1}.get(name, "trajectory")\n',
        encoding="utf-8",
    )
    found = {v for _, v in _string_constants(source)}
    assert {"fbm3w", "fbm2h", "trajectory"} <= found
