"""The FBM3@Work sample as the tests see it (a bag, its rosbag2-MCAP copy, the answers)."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import yaml

import ertools.benchmarks.fbm3w.sample as scenario


@dataclass(frozen=True)
class Sample:
    bag: Path
    mcap: Path
    config: Path
    answers: dict[str, Any]

    def expected_run(self, index: int) -> dict[str, Any]:
        runs: dict[str, Any] = self.answers["expected"]["runs_details"]
        return dict(runs[str(index)])

    def windows(self) -> tuple[tuple[str, float, float, float], ...]:
        """The completed runs' state windows, seconds from the bag's first message."""
        return tuple(
            (r["spec"], r["reference_s"], r["start_s"], r["end_s"])
            for r in self.answers["truth"]["runs"]
            if r["status"] == "completed"
        )


def generate_sample(out: Path, seed: int, *, sigma: float | None = None) -> Sample:
    """Run the scenario into ``out`` (with another noise sigma when given)."""
    saved = scenario.SIGMA_M
    if sigma is not None:
        scenario.SIGMA_M = sigma
    try:
        bag, mcap, config, answers = scenario.generate(out, seed=seed)
    finally:
        scenario.SIGMA_M = saved
    return Sample(bag, mcap, config, yaml.safe_load(answers.read_text()))
