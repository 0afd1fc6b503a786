"""The generated robot log with its two GT split files, shared by the trajectory tests."""

from __future__ import annotations

from typing import Any

import pytest
import yaml

from ertools.benchmarks.trajectory.sample import generate


@pytest.fixture(scope="session")
def robotlog(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    """Paths of the generated robot log and GT files, and the generator's answers."""

    out = tmp_path_factory.mktemp("robotlog")
    paths = generate(out, seed=7)
    answers = yaml.safe_load(paths[-1].read_text(encoding="utf-8"))
    return {
        "dir": out,
        "robot": paths[0],
        "gt": paths[1:3],
        "answers": answers,
    }


@pytest.fixture()
def robot_cli(robotlog: dict[str, Any]) -> list[str]:
    """The start of a `score trajectory` command line on the generated logs."""
    return [
        "score",
        "trajectory",
        str(robotlog["robot"]),
        *map(str, robotlog["gt"]),
        "--robot-topic",
        "/rockin/homer/marker_pose",
        "--gt-topic",
        "/fbm2h/robot_at_home/pose",
    ]
