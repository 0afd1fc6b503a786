"""How the suite runs: `make test` on every core with the 15 slowest listed, `make check` the
fast part; tests/slow.txt and the timing group name tests that exist."""

from __future__ import annotations

import importlib.util
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
TESTS = ROOT / "tests"


def _root_conftest() -> object:
    # by path: every test folder's conftest is a module named `conftest`
    spec = importlib.util.spec_from_file_location("root_conftest", TESTS / "conftest.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


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


def test_listed_tests_exist() -> None:
    conftest = _root_conftest()
    for entry in (*conftest._slow(), *conftest.TIMING):  # type: ignore[attr-defined]
        path = entry.split("::")[0]
        assert (TESTS / path).exists(), f"tests/slow.txt or TIMING names {entry}: no such file"
        if "::" in entry:
            name = entry.split("::")[1].split("[")[0]
            assert f"def {name}(" in (TESTS / path).read_text(encoding="utf-8"), entry


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
    assert request.node.nodeid.endswith("@core/test_suite_config.py"), request.node.nodeid
