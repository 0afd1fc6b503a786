"""The in-process runner (tests/helpers/inprocess.py) and the shell bridge
(tests/helpers/shell_bridge.py): a command run in the test's process prints what the process
prints, and leaves nothing behind.
"""

from __future__ import annotations

import logging
import os
import subprocess
import sys
import warnings
from pathlib import Path

import pytest

from ertools import caches
from ertools.cli import info
from ertools.io.mcap import scan, summary
from tests.helpers.inprocess import run
from tests.helpers.shell_bridge import parse_request, run_bash

ROOT = Path(__file__).resolve().parents[2]
BAG = "sample_bags/fbm3w/log_fbm3w_mocap_2015-11-20-12-00-00_0.bag"
MCAP = next(iter(sorted((ROOT / "sample_bags").rglob("*.mcap"))), None)


def test_exit_status_stdout_and_stderr_apart() -> None:
    ran = run(["info", "no-such.bag"], cwd=ROOT)
    assert (ran.code, ran.stdout) == (1, "")
    assert ran.stderr.startswith("ertools: error: no-such.bag")
    ran = run(["-V"])
    assert (ran.code, ran.stdout, ran.stderr) == (0, "ertools 0.1.0\n", "")
    usage = run(["info"])
    assert usage.code == 2 and "the following arguments are required: BAG" in usage.stderr


def test_folder_environment_and_logger_are_put_back(tmp_path: Path) -> None:
    before = os.getcwd(), dict(os.environ), logging.getLogger("ertools").handlers[:]
    (tmp_path / "x").mkdir()
    ran = run(["info", BAG, "-o", str(tmp_path / "x" / "info.txt")], cwd=ROOT, env={"A": "1"})
    assert ran.code == 0, ran.stderr
    assert (tmp_path / "x" / "info.txt").read_text().startswith("path:")
    assert (os.getcwd(), dict(os.environ), logging.getLogger("ertools").handlers) == before


def test_a_relative_path_is_read_from_the_folder_given(tmp_path: Path) -> None:
    assert run(["info", BAG], cwd=tmp_path).code == 1  # not there
    assert run(["info", BAG], cwd=ROOT).code == 0


@pytest.mark.skipif(MCAP is None, reason="n/a: the samples hold no MCAP file")
def test_file_memories_are_emptied_before_and_after() -> None:
    assert MCAP is not None
    assert run(["info", str(MCAP)]).code == 0
    assert not summary._SUMMARIES and not scan._SCANS and not scan._LAYOUTS
    caches.clear()


def test_a_warning_is_printed_each_time_as_by_a_new_process() -> None:
    """Python's "once per place" memory is per process: the second run prints it again."""

    def warn_then_fail(args: object) -> int:
        warnings.warn("careful", UserWarning, stacklevel=1)
        return 3

    saved = info.run
    info.run = warn_then_fail  # type: ignore[assignment]
    try:
        first, second = run(["info", BAG]), run(["info", BAG])
    finally:
        info.run = saved
    assert first.code == second.code == 3
    assert "UserWarning: careful" in first.stderr
    assert "UserWarning: careful" in second.stderr


def test_merged_output_interleaves_as_written() -> None:
    ran = run(["info", BAG, "no-such.bag"], cwd=ROOT, merge=True)
    assert ran.stderr == ""
    # the first bag described (stdout), then the second's error (stderr), in one text
    assert ran.code == 1
    assert 0 <= ran.stdout.index(BAG) < ran.stdout.index("ertools: error: no-such.bag")


def test_requests_parse_with_empty_and_spaced_arguments() -> None:
    assert parse_request(b"12\0/tmp/a b\x002\0\0x y\0") == (12, "/tmp/a b", ["", "x y"])
    assert parse_request(b"7\0/\x000\0") == (7, "/", [])


# Quoting, a variable, a glob, redirections, a pipe into another program, a failure turned into
# text, stderr thrown away: what the pages do.
SCRIPT = """
set -euo pipefail
B=sample_bags/fbm3w
ertools info "$B"/*.bag --format json | head -3
ertools info $B/log_fbm3w_mocap_2015-11-20-12-00-00_0.bag > info.txt
wc -l < info.txt
ertools info missing.bag 2>/dev/null || echo "exit status $?"
ertools info missing.bag 2>&1 | tail -1 || echo "exit status $?"
ertools -V
ertools info --format table $B/log_fbm3w_mocap_2015-11-20-12-00-00_0.bag >> info.txt
wc -l < info.txt
"""


@pytest.mark.slow
def test_the_bridge_prints_what_the_processes_print(tmp_path: Path) -> None:
    """The same script through bash with ``ertools`` as the console script and through the
    bridge: the same output, byte for byte, and the same files."""
    outputs = []
    for how in ("process", "bridge"):
        work = tmp_path / how
        work.mkdir()
        (work / "sample_bags").symlink_to(ROOT / "sample_bags")
        env = {**os.environ, "PATH": f"{Path(sys.executable).parent}:{os.environ['PATH']}"}
        if how == "process":
            proc = subprocess.run(
                ["bash", "-c", SCRIPT],
                cwd=work,
                env=env,
                capture_output=True,
                text=True,
                timeout=120,
                check=False,
            )
            got = proc.returncode, proc.stdout, proc.stderr
        else:
            got = run_bash(SCRIPT, cwd=work, env=env, timeout=120, merge=False)
        outputs.append((*got, (work / "info.txt").read_text()))
    assert outputs[0][0] == 0, outputs[0][2]
    assert outputs[1] == outputs[0]
    assert "exit status 1" in outputs[0][1]
