"""The words of a pose source, with no bag reader behind them: the time sources, the default
tf parent, ``PARENT:CHILD`` parsing, :class:`PoseSpec` (a source as the command line gives it).
:mod:`ertools.benchmarks.common.sources` builds the
chooser on them; the command-line builders (:mod:`ertools.cli.options`) use them to declare
options without loading numpy or the readers (``ertools noise --help`` stays instant)."""

from __future__ import annotations

from typing import Literal

from ertools.errors import UsageError
from ertools.frozen_dataclass import frozen_dataclass

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


@frozen_dataclass
class PoseSpec:
    """A pose source as the command line gives it.

    Attributes:
        topic: a pose topic (PoseStamped, Pose2D, TransformStamped, PoseWithCovarianceStamped,
            Odometry), or None.
        tf: ``(parent, child)`` frames read from ``/tf`` and ``/tf_static``, or None. At most
            one of ``topic`` and ``tf`` is set; neither means "the command's default".
        time_source: ``header`` (message stamp) or ``record`` (the bag's record time); tf
            poses always carry their transforms' stamps.
        time_source_given: the user chose ``time_source`` (a fallback then says so louder).
    """

    topic: str | None = None
    tf: tuple[str, str] | None = None
    time_source: TimeSource = DEFAULT_TIME_SOURCE
    time_source_given: bool = False

    def __post_init__(self) -> None:
        if self.topic is not None and self.tf is not None:
            raise UsageError(f"give --topic {self.topic} or --tf {self.tf_text}, not both")
        if self.time_source not in TIME_SOURCES:
            raise UsageError(f"--time-source {self.time_source}: choose header or record")

    @property
    def given(self) -> bool:
        """True when the command line named a topic or a tf pair."""
        return self.topic is not None or self.tf is not None

    @property
    def tf_text(self) -> str:
        return f"{self.tf[0]}:{self.tf[1]}" if self.tf is not None else ""

    @property
    def name(self) -> str:
        """The source in messages: the topic, or ``tf PARENT:CHILD``."""
        if self.topic is not None:
            return self.topic
        return f"tf {self.tf_text}" if self.tf is not None else "the default source"

    def describe(self) -> str:
        """How the user would spell it: ``--topic /x`` or ``--tf world:robot``."""
        if self.topic is not None:
            return f"--topic {self.topic}"
        if self.tf is not None:
            return f"--tf {self.tf_text}"
        return "the default source"
