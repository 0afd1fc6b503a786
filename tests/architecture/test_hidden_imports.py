"""Every dependency visible to the import contracts (issue 37): no submodule reached as an
attribute of a package without an import of it, no module ``__getattr__`` but the root's (the
public API's names), no module class swapped, no ``import_module`` but the registry's."""

from __future__ import annotations

from pathlib import Path

from tests.architecture.archscan import ROOT, hidden_imports, plant, ratchet

# None left (the old benchmark record went with the last conversion): none may come back.
ALLOWED: frozenset[str] = frozenset()


def test_no_new_hidden_import() -> None:
    ratchet(hidden_imports(ROOT), ALLOWED, "hidden imports")


def test_each_kind_of_hidden_import_is_found(tmp_path: Path) -> None:
    root = plant(
        tmp_path,
        {
            "ertools/__init__.py": "def __getattr__(name):\n    raise AttributeError(name)\n",
            "ertools/report/__init__.py": "__getattr__ = print\n",
            "ertools/report/folder.py": "def write() -> None: ...\n",
            "ertools/cli.py": "from ertools import report\n\nreport.folder.write()\n",
            "ertools/ok.py": "import ertools.report.folder\n\nertools.report.folder.write()\n",
            "ertools/lazy.py": "def __getattr__(name):\n    return name\n",
            "ertools/swap.py": "import sys\nsys.modules[__name__].__class__ = type\n",
            "ertools/load.py": "from importlib import import_module\nimport_module('x')\n",
            "ertools/benchmarks/registry.py": "import importlib\nimportlib.import_module('x')\n",
        },
    )
    assert hidden_imports(root) == {
        "ertools/cli.py: ertools.report.folder reached as an attribute",
        "ertools/report/__init__.py: module __getattr__ assigned",
        "ertools/lazy.py: module __getattr__",
        "ertools/swap.py: module class swapped",
        "ertools/load.py: import_module outside the registry",
    }
