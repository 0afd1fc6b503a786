"""The scoring processes' fork server (ertools/competition/children.py): a scorer never inherits a
lock held by another thread of the process that asked for it. (The command's server is a fork
of it, its scorers the server's children, and all end with it: test_rescore_faults.py; a
scorer that dies costs its job only: test_rescore_cli.py, test_rescore_dask.py.)"""

from __future__ import annotations

import ast
import json
import os
import signal
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from ertools.competition.children import SCORING_IMPORTS
from tests.rescore.rescore_competition import LOGS, expected_value, make_competition
from tests.rescore.test_rescore_faults import DEADLINE_S, HOLD, TOY_RESCORE, ppid, wait_for

HERE = Path(__file__).parent
ROOT = HERE.parents[1]
LOCKED = {"toy-alpha-20151120T114000": ("alpha", "2015-11-20T11:40:00Z", "1\nlocked\n5\n")}
# scored by a scorer that waited on an inherited lock, the run would never end: far longer
# than the run takes on a loaded 2-core machine (a few seconds)
HANG_S = 120


def rescore_from(
    caller: str, tmp_path: Path, manifest: Path, out: Path, *options: str
) -> subprocess.CompletedProcess[str]:
    """``rescore`` run by the script ``caller`` (its text; it adds its first argument, the toy's
    folder, to its sys.path and calls the command line with the rest), as a library caller's
    process would: its environment holds no PYTHONPATH."""
    script = tmp_path / "caller.py"
    script.write_text(textwrap.dedent(caller))
    return subprocess.run(
        [
            sys.executable,
            str(script),
            str(HERE),
            "rescore",
            "-q",
            "--no-reports",
            "--config",
            str(manifest),
            "--out",
            str(out),
            *options,
        ],
        env={k: v for k, v in os.environ.items() if k != "PYTHONPATH"},
        check=False,
        capture_output=True,
        text=True,
        timeout=HANG_S,
    )


@pytest.mark.skipif(not hasattr(os, "fork"), reason="n/a: no fork on this platform")
@pytest.mark.parametrize("parallel", [["--jobs", "2"], ["--jobs", "2", "--scheduler", "local"]])
def test_a_lock_held_by_another_thread_is_not_inherited(
    parallel: list[str], tmp_path: Path
) -> None:
    """A library caller with threads of its own (a notebook's) runs rescore while one of them
    holds a lock the scorer takes: a scorer forked from that process would wait for it for
    ever. Every execution is scored, the locked one included, by scorers that import the toy
    from the folder the caller put on its sys.path (a fresh interpreter is given it)."""
    if "--scheduler" in parallel:
        pytest.importorskip("distributed", reason="needs the dask extra: pip install -e '.[dask]'")
    comp = make_competition(tmp_path / "comp", extra=LOCKED)
    out = tmp_path / "out"
    caller = """
            import sys, threading
            sys.path.insert(0, sys.argv.pop(1))  # as a notebook adds a folder of its own
            import rescore_toy
            from ertools.benchmarks import registry
            from ertools.cli.main import main

            registry.ENTRIES = (registry.Entry("toy", "rescore_toy:TOY", "a toy benchmark"),)
            held = threading.Event()

            def hold():
                with rescore_toy.LOCK:
                    held.set()
                    threading.Event().wait()

            threading.Thread(target=hold, daemon=True).start()
            held.wait()
            raise SystemExit(main(sys.argv[1:]))
            """
    done = rescore_from(caller, tmp_path, comp.manifest, out, *parallel)
    assert done.returncode == 0, done.stderr
    rows = {r["id"]: r for r in json.loads((out / "results.json").read_text())["executions"]}
    for ident in LOGS:
        assert rows[ident]["rank_value"] == expected_value(ident)
    # the toy's value: the numbers' mean x the scale (2) + alpha's offset (0.25)
    assert rows["toy-alpha-20151120T114000"]["rank_value"] == pytest.approx(3 * 2 + 0.25)


