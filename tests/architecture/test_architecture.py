"""The architecture as written in docs/ARCHITECTURE.md: imports at the top (the tests' too),
layers kept.

``make lint`` runs the import-linter contracts of ``pyproject.toml``; these tests show that
they can fail (an upward import planted in a copy of the package is refused) and keep the one
exception to "imports at the top": a function imports only a heavy or optional third-party
package (or one of a few standard-library modules, measured), and says why on the import
(``# lazy: ...``).
"""

from __future__ import annotations

import ast
import shutil
import subprocess
import sys
from collections.abc import Iterable, Set
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
PACKAGE = ROOT / "ertools"
LINT_IMPORTS = Path(sys.executable).with_name("lint-imports")

# Third-party packages a function may import itself, each slow to import or optional.
LAZY_ALLOWED = {
    "matplotlib",
    "scipy",
    "pandas",
    "rosbags",
    "mcap",
    "zstandard",
    "lz4",
    "jinja2",
    "distributed",
    "dask",
    "google",
    "yaml",
}
# Standard-library modules a function may import itself (issue 39, docs/performance.md
# "Start-up"): each costs 1-3 ms with what it pulls in, on the start-up of every command that
# reads a bag, for a use off the default path: statistics (random, fractions, decimal) for
# z_value, tempfile and shutil (bz2, lzma) for file-compressed rosbag2 storage, bz2 for bz2
# chunks, csv and decimal for text trajectories. Any other one is imported at the top.
LAZY_STDLIB = {"statistics", "tempfile", "shutil", "bz2", "csv", "decimal"}


def _function_imports(path: Path) -> list[tuple[int, str, str]]:
    """(line, imported module, source text of the line and the two above) of every import
    inside a function, imports under ``if TYPE_CHECKING:`` aside."""
    source = path.read_text(encoding="utf-8")
    lines = source.splitlines()
    found: list[tuple[int, str, str]] = []

    def walk(node: ast.AST, in_function: bool, type_only: bool) -> None:
        for child in ast.iter_child_nodes(node):
            only = type_only or (
                isinstance(child, ast.If) and "TYPE_CHECKING" in ast.unparse(child.test)
            )
            inside = in_function or isinstance(child, ast.FunctionDef | ast.AsyncFunctionDef)
            if isinstance(child, ast.Import | ast.ImportFrom) and in_function and not only:
                module = (
                    child.names[0].name
                    if isinstance(child, ast.Import)
                    else ("." * child.level) + (child.module or "")
                )
                context = "\n".join(lines[max(child.lineno - 3, 0) : child.end_lineno])
                found.append((child.lineno, module, context))
            walk(child, inside, only)

    walk(ast.parse(source), False, False)
    return found


# An ertools module needed only now and then (``ertools.report.folder`` for ``--report``) is
# imported inside the function that needs it, a plain import the contracts see, with its reason
# like the rest (tests/architecture/test_lazy_imports.py).
LAZY_ERTOOLS = frozenset({"ertools"})


def _misplaced(paths: Iterable[Path], allowed: Set[str]) -> list[str]:
    """``path:line: module: what to do`` of every import inside a function of ``paths`` that
    is not a package of ``allowed`` imported with a ``# lazy:`` reason (on its line or the two
    above). Code in strings (a script for a subprocess, a module written to a folder) is text,
    not an import of the file."""
    bad = []
    for path in paths:
        shown = path.relative_to(ROOT) if path.is_relative_to(ROOT) else path
        for line, module, context in _function_imports(path):
            where = f"{shown}:{line}: {module}"
            if module.split(".")[0] not in allowed:
                bad.append(f"{where}: import it at the top of the module")
            elif "# lazy:" not in context:
                bad.append(f"{where}: say why it is imported here (# lazy: ...)")
    return bad


@pytest.mark.slow
def test_function_level_imports_are_heavy_third_party_with_a_reason() -> None:
    bad = _misplaced(sorted(PACKAGE.rglob("*.py")), LAZY_ALLOWED | LAZY_STDLIB | LAZY_ERTOOLS)
    assert not bad, "\n".join(bad)


# The tests keep the package's rule. Beyond its lazy packages, the dev extra's slow ones that
# only a few tests need: evo (each such test skips without it, pytest.importorskip) and
# papermill (the notebook runs).
TESTS = ROOT / "tests"
LAZY_IN_TESTS = LAZY_ALLOWED | {"evo", "papermill"}


# The toy benchmark (docs/writing-a-benchmark.md) is written as a package of ertools is: its
# declare imports its pipeline inside the stages, each with its reason, as the package's do.
TOYBENCH = TESTS / "helpers" / "toybench"


def test_tests_import_at_the_top_too() -> None:
    tests = [p for p in sorted(TESTS.rglob("*.py")) if not p.is_relative_to(TOYBENCH)]
    bad = _misplaced(tests, LAZY_IN_TESTS)
    bad += _misplaced(sorted(TOYBENCH.glob("*.py")), LAZY_ALLOWED | {"tests"})
    assert not bad, "\n".join(bad)


def test_the_tests_rule_refuses_what_it_should(tmp_path: Path) -> None:
    module = tmp_path / "test_m.py"
    module.write_text(
        "import subprocess\n\n"
        "def test_a():\n    from ertools.errors import UsageError\n    return UsageError\n\n"
        "def test_b():\n    import json\n    return json\n\n"
        "def test_c():\n    # lazy: slow\n    from evo.core import sync\n    return sync\n\n"
        "def test_d():\n    from evo.core import sync\n    return sync\n\n"
        "def test_e():\n    import shutil  # lazy: not a heavy package, refused anyway\n\n"
        "def test_f():\n"
        "    code = 'from ertools.io import read_poses\\nimport json'\n"
        "    subprocess.run(['python', '-c', code])\n",
        encoding="utf-8",
    )
    assert _misplaced([module], LAZY_IN_TESTS) == [
        f"{module}:4: ertools.errors: import it at the top of the module",
        f"{module}:8: json: import it at the top of the module",
        f"{module}:17: evo.core: say why it is imported here (# lazy: ...)",
        f"{module}:21: shutil: import it at the top of the module",
    ]


