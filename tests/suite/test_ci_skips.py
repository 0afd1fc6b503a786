"""In CI a skip is a failure unless it says it is not about the machine ("n/a:")."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

pytestmark = pytest.mark.slow

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


def _pytest(tmp_path: Path, ci: bool, files: dict[str, str]) -> subprocess.CompletedProcess[str]:
    """pytest on ``files`` (name -> source) beside the suite's own conftest, with or without CI."""
    (tmp_path / "conftest.py").write_text(CONFTEST.read_text(encoding="utf-8"))
    for name, source in files.items():
        (tmp_path / name).write_text(source)
    env = {k: v for k, v in os.environ.items() if k != "CI"}
    if ci:
        env["CI"] = "true"
    return subprocess.run(
        [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", str(tmp_path)],
        cwd=tmp_path,
        env=env,
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
    )


@pytest.mark.parametrize(
    ("ci", "summary"),
    [
        (True, "1 failed, 1 passed, 1 skipped, 1 xfailed"),
        (False, "1 passed, 2 skipped, 1 xfailed"),
    ],
)
def test_skips_fail_only_in_ci(tmp_path: Path, ci: bool, summary: str) -> None:
    proc = _pytest(tmp_path, ci, {"test_cases.py": CASES})
    assert proc.stdout.strip().splitlines()[-1].startswith(summary)


EXTRA = """import pytest
pytest.importorskip('no_such_extra_module', reason='needs the extra')
def test_uses_it():
    pass
"""


def test_a_module_skipped_at_collection_fails_in_ci(tmp_path: Path) -> None:
    """``pytest.importorskip`` of an extra the install step forgot (the dask extra once):
    a skip of the whole module at collection, which the per-test rule does not see."""
    files = {"test_extra.py": EXTRA, "test_other.py": "def test_runs():\n    assert True\n"}
    (tmp_path / "ci").mkdir()
    (tmp_path / "local").mkdir()
    in_ci = _pytest(tmp_path / "ci", True, files)
    local = _pytest(tmp_path / "local", False, files)
    assert in_ci.returncode != 0
    assert "skipped in CI, where the machine must provide it" in in_ci.stdout
    assert local.returncode == 0
    assert "1 passed, 1 skipped" in local.stdout
