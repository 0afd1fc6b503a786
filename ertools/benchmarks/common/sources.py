"""Where a pose stream comes from, chosen once for every command and benchmark.

A pose source is a pose topic (``--topic TOPIC``) or a tf frame pair (``--tf PARENT:CHILD``),
read with a time source (``--time-source header|record``). :class:`PoseSpec` is what the
command line gives (maybe nothing); :func:`choose_source` turns it, with the command's list
of defaults, into the :class:`ertools.io.PoseSource` to read, and :func:`read_source` reads it.
Every command that reads poses goes through these two functions, so the rules below hold
everywhere:

- a source given on the command line is used as is (its topic must be in the bags);
- otherwise the first default present in the bags is used, with a warning when it is not the
  first one (the bags lack the usual topic);
- ``header`` is asked for but a message type has no header (``geometry_msgs/Pose2D``): the
  record time is used, with a warning saying so (the stamps would otherwise be zero);
- nothing fits: a :class:`~ertools.errors.TopicError` listing the pose topics there are.
"""

from __future__ import annotations

import logging
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Literal

from ertools.errors import TopicError, UsageError
from ertools.io import PoseSource, read_pose_source, topics
from ertools.io.model import POSE_TYPES, TF_TYPES
from ertools.streams import PoseStream

log = logging.getLogger(__name__)

TimeSource = Literal["header", "record"]
TIME_SOURCES: tuple[TimeSource, ...] = ("header", "record")
# One default for every command: the message stamp is the mocap's own clock, the same on
# every machine that logged it; the record time is when one machine's recorder got it.
DEFAULT_TIME_SOURCE: TimeSource = "header"
# The parent frame a bare child frame is read in: the mocap frame of the 2015 arena.
DEFAULT_PARENT = "world"
# Message types with no header stamp: ``header`` falls back on the record time there.
HEADERLESS_TYPES = ("geometry_msgs/Pose2D",)


@dataclass(frozen=True)
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

    def describe(self) -> str:
        """How the user would spell it: ``--topic /x`` or ``--tf world:robot``."""
        if self.topic is not None:
            return f"--topic {self.topic}"
        if self.tf is not None:
            return f"--tf {self.tf_text}"
        return "the default source"

    def to_io(self) -> PoseSource:
        """The reader's :class:`~ertools.io.PoseSource` (a topic, else the tf pair)."""
        if self.tf is not None:
            return PoseSource(topic=None, frame=self.tf[1], parent=self.tf[0])
        return PoseSource(topic=self.topic, time_source=self.time_source)


def topic(name: str, time_source: TimeSource = DEFAULT_TIME_SOURCE) -> PoseSpec:
    """A topic default (for :func:`choose_source`'s ``defaults``)."""
    return PoseSpec(topic=name, time_source=time_source)


def tf(child: str, parent: str = DEFAULT_PARENT) -> PoseSpec:
    """A tf default (for :func:`choose_source`'s ``defaults``)."""
    return PoseSpec(tf=(parent, child))


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


def pose_topics(present: Mapping[str, str]) -> list[str]:
    """The topics of ``present`` (name -> type) that hold poses (tf topics excluded)."""
    return [t for t, ty in present.items() if ty in POSE_TYPES and ty not in TF_TYPES]


def choose_source(
    paths: Sequence[str | Path],
    spec: PoseSpec,
    defaults: Sequence[PoseSpec] = (),
    *,
    what: str = "poses",
    only_topic: bool = False,
    present: Mapping[str, str] | None = None,
) -> PoseSpec:
    """The pose source to read: ``spec`` when given, else the first default in the bags.

    Args:
        paths: the bags (their indexes are read, no messages).
        spec: what the command line gave; its time source applies to a default topic too.
        defaults: the command's usual sources, best first (topics and tf pairs).
        what: what the poses are, for messages ("end-effector poses").
        only_topic: with no default present, use the bags' only pose topic (with a note).
        present: the bags' topics (name -> type) when the caller has them already.

    Raises:
        TopicError: the given topic is not in the bags, or no default and no single pose topic.
    """
    if present is None:
        present = topics(list(paths))
    flag_hint = "choose one with --topic TOPIC or --tf PARENT:CHILD"
    if spec.topic is not None:
        if spec.topic not in present:
            there = ", ".join(pose_topics(present)) or "none"
            raise TopicError(
                f"{spec.topic}: no such topic (pose topics there: {there})", path=paths[0]
            )
        return spec
    if spec.tf is not None:
        return spec
    for index, default in enumerate(defaults):
        found = default.tf is not None and any(t in present for t in ("/tf", "/tf_static"))
        found = found or default.topic in present
        if not found:
            continue
        chosen = replace(default, time_source=spec.time_source)
        if index > 0:
            log.warning(
                "%s absent; %s: using %s",
                defaults[0].describe().split(" ", 1)[1],
                what,
                chosen.describe().split(" ", 1)[1],
            )
        return chosen
    found_topics = pose_topics(present)
    if only_topic and len(found_topics) == 1:
        log.warning("%s: using the only pose topic %s", what, found_topics[0])
        return PoseSpec(topic=found_topics[0], time_source=spec.time_source)
    tried = ", ".join(d.describe().split(" ", 1)[1] for d in defaults)
    raise TopicError(
        f"no {what}"
        + (f": {tried} absent" if tried else "")
        + f" (pose topics there: {', '.join(found_topics) or 'none'}); {flag_hint}",
        path=paths[0],
    )


def time_source_fallback(spec: PoseSpec, present: Mapping[str, str]) -> str | None:
    """The warning when ``header`` cannot be honoured for ``spec`` (a headerless type)."""
    if spec.topic is None or spec.time_source != "header":
        return None
    msgtype = present.get(spec.topic)
    if msgtype not in HEADERLESS_TYPES:
        return None
    return (
        f"{spec.topic} is {msgtype}, which has no header stamp: its times are the record "
        "times (--time-source record)"
    )


def read_source(
    paths: Sequence[str | Path],
    spec: PoseSpec,
    defaults: Sequence[PoseSpec] = (),
    *,
    what: str = "poses",
    only_topic: bool = False,
    start_ns: int | None = None,
    end_ns: int | None = None,
) -> PoseStream:
    """Choose the source (:func:`choose_source`) and read its poses, warning on a fallback.

    Raises:
        TopicError: no source, or the chosen one holds no pose.
    """
    present = topics(list(paths))
    chosen = choose_source(paths, spec, defaults, what=what, only_topic=only_topic, present=present)
    fallback = time_source_fallback(chosen, present)
    if fallback is not None:
        # A warning when the user chose the topic or the time: what they asked for is not
        # what they get. A command's own default topic being Pose2D is the 2015 setup (the
        # nodes read the pose2d topics live): said with -v only, not on every run.
        loud = spec.topic is not None or spec.time_source_given
        log.log(logging.WARNING if loud else logging.INFO, "%s", fallback)
    poses = read_pose_source(list(paths), chosen.to_io(), start_ns=start_ns, end_ns=end_ns)
    if len(poses) == 0:
        raise TopicError(f"{poses.source or chosen.describe()}: no pose messages", path=paths[0])
    return poses
