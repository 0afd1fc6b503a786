"""docs/writing-a-benchmark.md stays true: every Python block is a verbatim excerpt of the file
its first line names (the toy benchmark of tests/helpers/toybench/ and its test), and every
console command runs as printed with the toy registered, printing the lines shown under it.

The commands run here rather than in tests/e2e/test_docs_commands.py because the toy is not
in ertools' registry: this test adds its line to the entries (the registry is not edited) and
runs the page's bash with its ``ertools`` commands in this process (tests/helpers/shell_bridge.py),
so they see the line; the page's rules for shown output are that test's.
"""

from __future__ import annotations

import os
import re
from pathlib import Path

import pytest

from ertools.benchmarks import registry
from tests.benchmarks.registry.test_registry_toy import TOY
from tests.e2e.test_docs_commands import FENCE, MARK, console_commands, find
from tests.helpers.shell_bridge import run_bash
from tests.helpers.stderr_text import joined_lines
from tests.helpers.toybench import sample

ROOT = Path(__file__).resolve().parents[2]
PAGE = ROOT / "docs" / "writing-a-benchmark.md"
HEADER = re.compile(r"# (tests/\S+\.py)\n")


def python_blocks(page: str) -> list[tuple[int, str, str]]:
    """(line, file named on the block's first line, the rest of the block) of each ``python``
    block; a block naming no file has ``""``."""
    blocks = []
    for fence in FENCE.finditer(page):
        if fence.group(1) == "python":
            line = page.count("\n", 0, fence.start(2)) + 1
            header = HEADER.match(fence.group(2))
            name, body = (header.group(1), fence.group(2)[header.end() :]) if header else ("", "")
            blocks.append((line, name, body))
    return blocks


def test_each_python_block_is_an_excerpt_of_the_file_it_names() -> None:
    blocks = python_blocks(PAGE.read_text(encoding="utf-8"))
    assert len(blocks) >= 10
    named = set()
    for line, name, body in blocks:
        assert name, f"line {line}: a python block's first line names its file (# tests/...py)"
        text = (ROOT / name).read_text(encoding="utf-8")
        assert body.strip() and body in text, f"line {line}: not a verbatim excerpt of {name}"
        named.add(Path(name).name)
    toy = {p.name for p in (ROOT / "tests" / "helpers" / "toybench").glob("*.py")}
    assert toy - named == {"__init__.py"}  # every module of the toy is quoted


def test_an_edited_excerpt_is_refused() -> None:
    page = "```python\n# tests/helpers/toybench/rules.py\nRULES = (RULE_NAN_POSES,)\n```\n"
    ((_, name, body),) = python_blocks(page)
    assert body in (ROOT / name).read_text(encoding="utf-8")
    assert body.replace("RULES", "RULE") not in (ROOT / name).read_text(encoding="utf-8")
    assert python_blocks("```python\nx = 1\n```\n") == [(2, "", "")]


@pytest.mark.slow
def test_the_commands_run_as_printed(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(registry, "ENTRIES", (*registry.ENTRIES, TOY))
    sample.generate(tmp_path, seed=1)
    commands = console_commands(PAGE.read_text(encoding="utf-8"))
    lines = ["set -euo pipefail"]
    for number, command in enumerate(commands):
        lines += [f"printf '\\n{MARK} {number}\\n'", command.text]
    env = {k: v for k, v in os.environ.items() if k not in ("VIRTUAL_ENV", "PYTHONPATH")}
    env["PATH"] = "/usr/local/bin:/usr/bin:/bin"
    returncode, printed, _ = run_bash("\n".join(lines), cwd=tmp_path, env=env, timeout=300)
    outputs: dict[int, list[str]] = {}
    for line in printed.splitlines():
        if line.startswith(MARK + " "):
            outputs[int(line.split()[1])] = []
        elif outputs:
            outputs[max(outputs)].append(line)
    assert returncode == 0, printed[-3000:]
    assert sorted(outputs) == list(range(len(commands)))
    for number, command in enumerate(commands):
        out = [x.strip() for x in joined_lines("\n".join(outputs[number]))]
        position = 0
        for expected in command.shown:
            found = find(expected, out, position)
            assert found >= 0, f"line {command.line}: $ {command.text}\nshows {expected!r}:\n" + (
                "\n".join(out[:60])
            )
            position = found + 1
