"""The simulated FBM2@Home sample, generated once per test session into a temp folder."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pytest
import yaml

from ertools.benchmarks.fbm2h.sample import generate


@dataclass(frozen=True)
class Sample:
    bag: Path
    goal: Path
    transform: Path
    timing: Path
    answers: dict[str, Any]

    @property
    def folder(self) -> Path:
        return self.bag.parent


@pytest.fixture(scope="session")
def fbm2h_sample(tmp_path_factory: pytest.TempPathFactory) -> Sample:
    out = tmp_path_factory.mktemp("fbm2h_sample")
    bag, goal, transform, timing, answers = generate(out, seed=2016)
    return Sample(bag, goal, transform, timing, yaml.safe_load(answers.read_text()))
