"""The words of a pose source, with no bag reader behind them: the time sources, the default
tf parent, ``PARENT:CHILD`` parsing. :mod:`ertools.benchmarks.common.sources` builds the
chooser on them; the command-line builders (:mod:`ertools.cli.options`) use them to declare
options without loading numpy or the readers (``ertools noise --help`` stays instant)."""

from __future__ import annotations

from typing import Literal

TimeSource = Literal["header", "record"]
TIME_SOURCES: tuple[TimeSource, ...] = ("header", "record")
# One default for every command: the message stamp is the mocap's own clock, the same on
# every machine that logged it; the record time is when one machine's recorder got it.
DEFAULT_TIME_SOURCE: TimeSource = "header"
# The parent frame a bare child frame is read in: the mocap frame of the 2015 arena.
DEFAULT_PARENT = "world"


def parse_tf(text: str) -> tuple[str, str]:
    """``PARENT:CHILD`` as a pair of frame names.

    Raises:
        ValueError: not two non-empty names around one colon (argparse turns it into a usage
            error, exit 2).
    """
    parent, sep, child = text.partition(":")
    if not sep or not parent or not child or ":" in child:
        raise ValueError(f"{text!r}: give PARENT:CHILD, e.g. world:robot_at_work")
    return parent, child
