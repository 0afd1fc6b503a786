"""A toy competition for the rescore tests: logs, per-team offset files and a manifest, with
the expected scores computed here by hand (mean of the numbers x scale + the team's offset)."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import pytest

from ertools.benchmarks import registry

SCALE = 2.0
OFFSETS = {"alpha": 0.25, "beta": 10.0}
# id -> (team, start, numbers); start as the manifest gives it (ISO 8601, UTC)
LOGS: dict[str, tuple[str, str, list[float]]] = {
    "toy-alpha-20151120T091000": ("alpha", "2015-11-20T09:10:00Z", [1.0, 2.0, 3.0]),
    "toy-beta-20151120T093000": ("beta", "2015-11-20T09:30:00Z", [0.5, 1.5]),
    "toy-alpha-20151120T100000": ("alpha", "2015-11-20T10:00:00Z", [4.0, 6.0]),
}


def expected_value(ident: str, offsets: dict[str, float] = OFFSETS) -> float:
    team, _, numbers = LOGS[ident]
    return sum(numbers) / len(numbers) * SCALE + offsets[team]


@dataclass(frozen=True)
class Competition:
    root: Path
    manifest: Path

    def log(self, ident: str) -> Path:
        return self.root / "logs" / f"{ident}.txt"

    def transform(self, team: str) -> Path:
        return self.root / "configs" / f"transform-{team}.yaml"


def use_toy_registry(monkeypatch: pytest.MonkeyPatch) -> None:
    """The registry holds the toy benchmark only (tests/rescore/rescore_toy.py)."""
    monkeypatch.setattr(
        registry,
        "ENTRIES",
        (registry.Entry("toy", "tests.rescore.rescore_toy:TOY", "a toy benchmark"),),
    )


def write_offsets(comp_root: Path, offsets: dict[str, float]) -> None:
    (comp_root / "configs").mkdir(parents=True, exist_ok=True)
    for team, offset in offsets.items():
        (comp_root / "configs" / f"transform-{team}.yaml").write_text(f"offset: {offset}\n")


def make_competition(
    root: Path, extra: dict[str, tuple[str, str, str]] | None = None
) -> Competition:
    """The logs of :data:`LOGS` (plus ``extra``: id -> (team, start, raw log text)) and a
    manifest listing them all."""
    (root / "logs").mkdir(parents=True)
    write_offsets(root, OFFSETS)
    entries = []
    logs = {k: (t, s, "\n".join(str(n) for n in v) + "\n") for k, (t, s, v) in LOGS.items()}
    logs.update(extra or {})
    for ident, (team, start, text) in logs.items():
        (root / "logs" / f"{ident}.txt").write_text(text)
        entries.append(
            f"  - benchmark: toy\n    team: {team}\n    bags: [logs/{ident}.txt]\n"
            f"    start: {start}\n"
        )
    teams = "".join(
        f"      {team}:\n        transform: configs/transform-{team}.yaml\n" for team in OFFSETS
    )
    manifest = root / "competition.yaml"
    manifest.write_text(
        "version: 1\ntitle: Toy Cup\nbenchmarks:\n  toy:\n    inputs:\n"
        f"      scale: {SCALE}\n    teams:\n{teams}executions:\n" + "".join(entries)
    )
    return Competition(root, manifest)
