"""Every ``<score>_interval`` brackets ``<score>`` (issue 39): the JSON of every sample
command, as the README runs it, walked key by key.

A referee reads ``K_interval`` as the uncertainty of ``K``: the interval must contain the
number it is named after, at every depth of the result (runs, segments, percentiles, the
scores at the fitted clock offset). The commands are the README's ``ertools score`` lines
on ``sample_bags/`` (its tour and its "I have my own bags" examples), and the sample robot
log scored without ``--apply-offset``, whose clock the audit finds 0.35 s off.
"""

from __future__ import annotations

import json
import shlex
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from inprocess import run

ROOT = Path(__file__).resolve().parents[2]
README = ROOT / "README.md"
# options that write files elsewhere: the JSON on stdout is what is walked
DROPPED = {"--report": 1, "--foxglove": 1, "--plot": 1, "--plots": 1}


def readme_score_commands() -> list[list[str]]:
    """The README's ``$ ertools score ...`` commands on the samples, continuations joined,
    their file-writing options and redirections dropped."""
    text = README.read_text(encoding="utf-8").replace("\\\n", " ")
    out = []
    for line in text.splitlines():
        if not line.startswith("$ ertools score ") or "sample_bags/" not in line:
            continue
        words = shlex.split(line[2:].split(">", 1)[0])[1:]
        argv: list[str] = []
        skip = 0
        for w in words:
            if skip:
                skip -= 1
            elif w in DROPPED:
                skip = DROPPED[w]
            else:
                argv.append(w)
        if argv not in out:
            out.append(argv)
    return out


COMMANDS = [
    *readme_score_commands(),
    [
        "score",
        "trajectory",
        "sample_bags/robotlog/FBM2H_201511201200_homer.bag",
        "sample_bags/robotlog/",
    ],
]


def intervals(node: Any, path: str = "") -> Iterator[tuple[str, Any, Any]]:
    """(dotted key, score, interval) of every ``K_interval`` in a JSON document."""
    if isinstance(node, dict):
        for key, value in node.items():
            if key.endswith("_interval") and key != "uncertainty":
                base = key.removesuffix("_interval")
                yield f"{path}{base}", node.get(base), value
            else:
                yield from intervals(value, f"{path}{key}.")
    elif isinstance(node, list):
        for i, value in enumerate(node):
            yield from intervals(value, f"{path}{i}.")


def test_the_readme_commands_were_found() -> None:
    benchmarks = {argv[1] for argv in COMMANDS}
    assert benchmarks == {"fbm3w", "fbm2h", "fbm1h", "trajectory"}, COMMANDS


@pytest.mark.parametrize(
    "argv", COMMANDS, ids=[" ".join(a[:2]) + f" #{i}" for i, a in enumerate(COMMANDS)]
)
def test_every_interval_holds_its_score(argv: list[str]) -> None:
    ran = run([*argv, "--format", "json"], cwd=ROOT)
    assert ran.code in (0, 1), ran.stderr  # 1: a benchmark's failed runs, still scored
    document = json.loads(ran.stdout)
    found = list(intervals(document))
    assert found, "no interval in the result"
    for key, score, iv in found:
        if iv is None:
            continue  # a score without interval (too few draws): said on stderr
        assert isinstance(score, int | float), f"{key}_interval beside {score!r}"
        low, high = iv
        assert low <= score <= high, f"{key} {score} outside its interval [{low}, {high}]"
