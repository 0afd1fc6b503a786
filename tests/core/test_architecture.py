"""The architecture as written in docs/ARCHITECTURE.md: imports at the top, layers kept.

``make lint`` runs the import-linter contracts of ``pyproject.toml``; these tests show that
they can fail (an upward import planted in a copy of the package is refused) and keep the one
exception to "imports at the top": a function imports only a heavy or optional third-party
package, and says why on the import (``# lazy: ...``).
"""

from __future__ import annotations

import ast
import shutil
import subprocess
import sys
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


# ertools modules imported only where they are used, each costing ~25-30 ms that commands
# without that use should not pay: the report (--report: its pages, the audit, Jinja2),
# Foxglove (--foxglove: protobuf), the bulk decoders (reading messages: worker threads, the
# MCAP index, sqlite; `ertools info` reads indexes only), the YAML writer (PyYAML), and the
# parts of one bag format read only when that format (or that damage) is met.
LAZY_ERTOOLS = {
    "ertools.report.folder",
    "ertools.report.foxglove",
    "ertools.io.bulk",
    "ertools.yamlout",
    "ertools.io.ros1.check",
    "ertools.io.rosbag2.metadata",
    # the pose-source chooser reads bags: the option parsers (every --help) build without it
    "ertools.benchmarks.common.sources",
}


def test_function_level_imports_are_heavy_third_party_with_a_reason() -> None:
    bad = []
    for path in sorted(PACKAGE.rglob("*.py")):
        for line, module, context in _function_imports(path):
            where = f"{path.relative_to(ROOT)}:{line}: {module}"
            if module.split(".")[0] not in LAZY_ALLOWED and module not in LAZY_ERTOOLS:
                bad.append(f"{where}: import it at the top of the module")
            elif "# lazy:" not in context:
                bad.append(f"{where}: say why it is imported here (# lazy: ...)")
    assert not bad, "\n".join(bad)


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
