"""Recompute a benchmark score from its logs.

Each benchmark has its own options: `ertools score NAME --help`.
"""

from __future__ import annotations

import argparse

from ertools.cli.groups import add_group_arguments, run_group
from ertools.cli.main import Command

MEMBERS: dict[str, Command] = {
    "fbm1h": Command(
        "ertools.cli.score_fbm1",
        "FBM1@Home object perception",
        "ertools score fbm1h run.bag --items configs/fbm1h.yaml",
    ),
    "fbm1w": Command(
        "ertools.cli.score_fbm1",
        "FBM1@Work object perception",
        "ertools score fbm1w run.bag --items configs/fbm1w.yaml",
    ),
    "fbm2h": Command(
        "ertools.cli.score_fbm2h",
        "FBM2@Home navigation: waypoint errors",
        "ertools score fbm2h run.bag --goal goal.yaml --transform transform-homer.yaml",
    ),
    "fbm3w": Command(
        "ertools.cli.score_fbm3w",
        "FBM3@Work trajectory following: path error",
        "ertools score fbm3w run.bag --config configs/fbm3w.yaml",
    ),
    "trajectory": Command(
        "ertools.cli.score_trajectory",
        "robot log vs mocap ground truth, with clock audit",
        "ertools score trajectory robot.bag gt/ --robot-topic /rockin/homer/marker_pose",
    ),
}


def add_arguments(parser: argparse.ArgumentParser) -> None:
    add_group_arguments(parser, MEMBERS)


def run(args: argparse.Namespace) -> int:
    return run_group("score", MEMBERS, args)
