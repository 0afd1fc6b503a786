"""``make demo`` runs the commands the README tour shows, with the same options."""

from __future__ import annotations

import shlex
from pathlib import Path

import pytest

from ertools import demo
from ertools.cli import score
from ertools.cli.main import COMMANDS, build_parser
from ertools.demo import steps
from tests.e2e.test_readme import ROOT, console_blocks

# Where the output goes is the demo's business, not a scoring option.
OUTPUT_OPTIONS = frozenset(
    {"--report", "--format", "--plot", "--plots", "--out", "-o", "--out-dir", "--foxglove"}
)


def _options(argv: list[str]) -> frozenset[str]:
    return frozenset(a for a in argv if a.startswith("-") and a not in OUTPUT_OPTIONS)


def _key(argv: list[str]) -> tuple[str, ...]:
    """The command (``score trajectory``, ``audit``...) a command line runs."""
    return tuple(argv[:2]) if argv[0] == "score" else (argv[0],)


def test_demo_steps_use_the_options_the_readme_shows(tmp_path: Path) -> None:
    readme: dict[tuple[str, ...], frozenset[str]] = {}
    for commands, _ in console_blocks((ROOT / "README.md").read_text(encoding="utf-8")):
        for command in commands:
            argv = shlex.split(command.replace("\\\n", " "), comments=True)
            if argv and argv[0] == "ertools" and "sample_bags" in command:
                readme.setdefault(_key(argv[1:]), _options(argv[1:]))
    demo = {_key(step.argv): _options(step.argv) for step in steps(ROOT / "sample_bags", tmp_path)}
    shared = set(readme) & set(demo)
    # The demo covers the tour's scoring commands, so its reports are the README's numbers.
    assert {("score", "fbm3w"), ("score", "fbm2h"), ("score", "trajectory"), ("audit",)} <= shared
    for key in sorted(shared):
        assert demo[key] == readme[key], f"ertools {' '.join(key)}: demo and README differ"


def test_the_demo_lists_no_empty_output(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """Every `-> FILE` the demo prints is a file with content: a command printing nothing on
    stdout (rescore writes its own folder; a failed step) leaves no 0-byte file behind."""
    printed_by = {"timeline", "info", "noise"}  # the others print nothing in this fake

    def fake_main(argv: list[str]) -> int:
        if argv[0] in printed_by:
            print("some output")
        if argv[0] == "rescore" and "--init" in argv:  # the season's manifest drafted
            Path(argv[argv.index("--init") + 1]).write_text("version: 1\n")
            return 0
        if argv[0] == "rescore":
            out = Path(argv[argv.index("--out") + 1])
            out.mkdir(parents=True)
            (out / "index.html").write_text("<html></html>")
            return 1 if Path(argv[1]).name == "competition" else 0  # the day's planted problems
        return 0

    monkeypatch.setattr(demo, "ertools_main", fake_main)
    monkeypatch.setattr(demo, "make_competition", lambda day: None)
    assert demo.run(tmp_path) == 0
    err = capsys.readouterr().err
    listed = [Path(line.split("-> ", 1)[1].split(" (exit")[0]) for line in err.splitlines()
              if "   -> " in line]  # fmt: skip
    assert len(listed) == len(printed_by) + 2  # and the two rescore sites
    assert "nothing on stdout" in err
    files = [p for p in listed if p.is_file()]
    assert files and all(p.stat().st_size > 0 for p in files)
    assert (tmp_path / "rescore" / "index.html") in files
    assert (tmp_path / "season" / "index.html") in files
    assert not [p for p in tmp_path.rglob("*") if p.is_file() and p.stat().st_size == 0]


def test_every_demo_step_parses(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """Each step's command line is one the real parser takes (the referee-scored benchmarks
    refuse --foxglove: the demo once passed it and failed three steps)."""
    refused = []
    for step in steps(ROOT / "sample_bags", tmp_path):
        name, argv = step.argv[0], step.argv[1:]
        if name == "score":  # a group: the member's own parser takes the words after its name
            prog, module, argv = f"ertools score {argv[0]}", score.__name__, argv[1:]
        else:
            prog, module = f"ertools {name}", COMMANDS[name].module
        parser, _ = build_parser(prog, module)
        try:
            parser.parse_args(argv)
        except SystemExit:
            refused.append(" ".join(step.argv[:2]))
    assert not refused, (refused, capsys.readouterr().err)
