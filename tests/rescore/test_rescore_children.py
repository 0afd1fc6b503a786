"""The scoring processes' fork server (ertools/rescore/children.py): a scorer never inherits a
lock held by another thread of the process that asked for it, the command's server is a fork
(it starts warm), and a scorer that dies costs its job only."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest
from rescore_competition import LOGS, expected_value, make_competition
from test_rescore_faults import HOLD, TOY_RESCORE, alive, descendants, wait_for

HERE = Path(__file__).parent
LOCKED = {"toy-alpha-20151120T114000": ("alpha", "2015-11-20T11:40:00Z", "1\nlocked\n5\n")}
# scored by a scorer that waited on an inherited lock, the run would never end: far longer
# than the run takes on a loaded 2-core machine (a few seconds)
HANG_S = 120


def _env() -> dict[str, str]:
    return {
        **os.environ,
        "PYTHONPATH": os.pathsep.join([str(HERE), os.environ.get("PYTHONPATH", "")]),
    }


@pytest.mark.skipif(not hasattr(os, "fork"), reason="n/a: no fork on this platform")
@pytest.mark.parametrize("parallel", [["--jobs", "2"], ["--jobs", "2", "--scheduler", "local"]])
def test_a_lock_held_by_another_thread_is_not_inherited(
    parallel: list[str], tmp_path: Path
) -> None:
    """A library caller with threads of its own (a notebook's) runs rescore while one of them
    holds a lock the scorer takes: a scorer forked from that process would wait for it for
    ever. Every execution is scored, the locked one included."""
    if "--scheduler" in parallel:
        pytest.importorskip("distributed", reason="needs the dask extra: pip install -e '.[dask]'")
    comp = make_competition(tmp_path / "comp", extra=LOCKED)
    caller = tmp_path / "caller.py"
    caller.write_text(
        textwrap.dedent(
            """
            import sys, threading
            import rescore_toy
            from ertools.benchmarks import registry
            from ertools.cli.main import main

            registry.REGISTRY = {"toy": "rescore_toy:TOY"}
            held = threading.Event()

            def hold():
                with rescore_toy.LOCK:
                    held.set()
                    threading.Event().wait()

            threading.Thread(target=hold, daemon=True).start()
            held.wait()
            raise SystemExit(main(sys.argv[1:]))
            """
        )
    )
    out = tmp_path / "out"
    done = subprocess.run(
        [
            sys.executable,
            str(caller),
            "rescore",
            "-q",
            "--no-reports",
            "--config",
            str(comp.manifest),
            "--out",
            str(out),
            *parallel,
        ],
        env=_env(),
        check=False,
        capture_output=True,
        text=True,
        timeout=HANG_S,
    )
    assert done.returncode == 0, done.stderr
    rows = {r["id"]: r for r in json.loads((out / "results.json").read_text())["executions"]}
    for ident in LOGS:
        assert rows[ident]["rank_value"] == expected_value(ident)
    # the toy's value: the numbers' mean x the scale (2) + alpha's offset (0.25)
    assert rows["toy-alpha-20151120T114000"]["rank_value"] == pytest.approx(3 * 2 + 0.25)


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="n/a: reads /proc")
@pytest.mark.parametrize("parallel", [["--jobs", "2"], ["--jobs", "2", "--scheduler", "local"]])
def test_the_command_forks_its_server_and_its_scorers(parallel: list[str], tmp_path: Path) -> None:
    """The command has one thread when its server starts: the server is a fork of it (warm,
    in milliseconds), not a fresh interpreter; the two scorers are the server's children, and
    the three end when the command is killed."""
    if "--scheduler" in parallel:
        pytest.importorskip("distributed", reason="needs the dask extra: pip install -e '.[dask]'")
    comp = make_competition(tmp_path / "comp", extra=HOLD)
    pid_files = [comp.log(ident).with_name(comp.log(ident).name + ".pid") for ident in HOLD]
    proc = subprocess.Popen(
        [*TOY_RESCORE, str(comp.manifest), "--out", str(tmp_path / "out"), *parallel],
        env=_env(),
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    tree: list[int] = []
    try:
        wait_for(
            lambda: all(p.is_file() and p.read_text().endswith("\n") for p in pid_files),
            "both executions being scored",
        )
        scorers = {int(p.read_text()) for p in pid_files}
        tree = descendants(proc.pid)
        parents = {pid: _ppid(pid) for pid in tree}
        servers = [pid for pid in tree if parents[pid] == proc.pid]
        assert len(servers) == 1, f"one server below the command: {tree}"
        assert {parents[pid] for pid in scorers} == set(servers)
        assert "ertools.rescore.children" not in _cmdline(servers[0])
        assert _cmdline(servers[0]) == _cmdline(proc.pid)  # a fork: the command's own line
        proc.send_signal(signal.SIGKILL)
        proc.wait()
        wait_for(lambda: not any(alive(p) for p in tree), "the server and scorers ending")
    finally:
        proc.kill()
        proc.wait()
        for pid in tree:  # only if the test failed: leave nothing behind
            if alive(pid):
                os.kill(pid, signal.SIGKILL)


def _ppid(pid: int) -> int:
    status = Path(f"/proc/{pid}/status").read_text()
    return int(status.split("\nPPid:\t", 1)[1].split("\n", 1)[0])


def _cmdline(pid: int) -> str:
    return Path(f"/proc/{pid}/cmdline").read_bytes().replace(b"\0", b" ").decode()