def test_the_rule_sees_a_function_level_import(tmp_path: Path) -> None:
    module = tmp_path / "m.py"
    module.write_text(
        "import os\n\n"
        "def f():\n    from ertools import errors\n    return errors\n\n"
        "def g():\n    import scipy  # lazy: slow\n    return scipy\n\n"
        "if True:\n    def h():\n        import json\n        return json\n",
        encoding="utf-8",
    )
    assert [(line, name) for line, name, _ in _function_imports(module)] == [
        (4, "ertools"),
        (8, "scipy"),
        (13, "json"),
    ]


def _lint_imports(package_parent: Path) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [str(LINT_IMPORTS), "--no-cache", str(ROOT / "pyproject.toml")],
        cwd=package_parent,
        env={"PYTHONPATH": str(package_parent), "PATH": "/usr/bin:/bin"},
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
    )


@pytest.mark.slow
@pytest.mark.skipif(not LINT_IMPORTS.exists(), reason="lint-imports not installed (dev extra)")
def test_the_contract_holds_and_refuses_an_upward_import(tmp_path: Path) -> None:
    copy = tmp_path / "ertools"
    shutil.copytree(PACKAGE, copy, ignore=shutil.ignore_patterns("__pycache__"))
    assert _lint_imports(tmp_path).returncode == 0
    # the reader layer reaching up into a benchmark: refused, and said where
    model = copy / "io" / "model.py"
    model.write_text(
        model.read_text(encoding="utf-8") + "\nfrom ertools.benchmarks.fbm3w import declare\n",
        encoding="utf-8",
    )
    refused = _lint_imports(tmp_path)
    assert refused.returncode != 0
    assert "ertools.io.model -> ertools.benchmarks.fbm3w.declare" in refused.stdout


ACYCLIC_WITH_ANNOTATIONS = """\
[tool.importlinter]
root_package = "ertools"
exclude_type_checking_imports = false

[[tool.importlinter.contracts]]
id = "acyclic-annotations"
name = "no import cycle between sibling modules, imports for annotations included"
type = "acyclic_siblings"
ancestors = ["ertools"]
"""


@pytest.mark.slow
@pytest.mark.skipif(not LINT_IMPORTS.exists(), reason="lint-imports not installed (dev extra)")
def test_no_cycle_even_through_annotations(tmp_path: Path) -> None:
    """Imports under TYPE_CHECKING (annotations only) count for the contracts: a cycle
    through them is still two modules that cannot be understood apart: there is none (the
    ROS1 bag and its run reader share a protocol, ertools.io.ros1.runs.IndexedBag)."""
    config = tmp_path / "acyclic.toml"
    config.write_text(ACYCLIC_WITH_ANNOTATIONS, encoding="utf-8")
    copy = tmp_path / "pkg" / "ertools"
    shutil.copytree(PACKAGE, copy, ignore=shutil.ignore_patterns("__pycache__"))

    def lint() -> subprocess.CompletedProcess[str]:
        return subprocess.run(
            [str(LINT_IMPORTS), "--no-cache", str(config)],
            cwd=copy.parent,
            env={"PYTHONPATH": str(copy.parent), "PATH": "/usr/bin:/bin"},
            capture_output=True,
            text=True,
            timeout=120,
            check=False,
        )

    assert lint().returncode == 0, lint().stdout[-2000:]
    runs = copy / "io" / "ros1" / "runs.py"
    runs.write_text(
        runs.read_text(encoding="utf-8").replace(
            "if TYPE_CHECKING:\n",
            "if TYPE_CHECKING:\n    from ertools.io.ros1.index import Ros1Bag\n",
        ),
        encoding="utf-8",
    )
    planted = lint()
    assert planted.returncode != 0 and "ertools.io.ros1" in planted.stdout


# One concept per module (/work/shared/STYLE.md): a module past this many lines holds more than
# one and is split into modules of its package (issue 27).
MAX_MODULE_LINES = 600


def _long_modules(package: Path, limit: int) -> list[str]:
    """``path: N lines`` of every module of ``package`` longer than ``limit`` lines."""
    out = []
    for path in sorted(package.rglob("*.py")):
        count = len(path.read_text(encoding="utf-8").splitlines())
        if count > limit:
            out.append(f"{path.relative_to(package.parent)}: {count} lines")
    return out


def test_no_module_over_the_line_limit() -> None:
    too_long = _long_modules(PACKAGE, MAX_MODULE_LINES)
    assert not too_long, (
        f"split these into cohesive modules of at most {MAX_MODULE_LINES} lines:\n"
        + "\n".join(too_long)
    )


def test_the_line_limit_sees_a_long_module(tmp_path: Path) -> None:
    package = tmp_path / "pkg"
    (package / "sub").mkdir(parents=True)
    (package / "short.py").write_text("x = 1\n" * MAX_MODULE_LINES, encoding="utf-8")
    (package / "sub" / "long.py").write_text("x = 1\n" * (MAX_MODULE_LINES + 1), encoding="utf-8")
    assert _long_modules(package, MAX_MODULE_LINES) == [
        f"pkg/sub/long.py: {MAX_MODULE_LINES + 1} lines"
    ]
