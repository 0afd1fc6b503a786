"""The top-level CLI: help, unknown commands, exit codes."""

from __future__ import annotations

import logging
import subprocess
import sys
import time

import pytest

from ertools.cli.logs import configure_logging
from ertools.cli.main import COMMANDS, main
from ertools.cli.output import note


def test_help_lists_every_command_with_an_example(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["--help"]) == 0
    out = capsys.readouterr().out
    for name, cmd in COMMANDS.items():
        assert f"  {name} " in out
        assert cmd.example in out


def test_no_arguments_is_a_usage_error(capsys: pytest.CaptureFixture[str]) -> None:
    assert main([]) == 2


def test_unknown_command(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["frobnicate"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "unknown command 'frobnicate'" in err


@pytest.mark.xdist_group("timing")
def test_help_is_instant_and_imports_nothing_heavy() -> None:
    code = (
        "import sys, time; t=time.perf_counter(); from ertools.cli.main import main; "
        "import contextlib, io\n"
        "with contextlib.redirect_stdout(io.StringIO()): main(['--help'])\n"
        "heavy=[m for m in ('numpy','scipy','rosbags','matplotlib','pandas','mcap') "
        "if m in sys.modules]; print(','.join(heavy))"
    )
    start = time.perf_counter()
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == ""
    # Generous bound: interpreter start-up alone is ~30 ms; heavy imports would add ~1 s.
    assert time.perf_counter() - start < 3.0


def test_library_warnings_read_like_the_cli_notes(capsys: pytest.CaptureFixture[str]) -> None:
    # Logged warnings and cli.output.note warnings share one wording: "ertools: warning: ...".
    root = logging.getLogger("ertools")
    saved = (root.handlers[:], root.level, root.propagate)
    try:
        configure_logging(1)
        logging.getLogger("ertools.somewhere").warning("%d files overlap", 2)
        logging.getLogger("ertools.somewhere").info("reading")
        note("warning: a note")
    finally:
        root.handlers[:], root.level, root.propagate = saved
    assert capsys.readouterr().err.splitlines() == [
        "ertools: warning: 2 files overlap",
        "ertools: info: reading",
        "ertools: warning: a note",
    ]
