"""The public API without tricks (issue 37): each name of ``ertools.API`` is the function of
ertools/api.py itself, so ``help()`` and ``inspect.signature`` show its own documentation and
parameters; any other attribute of ``ertools`` is an AttributeError; ``import ertools`` stays
light; the names are written once (plus the typed import that type checkers read)."""

from __future__ import annotations

import ast
import inspect
import pydoc
import subprocess
import sys
from pathlib import Path

import pytest

import ertools
from ertools import api

ROOT = Path(__file__).resolve().parents[2]


@pytest.mark.parametrize("name", ertools.API)
def test_each_name_is_the_function_itself(name: str) -> None:
    function = getattr(api, name)
    assert getattr(ertools, name) is function
    assert inspect.isfunction(getattr(ertools, name))
    # the signature is the function's own, never (*args, **kwargs)
    signature = inspect.signature(getattr(ertools, name))
    assert signature == inspect.signature(function)
    assert list(signature.parameters) == list(inspect.signature(function).parameters)
    assert not any(p.kind is p.VAR_POSITIONAL for p in signature.parameters.values())
    # help() shows its documentation: the docstring's first line, not a package's contents
    first = (function.__doc__ or "").strip().splitlines()[0]
    shown = pydoc.render_doc(getattr(ertools, name), renderer=pydoc.plaintext)
    assert " ".join(first.split()) in " ".join(shown.split())
    assert "PACKAGE CONTENTS" not in shown


def test_the_names_are_the_api_modules_public_functions() -> None:
    """``ertools.API`` is every public function defined in ertools/api.py, in the order of
    docs/api.md (the module's own order is free)."""
    tree = ast.parse((ROOT / "ertools" / "api.py").read_text(encoding="utf-8"))
    defined = {
        node.name
        for node in tree.body
        if isinstance(node, ast.FunctionDef) and not node.name.startswith("_")
    }
    assert set(ertools.API) == defined
    assert len(ertools.API) == len(set(ertools.API)) == 9
    assert ertools.__all__ == ["__version__", *ertools.API]


def test_the_typed_import_names_the_same() -> None:
    """The second writing of the names, for mypy and editors: the ``TYPE_CHECKING`` import."""
    tree = ast.parse((ROOT / "ertools" / "__init__.py").read_text(encoding="utf-8"))
    (block,) = [n for n in tree.body if isinstance(n, ast.If)]
    assert ast.unparse(block.test) == "TYPE_CHECKING"
    (imported,) = block.body
    assert isinstance(imported, ast.ImportFrom) and imported.module == "ertools.api"
    assert sorted(a.name for a in imported.names) == sorted(ertools.API)


FRESH = """
import sys, ertools
assert "numpy" not in sys.modules and "ertools.api" not in sys.modules, "not light"
for name in ("serialize", "auditing", "api", "nope"):
    try:
        getattr(ertools, name)
    except AttributeError as err:
        print(name, "AttributeError", err)
    else:
        print(name, "found")
print("dir", sorted(n for n in dir(ertools) if not n.startswith("__")))
"""


def test_a_fresh_import_offers_only_the_api() -> None:
    out = subprocess.run(
        [sys.executable, "-c", FRESH], capture_output=True, text=True, timeout=60, check=True
    ).stdout.splitlines()
    assert out[:3] == [
        "serialize AttributeError module 'ertools' has no attribute 'serialize'",
        "auditing AttributeError module 'ertools' has no attribute 'auditing'",
        "api AttributeError module 'ertools' has no attribute 'api'",
    ]
    assert out[3] == "nope AttributeError module 'ertools' has no attribute 'nope'"
    assert out[4] == f"dir {sorted(['API', *ertools.API])}"
