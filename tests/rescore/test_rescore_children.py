"""The scoring processes' fork server (ertools/rescore/children.py): a scorer never inherits a
lock held by another thread of the process that asked for it. (The command's server is a fork
of it, its scorers the server's children, and all end with it: test_rescore_faults.py; a
scorer that dies costs its job only: test_rescore_cli.py, test_rescore_dask.py.)"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest
from rescore_competition import LOGS, expected_value, make_competition

HERE = Path(__file__).parent
LOCKED = {"toy-alpha-20151120T114000": ("alpha", "2015-11-20T11:40:00Z", "1\nlocked\n5\n")}
# scored by a scorer that waited on an inherited lock, the run would never end: far longer
# than the run takes on a loaded 2-core machine (a few seconds)
HANG_S = 120


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
    caller = tmp_path / "caller.py"
    caller.write_text(
        textwrap.dedent(
            """
            import sys, threading
            sys.path.insert(0, sys.argv.pop(1))  # as a notebook adds a folder of its own
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
            str(HERE),
            "rescore",
            "-q",
            "--no-reports",
            "--config",
            str(comp.manifest),
            "--out",
            str(out),
            *parallel,
        ],
        env={k: v for k, v in os.environ.items() if k != "PYTHONPATH"},
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
