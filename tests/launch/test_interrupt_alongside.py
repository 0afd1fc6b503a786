"""A Ctrl-C while the trajectory score's clock audit runs on its second core: one line,
``ertools: interrupted``, and exit status 130; the audit's thread prints nothing."""

from __future__ import annotations

import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

pytestmark = pytest.mark.slow

ROOT = Path(__file__).resolve().parents[2]
ROBOT = ROOT / "sample_bags" / "robotlog" / "FBM2H_201511201200_homer.bag"
GT = ROOT / "sample_bags" / "robotlog"
TIMEOUT_S = 120

# The audit's search, on its thread, sends the process SIGINT after ``delay`` seconds (the
# calling thread associating meanwhile, or already waiting for the audit) and goes on for a
# while: the interrupt reaches the calling thread while the audit still runs.
HARNESS = textwrap.dedent(
    """
    import os, signal, sys, threading, time
    from ertools.__main__ import main
    from ertools.benchmarks.trajectory import comparison
    from ertools.io import pipeline

    delay = float(sys.argv[1])
    pipeline.workers = lambda: 2
    searched = comparison.search_offset

    def interrupted(*args, **kwargs):
        assert threading.current_thread() is not threading.main_thread()
        time.sleep(delay)
        os.kill(os.getpid(), signal.SIGINT)
        time.sleep(0.5)
        return searched(*args, **kwargs)

    comparison.search_offset = interrupted
    sys.argv = ["ertools", *sys.argv[2:]]
    sys.exit(main())
    """
)


@pytest.mark.parametrize("delay_s", [0.0, 0.3])
def test_a_ctrl_c_while_the_audit_runs_is_one_line(delay_s: float) -> None:
    proc = subprocess.run(
        [sys.executable, "-c", HARNESS, str(delay_s), "score", "trajectory", str(ROBOT), str(GT)],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=TIMEOUT_S,
        check=False,
    )
    assert (proc.returncode, proc.stderr, proc.stdout) == (130, "ertools: interrupted\n", "")
