"""Every import inside a function says why it is there, on its own line (issue 37):
``# lazy: <reason>``, the reason naming the cost avoided. The contracts see function-level
imports, so an ertools module may be imported lazily too; the reason is for the reader."""

from __future__ import annotations

from pathlib import Path

from tests.architecture.archscan import ROOT, plant, ratchet, unexplained_lazy_imports

ALLOWED: frozenset[str] = frozenset()


def test_no_new_function_import_without_its_reason() -> None:
    ratchet(unexplained_lazy_imports(ROOT), ALLOWED, "function-level imports without a reason")


def test_the_reason_must_be_on_the_import_line(tmp_path: Path) -> None:
    root = plant(
        tmp_path,
        {
            "ertools/a.py": (
                "from typing import TYPE_CHECKING\n"
                "import json\n"
                "if TYPE_CHECKING:\n"
                "    import numpy\n"
                "def f() -> None:\n"
                "    import scipy  # lazy: scipy ~150 ms, only here\n"
                "    # lazy: above, not on the line\n"
                "    import matplotlib\n"
                "    from ertools import b\n"
                "    def g() -> None:\n"
                "        import yaml  # lazy:\n"
                "    import csv  # lazy: not needed often\n"
                "    import jinja2  # lazy: Jinja2, 1.5 s\n"
                "    from ertools import (  # lazy: optional extra\n"
                "        c,\n"
                "    )\n"
            ),
        },
    )
    assert unexplained_lazy_imports(root) == {
        "ertools/a.py: matplotlib",
        "ertools/a.py: ertools",
        "ertools/a.py: yaml",
        "ertools/a.py: csv",
    }
