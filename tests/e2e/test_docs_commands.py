"""Every ``console`` block of ``docs/*.md``, pasted as printed into one shell per page.

Each page's ``$ `` lines (with their ``\\`` continuations) run in order in one bash session after
the README's ``. .venv/bin/activate``, from a folder laid out as a clone is (a copy of
``sample_bags/``, ``.venv``, ``../shared``), so nothing is written into the repository. A command
must exit 0 (a page shows an expected failure as ``cmd || echo "exit status $?"``), and the output
lines shown under a command (stdout and stderr, as a terminal shows them) must appear in its output
in that order; ``...`` on its own line elides output, and a shown line ending in ``...`` stands for
any line that starts with the text before it (for digits that differ between machines, times,
ports). Commands that are only illustrations (placeholders, servers) live in ``text`` blocks,
which this test does not run.

The shell is a real bash; its ``ertools`` commands run in the test's own process
(tests/helpers/shell_bridge.py), since what a page shows is their output, not their start-up.
The pages of REAL_PROCESSES run every command as a process.
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

import pytest

from tests.helpers.shell_bridge import run_bash
from tests.helpers.stderr_text import joined_lines

ROOT = Path(__file__).resolve().parents[2]
SHARED = ROOT.parent / "shared"
DOCS = ROOT / "docs"
FENCE = re.compile(r"^```(\w*)\n(.*?)^```", re.MULTILINE | re.DOTALL)
MARK = "@@docs-command"
# Pages whose commands run as processes of their own: a recording and its monitor side by side
# (the bridge runs one command at a time). Every other page's `ertools` commands run in the
# test's process, through the same bash (tests/helpers/shell_bridge.py).
REAL_PROCESSES = {"live.md"}
# Pages whose commands need a benchmark that only a test registers: their own test runs them.
OWN_TEST = {"writing-a-benchmark.md": "tests/e2e/test_writing_a_benchmark.py"}


@dataclass(frozen=True)
class Command:
    line: int  # line of the page the command starts on, for failure messages
    text: str
    shown: tuple[str, ...]


def console_commands(page: str) -> list[Command]:
    """The commands of a page's ``console`` blocks, each with the output lines shown under it."""
    commands: list[Command] = []
    for fence in FENCE.finditer(page):
        if fence.group(1) != "console":
            continue
        first = page.count("\n", 0, fence.start(2)) + 1
        text = ""
        start = 0
        shown: list[str] = []
        continued = False
        for number, line in enumerate(fence.group(2).splitlines(), first):
            if continued:
                text += "\n" + line
            elif line.startswith("$ "):
                if text:
                    commands.append(Command(start, text, tuple(shown)))
                text, start, shown = line[2:], number, []
            elif line.strip() and line.strip() != "...":
                assert text, f"line {number}: output shown before any command"
                shown.append(line.strip())
            continued = line.endswith("\\") and bool(text)
        if text:
            commands.append(Command(start, text, tuple(shown)))
    return commands


def matches(shown: str, line: str) -> bool:
    if shown.endswith("...") and len(shown) > 3:
        return line.startswith(shown[:-3])
    return line == shown


def find(shown: str, out: list[str], start: int) -> int:
    """Index of the first output line at or after ``start`` that ``shown`` stands for, or -1."""
    return next((i for i in range(start, len(out)) if matches(shown, out[i])), -1)


def test_shown_lines_match_exactly_or_by_prefix() -> None:
    out = ["a: 0.123456789", "b: 1", "a: 0.12"]
    assert find("a: 0.1234...", out, 0) == 0
    assert find("a: 0.12", out, 0) == 2
    assert find("a: 0.12", out, 3) == -1
    assert find("b: 1...", out, 0) == 1
    assert find("c...", out, 0) == -1


def test_console_commands_parse_continuations_output_and_elisions() -> None:
    page = "a\n```console\n$ a \\\n   --b\nout: 1\n...\n$ c\n```\n```text\n$ d\n```\n"
    assert console_commands(page) == [
        Command(3, "a \\\n   --b", ("out: 1",)),
        Command(7, "c", ()),
    ]