AFTER = {  # scored after the held ones: in time order, as the toy's executions are handed out
    "toy-alpha-20151120T120000": ("alpha", "2015-11-20T12:00:00Z", "2\n4\n"),
    "toy-beta-20151120T123000": ("beta", "2015-11-20T12:30:00Z", "3\n"),
}


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="n/a: reads /proc")
def test_a_killed_server_costs_the_jobs_its_scorers_held(tmp_path: Path) -> None:
    """The fork server killed (by hand, or for memory) while its two scorers hold a job each:
    those two rows say so, and the executions after them are scored by a new server."""
    comp = make_competition(tmp_path / "comp", extra={**HOLD, **AFTER})
    pid_files = [comp.log(ident).with_name(comp.log(ident).name + ".pid") for ident in HOLD]
    out = tmp_path / "out"
    proc = subprocess.Popen(
        [*TOY_RESCORE, str(comp.manifest), "--out", str(out), "--jobs", "2"],
        env={
            **os.environ,
            "PYTHONPATH": os.pathsep.join([str(HERE), os.environ.get("PYTHONPATH", "")]),
        },
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        wait_for(
            lambda: all(p.is_file() and p.read_text().endswith("\n") for p in pid_files),
            "both held executions being scored",
        )
        scorers = {int(p.read_text()) for p in pid_files}
        (server,) = {ppid(pid) for pid in scorers}
        os.kill(server, signal.SIGKILL)
        _, err = proc.communicate(timeout=DEADLINE_S)
    finally:
        proc.kill()
        proc.wait()
    assert proc.returncode == 1, err
    rows = {r["id"]: r for r in json.loads((out / "results.json").read_text())["executions"]}
    for ident in HOLD:
        assert rows[ident]["status"] == "failed"
        assert "the worker scoring it died (its fork server ended)" in rows[ident]["reason"]
    for ident in LOGS:
        assert rows[ident]["rank_value"] == expected_value(ident)
    # the numbers' mean x the scale (2) + the team's offset (alpha 0.25, beta 10)
    assert rows["toy-alpha-20151120T120000"]["rank_value"] == pytest.approx(3 * 2 + 0.25)
    assert rows["toy-beta-20151120T123000"]["rank_value"] == pytest.approx(3 * 2 + 10.0)
    assert "Traceback" not in err


@pytest.mark.skipif(not hasattr(os, "fork"), reason="n/a: no fork on this platform")
def test_a_server_that_cannot_fork_costs_each_job_its_row(tmp_path: Path) -> None:
    """The server runs but the system refuses it a process (EAGAIN: out of processes): each
    execution's row says so, in one line; the command ends with the others' outcome (1), not
    a traceback, and not the silent 0 a broken pipe would give."""
    comp = make_competition(tmp_path / "comp")
    out = tmp_path / "out"
    caller = """
            import errno, os, sys
            sys.path.insert(0, sys.argv.pop(1))
            from ertools.benchmarks import registry
            from ertools.cli.main import main

            registry.ENTRIES = (registry.Entry("toy", "rescore_toy:TOY", "a toy benchmark"),)
            command, fork = os.getpid(), os.fork

            def refused():  # in the server only: the command forks the server itself
                if os.getpid() != command:
                    raise OSError(errno.EAGAIN, os.strerror(errno.EAGAIN))
                return fork()

            os.fork = refused
            raise SystemExit(main(sys.argv[1:]))
            """
    done = rescore_from(caller, tmp_path, comp.manifest, out, "--jobs", "2")
    assert done.returncode == 1, done.stderr
    rows = json.loads((out / "results.json").read_text())["executions"]
    assert {r["id"] for r in rows} == set(LOGS)
    for row in rows:
        assert row["status"] == "failed"
        assert row["reason"] == (
            "no process could score it: the fork server could not start a scoring process: "
            "Resource temporarily unavailable"
        )
    assert "Traceback" not in done.stderr


def test_the_server_preloads_every_lazy_scipy_import_of_ertools() -> None:
    """Each function-level ``scipy`` import of ertools (lazy, to keep the command line's start
    fast) is among what the fork server imports as it starts: one missing is imported again by
    every scorer on its first job (scipy.stats alone: ~1 s of CPU each)."""
    lazy: dict[str, str] = {}
    for path in sorted((ROOT / "ertools").rglob("*.py")):
        tree = ast.parse(path.read_text(encoding="utf-8"))
        for func in ast.walk(tree):
            if not isinstance(func, ast.FunctionDef | ast.AsyncFunctionDef):
                continue
            for node in ast.walk(func):
                names = (
                    [node.module or ""]
                    if isinstance(node, ast.ImportFrom)
                    else [a.name for a in node.names]
                    if isinstance(node, ast.Import)
                    else []
                )
                for name in names:
                    if name.split(".")[0] == "scipy":
                        lazy[name] = f"{path.relative_to(ROOT)}:{node.lineno}"
    assert lazy, "no lazy scipy import found: the scan is broken"
    missing = {name: where for name, where in lazy.items() if name not in SCORING_IMPORTS}
    assert not missing, f"add to children.SCORING_IMPORTS: {missing}"
