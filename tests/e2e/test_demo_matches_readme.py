"""``make demo`` runs the commands the README tour shows, with the same options."""

from __future__ import annotations

import shlex
from pathlib import Path

from test_readme import ROOT, console_blocks

from ertools.demo import steps

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
