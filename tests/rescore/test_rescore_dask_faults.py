"""The Dask scheduler lost mid-run (issue 25, item 4): rescore ends, the executions it held are
failed rows, the results are written, and stderr has one line about it, no traceback from
`distributed`'s logger."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
from pathlib import Path

import pytest

from tests.rescore.rescore_competition import make_competition
from tests.rescore.test_rescore_dask import DASK, free_port, worker_command
from tests.rescore.test_rescore_faults import HOLD, TOY_RESCORE, wait_for

pytestmark = pytest.mark.slow

distributed = pytest.importorskip(
    "distributed", reason="needs the dask extra: pip install -e '.[dask]'"
)
# the toy's folder: tests/rescore/toy_main.py registers it as `rescore_toy`, which the workers
# import from there
HERE = Path(__file__).parent


def test_the_scheduler_lost_is_one_line(tmp_path: Path) -> None:
    if not DASK.exists():
        pytest.skip(f"no dask command beside {sys.executable}")
    port = free_port()
    address = f"tcp://127.0.0.1:{port}"
    env = {
        **os.environ,
        "PYTHONPATH": os.pathsep.join([str(HERE), os.environ.get("PYTHONPATH", "")]),
    }
    logs = (tmp_path / "dask.log").open("w")
    scheduler = subprocess.Popen(
        [str(DASK), "scheduler", "--host", "127.0.0.1", "--port", str(port), "--no-dashboard"],
        env=env,
        stdout=logs,
        stderr=subprocess.STDOUT,
    )
    worker = subprocess.Popen(
        worker_command(address, tmp_path),
        env=env,
        stdout=logs,
        stderr=subprocess.STDOUT,
    )
    comp = make_competition(tmp_path / "comp", extra=dict(list(HOLD.items())[:1]))
    ident = next(iter(HOLD))
    pid_file = comp.log(ident).with_name(comp.log(ident).name + ".pid")
    out = tmp_path / "out"
    proc = None
    try:
        with distributed.Client(address, timeout="20s") as client:
            client.wait_for_workers(1, timeout=30)
        proc = subprocess.Popen(
            [*TOY_RESCORE, str(comp.manifest), "--out", str(out), "--scheduler", address],
            env=env,
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
        )
        wait_for(lambda: pid_file.is_file() and pid_file.read_text().endswith("\n"), "held")
        # the three scored before the held one are gathered (and cached) before the scheduler
        # goes: a result still on its way to the client when the scheduler dies is lost with it
        outcomes = out / "cache" / "outcomes"
        wait_for(lambda: len(list(outcomes.glob("*.json"))) >= 3, "the others gathered")
        scheduler.send_signal(signal.SIGKILL)
        scheduler.wait()
        _, err = proc.communicate(timeout=120)
        assert proc.returncode == 1, err
        assert "Traceback" not in err and " - ERROR - " not in err, err
        dask_lines = [line for line in err.splitlines() if "Dask (" in line]
        assert len(dask_lines) == 1 and address in dask_lines[0], err
        rows = {r["id"]: r for r in json.loads((out / "results.json").read_text())["executions"]}
        assert rows[ident]["status"] == "failed"
        assert "scheduler" in rows[ident]["reason"]
        # the others were scored before the scheduler went, and their values are right
        assert [r["status"] for i, r in rows.items() if i != ident] == ["scored"] * 3
    finally:
        for p in (proc, scheduler, worker):
            if p is not None:
                p.kill()
                p.wait()
        logs.close()
