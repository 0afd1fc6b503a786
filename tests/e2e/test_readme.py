"""The README's console blocks, pasted as printed into one shell after the set-up commands
(a real bash, whose ``ertools`` commands run in the test's process: tests/helpers/shell_bridge.py).

Every ``$ `` line (with its ``\\`` continuations) runs in one bash session, in order, from a
folder laid out as a clone is (``sample_bags/``, ``.venv``, ``../shared``) so that nothing is
written into the repository; the output lines the README shows must appear in that order.
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

from tests.helpers.shell_bridge import run_bash

ROOT = Path(__file__).resolve().parents[2]
SHARED = ROOT.parent / "shared"
BLOCK = re.compile(r"^```console\n(.*?)^```", re.MULTILINE | re.DOTALL)


def console_blocks(text: str) -> list[tuple[list[str], list[str]]]:
    """(commands, shown output lines) of each ``console`` block; ``...`` elides output."""
    blocks = []
    for body in BLOCK.findall(text):
        commands: list[str] = []
        shown: list[str] = []
        continued = False
        for line in body.splitlines():
            if continued:
                commands[-1] += "\n" + line
            elif line.startswith("$ "):
                commands.append(line[2:])
            elif line.strip() and line.strip() != "...":
                shown.append(line.strip())
            continued = line.endswith("\\") and bool(commands)
        blocks.append((commands, shown))
    return blocks


def test_console_blocks_parse_commands_continuations_and_output() -> None:
    text = "```console\n$ a \\\n   --b\nout: 1\n...\n$ c\n```\n"
    assert console_blocks(text) == [(["a \\\n   --b", "c"], ["out: 1"])]


@pytest.mark.slow
def test_readme_tour_runs_as_printed(tmp_path: Path) -> None:
    if not SHARED.is_dir():
        pytest.skip("../shared not present: the tour scores its real bag")
    blocks = console_blocks((ROOT / "README.md").read_text(encoding="utf-8"))
    assert len(blocks) >= 2, "the README lost its tour"
    work = tmp_path / "clone"
    work.mkdir()
    (work / "sample_bags").symlink_to(ROOT / "sample_bags")
    (work / ".venv").symlink_to(Path(sys.prefix))
    (tmp_path / "shared").symlink_to(SHARED)
    script = "set -euo pipefail\n" + "\n".join(cmd for cmds, _ in blocks for cmd in cmds)
    env = {k: v for k, v in os.environ.items() if k not in ("VIRTUAL_ENV", "PYTHONPATH")}
    # The shell of a fresh terminal: ertools is on PATH only through the tour's activation.
    env["PATH"] = "/usr/local/bin:/usr/bin:/bin"
    # a real bash; its `ertools` commands run in this process (tests/helpers/shell_bridge.py): the
    # tour is about what they print
    code, stdout, stderr = run_bash(script, cwd=work, env=env, timeout=600, merge=False)
    assert code == 0, stderr[-2000:]
    # Run in a checkout, the tour leaves nothing `git status` would show: every file it
    # writes is under a folder .gitignore ignores (out/).
    written = sorted(p.name for p in work.iterdir() if p.name not in ("sample_bags", ".venv"))
    assert written, "the tour writes its outputs somewhere"
    for name in written:
        ignored = subprocess.run(
            ["git", "check-ignore", "--no-index", "-q", name + "/"],
            cwd=ROOT,
            check=False,
        )
        assert ignored.returncode == 0, f"the tour wrote {name} into the checkout, not ignored"
    out = [line.strip() for line in stdout.splitlines()]
    position = 0
    for expected in (line for _, shown in blocks for line in shown):
        assert expected in out[position:], f"the README shows {expected!r}; the tour printed other"
        position = out.index(expected, position) + 1
