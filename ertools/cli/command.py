"""What the dispatcher (ertools.cli.main) runs: a command's module by name, and a group's
member handed back to it (``ertools score fbm3w``)."""

from __future__ import annotations

from collections.abc import Sequence

from ertools.frozen_dataclass import frozen_dataclass


@frozen_dataclass
class Command:
    """A command: the module that implements it, a summary and an example."""

    module: str
    summary: str
    example: str


@frozen_dataclass
class Delegate:
    """What a command group's ``run`` returns: its member to run with the words after the
    member's name, which the dispatcher parses and runs as a command of its own."""

    prog: str
    module: str
    argv: Sequence[str]
