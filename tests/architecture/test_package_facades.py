"""A package's ``__init__.py`` imports nothing (issue 37), the root's aside (the public API's
names, PEP 562): a facade that re-exports its modules (``from ertools.io import read_poses``)
makes every user depend on the whole package, and the contracts cannot see which module is
used. Import the module that defines the name."""

from __future__ import annotations

from pathlib import Path

from tests.architecture.archscan import ROOT, facade_packages, plant, ratchet

# The list only shrinks.
ALLOWED: frozenset[str] = frozenset()


def test_no_new_package_facade() -> None:
    ratchet(facade_packages(ROOT), ALLOWED, "package __init__ files that import")


def test_a_facade_is_found(tmp_path: Path) -> None:
    root = plant(
        tmp_path,
        {
            "ertools/__init__.py": "from ertools._version import __version__\n",
            "ertools/io/__init__.py": '"""The readers."""\n',
            "ertools/io/reader.py": "def read() -> None: ...\n",
            "ertools/report/__init__.py": "from ertools.io.reader import read\n",
            "ertools/report/deep/__init__.py": "def f() -> None:\n    import json  # lazy: x\n",
        },
    )
    assert facade_packages(root) == {
        "ertools/report/__init__.py",
        "ertools/report/deep/__init__.py",
    }
