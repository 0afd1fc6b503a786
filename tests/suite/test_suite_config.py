"""How the suite runs: `make test` on every core with the 15 slowest listed, `make check` the
fast part (the tests not marked `slow`), the groups that xdist reads."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
TESTS = ROOT / "tests"


def _recipe(target: str) -> str:
    text = (ROOT / "Makefile").read_text(encoding="utf-8")
    match = re.search(rf"^{target}:.*\n((?:\t.*\n)+)", text, flags=re.MULTILINE)
    assert match, f"the Makefile has no {target} target"
    return match.group(1)


def test_make_test_runs_in_parallel_and_lists_the_slowest() -> None:
    pytest_line = _recipe("pytest")
    for part in ("-n $(PYTEST_JOBS)", "--dist loadgroup", "--durations=15"):
        assert part in pytest_line
    assert re.search(
        r"^test: lint typecheck pytest pytest-simd-off$", (ROOT / "Makefile").read_text(), re.M
    )


def _make_variable(name: str) -> list[str]:
    text = (ROOT / "Makefile").read_text(encoding="utf-8")
    match = re.search(rf"^{name} := ((?:.*\\\n)*.*)$", text, flags=re.MULTILINE)
    assert match, f"the Makefile has no {name}"
    return match.group(1).replace("\\\n", " ").split()


def test_the_second_pass_switches_every_simd_target_off_and_names_real_tests() -> None:
    """``make test`` runs the numeric tests again with NumPy's SIMD targets off (docs/qa.md,
    "Results on every CPU"): the variable set to what ``ertools.samples.simd`` lists, and
    every test it names exists."""
    recipe = _recipe("pytest-simd-off")
    assert (
        "python -m ertools.samples.simd" in recipe and "env -u NPY_DISABLE_CPU_FEATURES" in recipe
    )
    assert 'NPY_DISABLE_CPU_FEATURES="$$targets"' in recipe and "OPENBLAS_CORETYPE=" in recipe
    assert "$(SIMD_OFF_TESTS)" in recipe and "--deselect $(SIMD_OFF_SKIP)" in recipe
    tests = _make_variable("SIMD_OFF_TESTS")
    assert "tests/e2e/test_outputs_unchanged.py" in tests
    for entry in (*tests, *_make_variable("SIMD_OFF_SKIP")):
        path, _, name = entry.partition("::")
        assert (ROOT / path).is_file(), f"SIMD_OFF_TESTS names {entry}: no such file"
        if name:
            assert f"def {name}(" in (ROOT / path).read_text(encoding="utf-8"), entry


def test_make_check_is_lint_and_the_fast_tests() -> None:
    recipe = _recipe("check")
    assert "ruff check" in recipe and "lint-imports" in recipe
    assert '-m "not slow"' in recipe


PLANTED = """
import pytest

@pytest.mark.slow_cases("b")
@pytest.mark.parametrize("x", ["a", "b", "c"])
def test_cases(x):
    pass
"""


def _collect(tmp_path: Path, module: str, *args: str) -> subprocess.CompletedProcess[str]:
    """pytest with the suite's conftest as its only plug-in, on one planted module."""
    ini = "[pytest]\naddopts = --strict-markers\nmarkers =\n    slow\n    slow_cases\n"
    (tmp_path / "pytest.ini").write_text(ini, encoding="utf-8")
    (tmp_path / "test_planted.py").write_text(module, encoding="utf-8")
    argv = ["-p", "tests.conftest", "-p", "no:cacheprovider", "--collect-only", "-q", *args]
    return subprocess.run(
        [sys.executable, "-m", "pytest", *argv],
        cwd=tmp_path,
        env={**os.environ, "PYTHONPATH": str(ROOT)},
        capture_output=True,
        text=True,
        check=False,
        timeout=120,
    )


@pytest.mark.slow
def test_slow_cases_marks_the_named_cases_and_refuses_a_name_of_none(tmp_path: Path) -> None:
    """`make check` leaves out what `slow_cases` names, and only that; a name that is no case
    (a typo, a renamed parameter) stops the run rather than putting the case back unnoticed."""
    slow = _collect(tmp_path, PLANTED, "-m", "slow")
    assert slow.returncode == 0, slow.stdout + slow.stderr
    listed, _, summary = slow.stdout.partition("\n\n")
    assert listed.split() == ["test_planted.py::test_cases[b]"]
    assert summary.startswith("1/3 tests collected (2 deselected)"), summary
    typo = _collect(tmp_path, PLANTED.replace('slow_cases("b")', 'slow_cases("b", "d")'))
    assert typo.returncode != 0
    assert "slow_cases names no case of its test: test_planted.py::test_cases[d]" in typo.stderr
    # one case asked for by its id: the others were not collected, so nothing to check
    one = _collect(
        tmp_path, PLANTED.replace('"b"', '"b", "d"', 1), "test_planted.py::test_cases[a]"
    )
    assert one.returncode == 0, one.stdout + one.stderr


def test_no_list_of_slow_tests_beside_the_marks() -> None:
    """Slow tests are marked on the test (issue 37): a list would drift from the tests."""
    assert not (TESTS / "slow.txt").exists()


@pytest.fixture(scope="module")
def made_once() -> int:
    return 1


def test_a_test_sharing_a_module_fixture_carries_its_group(
    request: pytest.FixtureRequest, made_once: int
) -> None:
    """Under ``--dist loadgroup`` a test's group is the ``@group`` suffix of its node id: the
    one thing xdist's scheduler reads. Without it (pytest 9.2 with xdist 3.8, whose own suffix
    no longer takes: tests/conftest.py) the groups were silently ignored."""
    if not getattr(request.config.option, "loadgroup", False):
        pytest.skip("n/a: not run by an xdist worker under --dist loadgroup")
    assert made_once == 1
    assert request.node.nodeid.endswith("@suite/test_suite_config.py"), request.node.nodeid
