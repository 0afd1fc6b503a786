"""Test-suite root: its presence puts ``tests/`` on ``sys.path`` (pytest's prepend import
mode), so helpers shared by several test folders live in one module, ``tests/fakes.py``."""

import os
from pathlib import Path

import pytest

# A skip says "this machine cannot run it". CI's machine can run everything (it has ../shared
# beside the clone and .ci/run installs Chromium), so in CI a skip means a missing install step
# that would otherwise look like success. Skips that are not about the machine (a case covered
# elsewhere) say so with a reason starting "n/a:" and stay skips.
NOT_APPLICABLE = "n/a:"


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_makereport(item: pytest.Item, call: pytest.CallInfo[None]) -> object:
    outcome = yield
    report = outcome.get_result()  # type: ignore[attr-defined]
    if not (os.environ.get("CI") and report.skipped) or hasattr(report, "wasxfail"):
        return
    reason = report.longrepr[2] if isinstance(report.longrepr, tuple) else str(report.longrepr)
    if reason.removeprefix("Skipped: ").startswith(NOT_APPLICABLE):
        return
    report.outcome = "failed"
    report.longrepr = f"skipped in CI, where the machine must provide it: {reason}"


@pytest.hookimpl(hookwrapper=True)
def pytest_make_collect_report(collector: pytest.Collector) -> object:
    """The same rule for a whole module skipped at collection (``pytest.importorskip`` of an
    extra that the install step should have brought): in CI it fails."""
    outcome = yield
    report = outcome.get_result()  # type: ignore[attr-defined]
    if not (os.environ.get("CI") and report.skipped):
        return
    longrepr = report.longrepr
    reason = longrepr[2] if isinstance(longrepr, tuple) else str(longrepr)
    if reason.removeprefix("Skipped: ").startswith(NOT_APPLICABLE):
        return
    report.outcome = "failed"
    report.longrepr = f"skipped in CI, where the machine must provide it: {reason}"


@pytest.fixture(scope="session")
def sample_competition(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The sample competition (``python -m ertools.samples --competition``, default seed),
    generated once for the whole session (10 s): tests read it and write nothing into it."""
    from ertools.samples.competition import DEFAULT_SEED, generate_competition

    root = tmp_path_factory.mktemp("competition") / "day"
    generate_competition(root, seed=DEFAULT_SEED)
    return root
