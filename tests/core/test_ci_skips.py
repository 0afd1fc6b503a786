"""In CI a skip is a failure unless it says it is not about the machine ("n/a:")."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

CONFTEST = Path(__file__).resolve().parents[1] / "conftest.py"

CASES = """
import pytest

def test_needs_a_browser():
    pytest.skip("chromium not installed")

def test_covered_elsewhere():
    pytest.skip("n/a: covered by another test")

@pytest.mark.xfail(strict=True)
def test_known_bug():
    assert False

def test_runs():
    assert True
"""


def _run(tmp_path: Path, ci: bool) -> str:
    (tmp_path / "conftest.py").write_text(CONFTEST.read_text(encoding="utf-8"))
    (tmp_path / "test_cases.py").write_text(CASES)
    env = {k: v for k, v in os.environ.items() if k != "CI"}
    if ci:
        env["CI"] = "true"
    proc = subprocess.run(
        [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", str(tmp_path)],
        cwd=tmp_path,
        env=env,
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
    )
    return proc.stdout.strip().splitlines()[-1]


@pytest.mark.parametrize(
    ("ci", "summary"),
    [
        (True, "1 failed, 1 passed, 1 skipped, 1 xfailed"),
        (False, "1 passed, 2 skipped, 1 xfailed"),
    ],
)
def test_skips_fail_only_in_ci(tmp_path: Path, ci: bool, summary: str) -> None:
    assert _run(tmp_path, ci).startswith(summary)


def test_a_module_skipped_at_collection_fails_in_ci(tmp_path: Path) -> None:
    """``pytest.importorskip`` of an extra the install step forgot (the dask extra once):
    a skip of the whole module at collection, which the per-test rule does not see."""
    (tmp_path / "conftest.py").write_text(CONFTEST.read_text(encoding="utf-8"))
    (tmp_path / "test_extra.py").write_text(
        "import pytest\n"
        "pytest.importorskip('no_such_extra_module', reason='needs the extra')\n"
        "def test_uses_it():\n    pass\n"
    )
    (tmp_path / "test_other.py").write_text("def test_runs():\n    assert True\n")
    outcome = {}
    for ci in (True, False):
        env = {k: v for k, v in os.environ.items() if k != "CI"}
        if ci:
            env["CI"] = "true"
        proc = subprocess.run(
            [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", str(tmp_path)],
            cwd=tmp_path,
            env=env,
            capture_output=True,
            text=True,
            timeout=120,
            check=False,
        )
        outcome[ci] = (proc.returncode, proc.stdout)
    assert outcome[True][0] != 0
    assert "skipped in CI, where the machine must provide it" in outcome[True][1]
    assert outcome[False][0] == 0
    assert "1 passed, 1 skipped" in outcome[False][1]
