"""Offline acquisition of calibration data from mocap logs (seed 7.1.4 and 7.2.7)."""

from __future__ import annotations

import argparse

from ertools.cli.command import Command, Delegate
from ertools.cli.groups import add_group_arguments, run_group

MEMBERS: dict[str, Command] = {
    "transform": Command(
        "ertools.cli.acquire_transform",
        "marker-to-robot transform of a robot standing at the testbed origin (Listing 11)",
        "ertools acquire transform robot.bag --team homer",
    ),
    "items": Command(
        "ertools.cli.acquire_items",
        "FBM1 item transforms from a vanilla item list (Listing 9)",
        "ertools acquire items items.bag --items fbm1h-vanilla.yaml",
    ),
}


def add_arguments(parser: argparse.ArgumentParser) -> None:
    add_group_arguments(parser, MEMBERS)


def members() -> dict[str, Command]:
    """The group's members (every group module has this function)."""
    return MEMBERS


def run(args: argparse.Namespace) -> int | Delegate:
    return run_group("acquire", MEMBERS, args)
