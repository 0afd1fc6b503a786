"""The version, written once (``ertools/_version.py``), and the ways to start ertools."""

from __future__ import annotations

import ast
import subprocess
import sys
from importlib.metadata import version
from pathlib import Path

from ertools._version import __version__

ROOT = Path(__file__).resolve().parents[2]


def test_the_version_is_written_once() -> None:
    # the literal of _version.py, read as text: what setuptools reads without importing it
    tree = ast.parse((ROOT / "ertools" / "_version.py").read_text(encoding="utf-8"))
    (assign,) = [n for n in tree.body if isinstance(n, ast.Assign)]
    assert isinstance(assign.value, ast.Constant)
    written = assign.value.value
    assert __version__ == written
    # the installed metadata comes from it: pyproject.toml's version is dynamic
    assert version("ertools") == written
    pyproject = (ROOT / "pyproject.toml").read_text(encoding="utf-8")
    assert f'version = "{written}"' not in pyproject
    assert 'version = { attr = "ertools._version.__version__" }' in pyproject


def test_python_m_ertools_is_the_command() -> None:
    shown = subprocess.run(
        [sys.executable, "-m", "ertools", "--version"],
        capture_output=True,
        text=True,
        timeout=60,
        check=True,
    )
    assert shown.stdout == f"ertools {__version__}\n"
    bad = subprocess.run(
        [sys.executable, "-m", "ertools", "no-such-command"],
        capture_output=True,
        text=True,
        timeout=60,
        check=False,
    )
    assert bad.returncode == 2
    assert bad.stderr.startswith("ertools: error:")
