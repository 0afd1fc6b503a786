"""The three stages of a benchmark are functions of its ``pipeline`` module named after their
slots, ``load``, ``find_runs`` and ``score_runs`` (issue 37: functions named after their slots,
no renaming on the way), and no other module of the package defines a function of those names:
a slot's name means the slot."""

from __future__ import annotations

import ast
from pathlib import Path

from tests.architecture.archscan import ROOT, plant

SLOTS = ("load", "find_runs", "score_runs")


def slot_problems(root: Path) -> list[str]:
    """What breaks the rule in each package of ``root/ertools/benchmarks`` that has a declare."""
    problems = []
    for package in sorted((root / "ertools" / "benchmarks").iterdir()):
        if not (package / "declare.py").is_file():
            continue
        for module in sorted(package.glob("*.py")):
            tree = ast.parse(module.read_text(encoding="utf-8"))
            defined = {n.name for n in tree.body if isinstance(n, ast.FunctionDef)}
            where = module.relative_to(root).as_posix()
            if module.name == "pipeline.py":
                problems += [f"{where}: no function {s}" for s in SLOTS if s not in defined]
            else:
                problems += [f"{where}: defines {s}" for s in SLOTS if s in defined]
        if not (package / "pipeline.py").is_file():
            problems.append(f"{package.relative_to(root).as_posix()}: no pipeline.py")
    return problems


def test_every_benchmark_has_its_slots_in_pipeline() -> None:
    assert slot_problems(ROOT) == []


def test_a_slot_elsewhere_or_missing_is_found(tmp_path: Path) -> None:
    stages = "def load(): ...\ndef find_runs(): ...\ndef score_runs(): ...\n"
    root = plant(
        tmp_path,
        {
            "ertools/benchmarks/good/declare.py": "",
            "ertools/benchmarks/good/pipeline.py": stages,
            "ertools/benchmarks/half/declare.py": "",
            "ertools/benchmarks/half/pipeline.py": "def score_runs(): ...\n",
            "ertools/benchmarks/half/logs.py": "def load(): ...\ndef find_runs(): ...\n",
            "ertools/benchmarks/none/declare.py": "",
            "ertools/benchmarks/common/hygiene.py": "def load(): ...\n",  # no declare: shared
        },
    )
    assert slot_problems(root) == [
        "ertools/benchmarks/half/logs.py: defines load",
        "ertools/benchmarks/half/logs.py: defines find_runs",
        "ertools/benchmarks/half/pipeline.py: no function load",
        "ertools/benchmarks/half/pipeline.py: no function find_runs",
        "ertools/benchmarks/none: no pipeline.py",
    ]
