"""tests/ is a package (issue 37): every test folder is one, helpers shared by several folders
live in tests/helpers/ and are imported as ``tests.helpers.X``, and no test edits sys.path to
reach another folder's modules."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

TESTS = Path(__file__).resolve().parents[1]


def _folders_without_init(tests: Path) -> list[str]:
    return sorted(
        d.relative_to(tests.parent).as_posix()
        for d in {p.parent for p in tests.rglob("*.py")}
        if "__pycache__" not in d.parts and not (d / "__init__.py").is_file()
    )


def _sys_path_edits(path: Path) -> list[str]:
    """``sys.path`` changed by the module's own code (a script it runs as text is data)."""
    found: list[int] = []
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        target = None
        if isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute):
            target = node.func.value  # sys.path.insert(...), .append, .extend
        elif isinstance(node, (ast.Assign, ast.AugAssign)):
            targets = node.targets if isinstance(node, ast.Assign) else [node.target]
            target = next((t.value if isinstance(t, ast.Subscript) else t for t in targets), None)
        if target is not None and ast.unparse(target) == "sys.path":
            found.append(node.lineno)
    return [f"{path.name}:{line}" for line in sorted(found)]


def test_every_test_folder_is_a_package() -> None:
    """A folder without ``__init__.py`` would make its modules top-level ones again (and a
    second ``conftest`` or ``test_x`` of the same name a collection error)."""
    assert _folders_without_init(TESTS) == []


@pytest.mark.slow  # parses every test module (~1 s of CPU)
def test_no_test_edits_sys_path() -> None:
    found = [edit for p in sorted(TESTS.rglob("*.py")) for edit in _sys_path_edits(p)]
    assert found == [], "import from tests.helpers (or give a subprocess PYTHONPATH) instead"


def test_the_checks_find_what_they_look_for(tmp_path: Path) -> None:
    (tmp_path / "tests" / "lost").mkdir(parents=True)
    (tmp_path / "tests" / "__init__.py").write_text("")
    (tmp_path / "tests" / "lost" / "test_x.py").write_text("")
    assert _folders_without_init(tmp_path / "tests") == ["tests/lost"]
    module = tmp_path / "test_path.py"
    module.write_text(
        "import sys\n"
        "sys.path.insert(0, 'a')\n"
        "sys.path.append('b')\n"
        "sys.path[:0] = ['c']\n"
        "sys.path += ['d']\n"
        "CALLER = 'import sys; sys.path.insert(0, x)'  # a script run by a subprocess: data\n"
        "print(sys.path)\n"
    )
    assert _sys_path_edits(module) == [
        "test_path.py:2",
        "test_path.py:3",
        "test_path.py:4",
        "test_path.py:5",
    ]
