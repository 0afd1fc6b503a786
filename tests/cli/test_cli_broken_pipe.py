"""A reader that stops early (`ertools --help | head -1`, `| true`) is no error: no
BrokenPipeError traceback, nothing on stderr (issue 25)."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest


@pytest.mark.slow_cases("argv3")
@pytest.mark.parametrize("argv", [[], ["--help"], ["--version"], ["info", "--help"]])
def test_a_closed_stdout_is_not_an_error(argv: list[str]) -> None:
    # the pipe's reading end is closed before ertools starts: its first write finds the
    # pipe broken, every time (`| true` only races to do the same)
    read_end, write_end = os.pipe()
    os.close(read_end)
    try:
        proc = subprocess.run(
            [sys.executable, "-m", "ertools.cli.main", *argv],
            stdout=write_end,
            stderr=subprocess.PIPE,
            text=True,
            check=False,
        )
    finally:
        os.close(write_end)
    assert proc.stderr == ""
    assert proc.returncode in (0, 2)  # bare `ertools` is a usage error (2) that shows the help


def test_a_broken_pipe_of_its_own_is_an_error_not_a_silent_success() -> None:
    """A BrokenPipeError from a pipe or socket of ertools' own (a scoring process's, gone),
    while stdout's reader is still there: one error line and exit 1, never the silent 0 of a
    reader that stopped early (the results would be missing without a word)."""
    script = (
        "import ertools.cli.info as info\n"
        "def run(args):\n"
        "    raise BrokenPipeError(32, 'Broken pipe')\n"
        "info.run = run\n"
        "from ertools.cli.main import main\n"
        "raise SystemExit(main(['info', 'x.bag']))\n"
    )
    proc = subprocess.run(
        [sys.executable, "-c", script], capture_output=True, text=True, check=False
    )
    assert proc.returncode == 1
    assert proc.stderr == (
        "ertools: error: unexpected BrokenPipeError: [Errno 32] Broken pipe (this is a bug in "
        "ertools; re-run with --debug for the traceback)\n"
    )
    assert proc.stdout == ""
