"""`make notebooks` as a container's root: Jupyter refuses to start as root without
--allow-root, so the target adds it there (and says so) and only there. Run with stand-ins for
the venv's python and jupyter that record their arguments instead of installing or serving."""

from __future__ import annotations

import os
import shutil
import subprocess
from pathlib import Path

import pytest

pytestmark = pytest.mark.slow

ROOT = Path(__file__).resolve().parents[2]


def test_make_notebooks_starts_jupyter_as_root_with_allow_root(tmp_path: Path) -> None:
    if shutil.which("make") is None:
        pytest.skip("n/a: no make on this machine")
    stamp = ROOT / ".venv" / ".installed"
    if not stamp.exists() or stamp.stat().st_mtime < (ROOT / "pyproject.toml").stat().st_mtime:
        pytest.skip("n/a: the venv is not installed (make notebooks would install it first)")
    calls = tmp_path / "calls.txt"
    bin_dir = tmp_path / "bin"
    bin_dir.mkdir()
    for tool in ("python", "jupyter"):
        fake = bin_dir / tool
        fake.write_text(f'#!/bin/sh\necho "{tool} $*" >> {calls}\n')
        fake.chmod(0o755)
    proc = subprocess.run(
        ["make", "--no-print-directory", "notebooks", f"BIN={bin_dir}"],
        cwd=ROOT, capture_output=True, text=True, timeout=60, check=False,
    )  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    ran = calls.read_text().splitlines()
    assert ran[0] == "python -m pip install -qq -e .[notebooks]"
    if os.getuid() == 0:
        assert ran[-1] == "jupyter lab --allow-root notebooks/"
        assert "running as root (a container?): jupyter lab --allow-root" in proc.stdout
    else:
        assert ran[-1] == "jupyter lab notebooks/"
