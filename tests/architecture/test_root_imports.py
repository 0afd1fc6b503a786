"""Below the public API no module imports the root package (issue 37): ``ertools/__init__``
is the API's, and a module importing it (``from ertools import atomic``, ``import ertools``)
closes a cycle through the API's ``TYPE_CHECKING`` import. Import what is meant instead:
``from ertools.atomic import write_text``, ``from ertools._version import __version__``."""

from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from tests.architecture.archscan import ROOT, plant, ratchet, root_imports

LINT_IMPORTS = Path(sys.executable).with_name("lint-imports")

ALLOWED: frozenset[str] = frozenset()


def test_no_new_root_import() -> None:
    ratchet(root_imports(ROOT), ALLOWED, "modules importing the root package")


def test_every_spelling_of_a_root_import_is_found(tmp_path: Path) -> None:
    root = plant(
        tmp_path,
        {
            "ertools/__init__.py": "from ertools import api\n",
            "ertools/a.py": "from ertools import atomic\n",
            "ertools/b.py": "import ertools\n",
            "ertools/c.py": "def f() -> None:\n    import json, ertools  # lazy: x\n",
            "ertools/d.py": "import ertools.atomic\nfrom ertools.atomic import write_text\n",
            "ertools/pkg/e.py": "from . import d\n",
        },
    )
    assert root_imports(root) == {"ertools/a.py", "ertools/b.py", "ertools/c.py"}


@pytest.mark.skipif(not LINT_IMPORTS.exists(), reason="lint-imports not installed (dev extra)")
def test_the_root_contract_refuses_a_version_import(tmp_path: Path) -> None:
    """pyproject.toml's ``root`` contract (``make lint``) sees ``from ertools import
    __version__``, the spelling that the AST test shares with it."""
    copy = tmp_path / "ertools"
    shutil.copytree(ROOT / "ertools", copy, ignore=shutil.ignore_patterns("__pycache__"))
    model = copy / "io" / "model.py"
    text = model.read_text(encoding="utf-8")
    model.write_text(text + "\nfrom ertools import __version__\n", encoding="utf-8")
    refused = subprocess.run(
        [str(LINT_IMPORTS), "--no-cache", "--contract", "root", str(ROOT / "pyproject.toml")],
        cwd=tmp_path,
        env={"PYTHONPATH": str(tmp_path), "PATH": "/usr/bin:/bin"},
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
    )
    assert refused.returncode != 0, refused.stdout
    assert "ertools.io.model -> ertools " in refused.stdout + " ", refused.stdout