def pages() -> list[str]:
    return sorted(
        p.name
        for p in DOCS.glob("*.md")
        if p.name not in OWN_TEST and console_commands(p.read_text(encoding="utf-8"))
    )


def test_shell_commands_in_docs_are_console_or_text_blocks() -> None:
    """A ``$ `` line in an unlabelled or ``bash`` block would escape this test unnoticed."""
    for page in DOCS.glob("*.md"):
        for fence in FENCE.finditer(page.read_text(encoding="utf-8")):
            if fence.group(1) not in ("console", "text") and "\n$ " in "\n" + fence.group(2):
                pytest.fail(f"{page.name}: a ```{fence.group(1)} block holds $ commands")


def _cases() -> list[object]:
    # live.md records and monitors side by side on a deadline: in the timing group (conftest)
    timing = pytest.mark.xdist_group("timing")
    return [pytest.param(n, marks=timing) if n == "live.md" else n for n in pages()]


@pytest.mark.slow
@pytest.mark.parametrize("name", _cases())
def test_docs_commands_run_as_printed(name: str, tmp_path: Path) -> None:
    if not SHARED.is_dir():
        pytest.skip("../shared not present: the docs' commands read its real bags")
    commands = console_commands((DOCS / name).read_text(encoding="utf-8"))
    work = tmp_path / "clone"
    work.mkdir()
    # Copies, not links: a page may regenerate the samples or the notebooks in place.
    shutil.copytree(ROOT / "sample_bags", work / "sample_bags", symlinks=True)
    shutil.copytree(ROOT / "notebooks", work / "notebooks", symlinks=True)
    (work / ".venv").symlink_to(Path(sys.prefix))
    (tmp_path / "shared").symlink_to(SHARED)
    lines = ["set -euo pipefail", ". .venv/bin/activate"]
    for number, command in enumerate(commands):
        lines += [f"printf '\\n{MARK} {number}\\n'", command.text]
    env = {k: v for k, v in os.environ.items() if k not in ("VIRTUAL_ENV", "PYTHONPATH")}
    env["PATH"] = "/usr/local/bin:/usr/bin:/bin"
    # Unbuffered, so that stdout and stderr interleave as they do in a terminal.
    env["PYTHONUNBUFFERED"] = "1"
    if name in REAL_PROCESSES:
        proc = subprocess.run(
            ["bash", "-c", "\n".join(lines)],
            cwd=work,
            env=env,
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT,
            text=True,
            timeout=300,
            check=False,
        )
        returncode, printed = proc.returncode, proc.stdout
    else:  # the same shell, its `ertools` commands in this process (tests/helpers/shell_bridge.py)
        returncode, printed, _ = run_bash("\n".join(lines), cwd=work, env=env, timeout=300)
    outputs: dict[int, list[str]] = {}
    current = -1
    for line in printed.splitlines():
        if line.startswith(MARK + " "):
            current = int(line.split()[1])
            outputs[current] = []
        elif current >= 0:
            outputs[current].append(line)
    # An error message longer than a line continues on indented lines: the docs show it whole,
    # on one line (stderr_text.joined_lines).
    outputs = {n: [x.strip() for x in joined_lines("\n".join(o))] for n, o in outputs.items()}
    ran = max(outputs, default=-1)
    if returncode != 0:
        failed = commands[ran] if ran >= 0 else None
        where = f"line {failed.line}: $ {failed.text}" if failed else "activation"
        tail = "\n".join(outputs.get(ran, [])[-20:])
        pytest.fail(f"{name} {where}\nexited {returncode}:\n{tail}")
    assert ran == len(commands) - 1
    for number, command in enumerate(commands):
        out = outputs[number]
        position = 0
        for expected in command.shown:
            found = find(expected, out, position)
            assert found >= 0, (
                f"{name} line {command.line}: $ {command.text}\nshows {expected!r}; it printed:\n"
                + "\n".join(out[:60])
            )
            position = found + 1
