"""A reader that stops early (`ertools --help | head -1`, `| true`) is no error: no
BrokenPipeError traceback, nothing on stderr (issue 25)."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest


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
