"""The sample logs: ``sample_bags/<name>`` when present, else generated once into a temp dir."""

from __future__ import annotations

from pathlib import Path

import pytest
import yaml

from ertools.samples.__main__ import generate

REPO = Path(__file__).resolve().parents[2]


def sample_dir(name: str, tmp_factory: pytest.TempPathFactory) -> Path:
    """The folder of scenario ``name`` (bag, configs, answers)."""
    shipped = REPO / "sample_bags" / name
    if shipped.is_dir() and any(shipped.glob("*.answers.yaml")):
        return shipped

    out = tmp_factory.mktemp(f"samples_{name}")
    generate(out, [name])
    return out / name


def answers(folder: Path) -> dict:  # type: ignore[type-arg]
    (path,) = folder.glob("*.answers.yaml")
    data = yaml.safe_load(path.read_text(encoding="utf-8"))
    assert isinstance(data, dict)
    return data
