"""Test-suite root: fixtures and hooks for every test. ``tests`` is a package (pytest's
``pythonpath`` puts the clone's root on ``sys.path``): a test imports what it shares with
other folders as ``from tests.helpers.fakes import ...``."""

import contextlib
import dataclasses
import fcntl
import io
import os
import subprocess
import sys
from collections.abc import Generator, Iterator
from pathlib import Path

import pytest

from ertools.cli.main import main
from ertools.demo import competition_step
from ertools.samples.competition import DEFAULT_SEED

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


# ---------------------------------------------------------------------------------------------
# Running in parallel (`make test`: pytest-xdist, --dist loadgroup)

TESTS = Path(__file__).resolve().parent
# Tests that measure time (a bound on seconds) or hold live sockets and processes carry
# `pytest.mark.xdist_group("timing")`: they run one after another on one worker, never beside
# each other's load. Tests that take a second or more carry `pytest.mark.slow` (`make check`
# leaves them out: docs/qa.md says which); where only some cases of a parametrised test are
# slow, `pytest.mark.slow_cases("id", ...)` names them (a fixture's parameters cannot carry a
# mark of their own).


def _shares_a_module_fixture(item: pytest.Item) -> bool:
    info = getattr(item, "_fixtureinfo", None)
    if info is None:
        return False
    return any(
        d.scope in ("module", "class") for defs in info.name2fixturedefs.values() for d in defs
    )


@pytest.hookimpl(wrapper=True)
def pytest_collection_modifyitems(
    config: pytest.Config, items: list[pytest.Item]
) -> Generator[None, None, None]:
    """Marks the groups and the slow cases before xdist (and every other plugin) reads the
    marks; after them, makes sure each grouped test's node id carries its group."""
    _mark(items)
    _mark_slow_cases(config, items)
    yield
    if getattr(config.option, "loadgroup", False):  # an xdist worker under --dist loadgroup
        for item in items:
            _suffix_group(item)


def _suffix_group(item: pytest.Item) -> None:
    """``nodeid@group``, the one thing xdist's loadgroup scheduler reads a test's group from.

    xdist (3.8) writes the suffix into ``item._nodeid``, which pytest 9.2's structured node
    ids no longer read (pytest-xdist#1386): the groups were silently ignored, every worker
    set up every module fixture it drew a test of (the rescored competition twice), and the
    timing tests ran beside each other. Where xdist's own suffix took, nothing is done."""
    names = sorted(
        {
            str(m.args[0] if m.args else m.kwargs.get("name", "default"))
            for m in item.iter_markers("xdist_group")
        }
    )
    if not names:
        return
    suffix = "@" + "_".join(names)
    if item.nodeid.endswith(suffix):
        return
    wanted = item.nodeid + suffix
    node_id = getattr(item, "_id", None)
    if node_id is not None and hasattr(node_id, "_str_cache"):  # pytest >= 9.2
        # the same path, names and parameters; only the string form carries the group
        node_id = dataclasses.replace(node_id)
        object.__setattr__(node_id, "_str_cache", wanted)
        item._id = node_id
    else:
        item._nodeid = wanted  # type: ignore[attr-defined]
    assert item.nodeid == wanted, f"cannot put {item.nodeid} in its xdist group"


def _mark(items: list[pytest.Item]) -> None:
    for item in items:
        path = Path(str(item.path)).resolve()
        if not path.is_relative_to(TESTS) or item.get_closest_marker("xdist_group"):
            continue  # a group written on the test wins
        rel = path.relative_to(TESTS).as_posix()
        closure = getattr(getattr(item, "_fixtureinfo", None), "names_closure", ())
        if "rescored_competition" in closure:
            # the modules reading it on one worker: the other would wait for it, idle
            item.add_marker(pytest.mark.xdist_group("rescored_competition"))
        elif _shares_a_module_fixture(item):
            # Its module's tests on one worker: the fixture (a rescored folder, a report) is
            # made once, not once on each worker that draws one of them.
            item.add_marker(pytest.mark.xdist_group(rel))


def _mark_slow_cases(config: pytest.Config, items: list[pytest.Item]) -> None:
    """``slow`` on the cases that a test's ``slow_cases`` mark names. When whole files were
    collected (no ``path::test`` argument), a name that is no case of its test is an error:
    a typo would otherwise put a slow case back into ``make check`` unnoticed."""
    unmatched: dict[tuple[str, str], bool] = {}
    for item in items:
        mark = item.get_closest_marker("slow_cases")
        if mark is None:
            continue
        case = getattr(getattr(item, "callspec", None), "id", None)
        test = item.nodeid.partition("[")[0]
        for name in mark.args:
            unmatched.setdefault((test, name), True)
        if case in mark.args:
            item.add_marker(pytest.mark.slow)
            unmatched[(test, case)] = False
    missing = [f"{test}[{name}]" for (test, name), left in unmatched.items() if left]
    if missing and not any("::" in arg for arg in config.args):
        raise pytest.UsageError(f"slow_cases names no case of its test: {', '.join(missing)}")


@contextlib.contextmanager
def _exclusive(lock: Path) -> Iterator[None]:
    """One process at a time (the xdist workers of one session share the data they make)."""
    with lock.open("a") as fh:
        fcntl.flock(fh, fcntl.LOCK_EX)
        try:
            yield
        finally:
            fcntl.flock(fh, fcntl.LOCK_UN)


def shared_dir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A folder every worker of this session sees (the session's own under xdist)."""
    base = tmp_path_factory.getbasetemp()
    return base.parent if os.environ.get("PYTEST_XDIST_WORKER") else base


@pytest.fixture(scope="session")
def sample_competition(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The sample competition (``python -m ertools.samples --competition``, default seed),
    generated once for the whole session (10 s), by the first worker that needs it:
    tests read it and write nothing into it. Through the command, as users make it: its
    bytes are the same on every x86-64 CPU (``ertools.samples.simd``), an in-process
    ``write_competition`` call's are not (docs/samples.md)."""

    shared = shared_dir(tmp_path_factory)
    root = shared / "competition" / "day"
    with _exclusive(shared / "competition.lock"):
        if not root.is_dir():  # written whole or not at all (write_competition)
            root.parent.mkdir(parents=True, exist_ok=True)
            argv = ["--competition", str(root), "--seed", str(DEFAULT_SEED)]
            proc = subprocess.run(
                [sys.executable, "-m", "ertools.samples", *argv],
                capture_output=True,
                text=True,
                check=False,
                timeout=300,
            )
            assert proc.returncode == 0, proc.stderr
    return root


@pytest.fixture(scope="session")
def rescored_competition(
    sample_competition: Path, tmp_path_factory: pytest.TempPathFactory
) -> Path:
    """The sample competition rescored as ``make demo`` does (its step: reports, 2 jobs), once
    for the session, by the first worker that needs it: the results folder (results.json,
    index.html, a report per execution). Tests read it and write nothing into it."""

    shared = shared_dir(tmp_path_factory)
    out = shared / "rescored" / "rescore"
    with _exclusive(shared / "rescored.lock"):
        if not (out / "results.json").is_file() or not (out / "index.html").is_file():
            step = competition_step(sample_competition, out)
            err = io.StringIO()
            with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
                code = main([*step.argv, "--quiet"])
            assert code == step.expected_exit == 1, err.getvalue()[-2000:]
    return out
