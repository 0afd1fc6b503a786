"""No import cycle, imports under ``if TYPE_CHECKING:`` and inside functions included (issue
37): a cycle through annotations still ties the modules together for a reader and a refactor.
import-linter's ``acyclic_siblings`` contract excludes annotations; this test counts them."""

from __future__ import annotations

from pathlib import Path

from tests.architecture.archscan import ROOT, cycles, module_graph, plant, ratchet

# Today's modules in a cycle (all in one, closed through the root's TYPE_CHECKING import of
# ertools.api and the modules that import the root): the list only shrinks.
ALLOWED: frozenset[str] = frozenset()


def test_no_new_module_in_a_cycle() -> None:
    found = {module for cycle in cycles(module_graph(ROOT)) for module in cycle}
    ratchet(found, ALLOWED, "modules in an import cycle")


def test_a_cycle_through_annotations_is_found(tmp_path: Path) -> None:
    root = plant(
        tmp_path,
        {
            "ertools/__init__.py": "from typing import TYPE_CHECKING\nif TYPE_CHECKING:\n"
            "    from ertools.api import score\n",
            "ertools/api.py": "from ertools.low import helper\n",
            "ertools/low.py": "def helper() -> None:\n    import ertools  # lazy: test\n",
            "ertools/alone.py": "from ertools.low import helper\n",
        },
    )
    assert cycles(module_graph(root)) == [["ertools", "ertools.api", "ertools.low"]]


def test_relative_and_from_package_imports_are_edges(tmp_path: Path) -> None:
    root = plant(
        tmp_path,
        {
            "ertools/__init__.py": "",
            "ertools/pkg/__init__.py": "from . import b\n",
            "ertools/pkg/a.py": "from ertools.pkg import b\n",
            "ertools/pkg/b.py": "from .a import name\n",
        },
    )
    graph = module_graph(root)
    assert graph["ertools.pkg"] == {"ertools.pkg.b"}
    assert graph["ertools.pkg.a"] == {"ertools.pkg.b"}
    assert graph["ertools.pkg.b"] == {"ertools.pkg.a"}
    assert cycles(graph) == [["ertools.pkg.a", "ertools.pkg.b"]]
