"""`ertools rescore --scheduler` on a real Dask cluster: a `dask scheduler` and two `dask worker`
processes on 127.0.0.1, started here and torn down; the results equal `--jobs 1`'s."""

from __future__ import annotations

import contextlib
import json
import os
import shutil
import socket
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from ertools.cli.main import main
from tests.rescore.rescore_competition import (
    LOGS,
    expected_value,
    make_competition,
    use_toy_registry,
)

pytestmark = pytest.mark.slow

distributed = pytest.importorskip(
    "distributed", reason="needs the dask extra: pip install -e '.[dask]'"
)

# the root of the clone: the workers import the toy the tests register from it
# (tests.rescore.rescore_toy)
ROOT = Path(__file__).resolve().parents[2]
DASK = Path(sys.executable).with_name("dask")
# fields that differ between two runs of the same work by nature
VOLATILE = ("generated", "command", "options")
ROW_VOLATILE = ("seconds", "cached")


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port: int = s.getsockname()[1]
        return port


def worker_command(address: str, tmp_path: Path) -> list[str]:
    """A `dask worker` of one thread, no nanny, on 127.0.0.1."""
    return [
        str(DASK),
        "worker",
        address,
        "--nthreads",
        "1",
        "--host",
        "127.0.0.1",
        "--no-nanny",
        "--memory-limit",
        "0",
        "--local-directory",
        str(tmp_path / "dask"),
        "--no-dashboard",
    ]


@pytest.fixture
def cluster(tmp_path: Path) -> Iterator[str]:
    if not DASK.exists():
        pytest.skip(f"no dask command beside {sys.executable}")
    port = free_port()
    address = f"tcp://127.0.0.1:{port}"
    env = {
        **os.environ,
        "PYTHONPATH": os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")]),
    }
    common = ["--no-dashboard"]
    logs = (tmp_path / "dask.log").open("w")
    procs = [
        subprocess.Popen(
            [str(DASK), "scheduler", "--host", "127.0.0.1", "--port", str(port), *common],
            env=env,
            stdout=logs,
            stderr=subprocess.STDOUT,
        )
    ]
    try:
        for _ in range(2):
            procs.append(
                subprocess.Popen(
                    worker_command(address, tmp_path),
                    env=env,
                    stdout=logs,
                    stderr=subprocess.STDOUT,
                )
            )
        with distributed.Client(address, timeout="20s") as client:
            client.wait_for_workers(2, timeout=30)
        yield address
    finally:
        # killed outright: a graceful close costs seconds each and there is nothing to keep
        for proc in procs:
            proc.kill()
        for proc in procs:
            proc.wait()
        logs.close()


def comparable(out: Path) -> dict[str, Any]:
    doc: dict[str, Any] = json.loads((out / "results.json").read_text())
    for key in VOLATILE:
        doc.pop(key)
    for row in doc["executions"]:
        for key in ROW_VOLATILE:
            row.pop(key)
        if row["report"]:
            row["report_page"] = (out / row["report"]).is_file()
    return doc


def test_dask_cluster_gives_the_results_of_one_process(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, cluster: str
) -> None:
    use_toy_registry(monkeypatch)
    extra = {
        "toy-alpha-20151120T110000": ("alpha", "2015-11-20T11:00:00Z", "1\nbad\n"),
        "toy-alpha-20151120T111000": ("alpha", "2015-11-20T11:10:00Z", "1\nboom\n"),
    }
    comp = make_competition(tmp_path / "comp", extra)
    base = ["rescore", "--config", str(comp.manifest), "--no-reports"]
    assert main([*base, "--out", str(tmp_path / "one"), "--jobs", "1"]) == 1
    assert main([*base, "--out", str(tmp_path / "dask"), "--scheduler", cluster]) == 1
    one, dask = comparable(tmp_path / "one"), comparable(tmp_path / "dask")
    assert dask == one
    rows = {r["id"]: r for r in dask["executions"]}
    for ident in LOGS:
        assert rows[ident]["rank_value"] == expected_value(ident)
    assert rows["toy-alpha-20151120T111000"]["status"] == "failed"
    # a scorer that kills its process costs its row; the workers and the other rows go on
    shutil.rmtree(tmp_path / "dask")
    comp.log("toy-alpha-20151120T111000").write_text("1\ndie\n")
    assert main([*base, "--out", str(tmp_path / "dask"), "--scheduler", cluster]) == 1
    rows = {r["id"]: r for r in comparable(tmp_path / "dask")["executions"]}
    assert rows["toy-alpha-20151120T111000"]["status"] == "failed"
    assert "process scoring it died (exit code 7)" in rows["toy-alpha-20151120T111000"]["reason"]
    assert [i for i, r in rows.items() if r["status"] == "scored"] == sorted(
        LOGS, key=lambda i: LOGS[i][1]
    )


def test_local_cluster(
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    recwarn: pytest.WarningsRecorder,
    capsys: pytest.CaptureFixture[str],
) -> None:
    """--scheduler local starts a LocalCluster of --jobs workers; with Dask's default port
    (8787) taken, nothing is said of it (its HTTP routes take a free port)."""
    taken = socket.socket()
    with contextlib.suppress(OSError):  # already taken by something else: as good
        taken.bind(("", 8787))
        taken.listen()
    use_toy_registry(monkeypatch)
    monkeypatch.setenv("PYTHONPATH", str(ROOT))
    comp = make_competition(tmp_path / "comp")
    out = tmp_path / "out"
    code = main(
        [
            "rescore",
            "--config",
            str(comp.manifest),
            "--out",
            str(out),
            "--no-reports",
            "--scheduler",
            "local",
            "--jobs",
            "2",
        ]
    )
    assert code == 0
    doc = json.loads((out / "results.json").read_text())
    assert doc["options"] == {"jobs": 2, "scheduler": "local"}
    assert {r["id"]: r["rank_value"] for r in doc["executions"]} == {
        i: expected_value(i) for i in LOGS
    }
    taken.close()
    assert not [w for w in recwarn if "already in use" in str(w.message)]
    assert "already in use" not in capsys.readouterr().err
