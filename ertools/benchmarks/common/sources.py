"""Where a pose stream comes from, chosen once for every command and benchmark.

A pose source is a pose topic (``--topic TOPIC``) or a tf frame pair (``--tf PARENT:CHILD``),
read with a time source (``--time-source header|record``). :class:`PoseSpec` is what the
command line gives (maybe nothing); :func:`choose_source` turns it, with the command's list
of defaults, into the :class:`ertools.io.model.PoseSource` to read, and :func:`read_source`
reads it.
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
from dataclasses import replace
from pathlib import Path

from ertools.benchmarks.common.spec import (
    DEFAULT_PARENT,
    DEFAULT_TIME_SOURCE,
    TimeSource,
)
from ertools.benchmarks.common.spec import PoseSpec as PoseSpec  # noqa: PLC0414 (re-exported)
from ertools.errors import TopicError
from ertools.io.model import POSE_TYPES, TF_TYPES, PoseSource
from ertools.io.reader import read_pose_source, topics
from ertools.streams import PoseStream

log = logging.getLogger(__name__)

# Message types with no header stamp: ``header`` falls back on the record time there.
HEADERLESS_TYPES = ("geometry_msgs/Pose2D",)


def pose_source(spec: PoseSpec) -> PoseSource:
    """The reader's :class:`~ertools.io.model.PoseSource` of a spec (a topic, else the tf pair)."""
    if spec.tf is not None:
        return PoseSource(topic=None, frame=spec.tf[1], parent=spec.tf[0])
    return PoseSource(topic=spec.topic, time_source=spec.time_source)


def topic(name: str, time_source: TimeSource = DEFAULT_TIME_SOURCE) -> PoseSpec:
    """A topic default (for :func:`choose_source`'s ``defaults``)."""
    return PoseSpec(topic=name, time_source=time_source)


def tf(child: str, parent: str = DEFAULT_PARENT) -> PoseSpec:
    """A tf default (for :func:`choose_source`'s ``defaults``)."""
    return PoseSpec(tf=(parent, child))


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
    flags: str = "--topic TOPIC or --tf PARENT:CHILD",
) -> PoseSpec:
    """The pose source to read: ``spec`` when given, else the first default in the bags
    (a warning when it is not the first one).

    Args:
        paths: the bags (their indexes are read, no messages).
        spec: what the command line gave; its time source applies to a default topic too.
        defaults: the command's usual sources, best first (topics and tf pairs).
        what: what the poses are, for messages ("end-effector poses").
        only_topic: with no default present, use the bags' only pose topic (with a warning).
        present: the bags' topics (name -> type) when the caller has them already.
        flags: how the user names a source in this command (for the error message).

    Raises:
        TopicError: the given topic is not in the bags, or no default and no single pose topic.
    """
    chosen, fallback = _choose(paths, spec, defaults, what, only_topic, present, flags)
    if fallback is not None:
        log.warning("%s", fallback)
    return chosen


def _choose(
    paths: Sequence[str | Path],
    spec: PoseSpec,
    defaults: Sequence[PoseSpec],
    what: str,
    only_topic: bool,
    present: Mapping[str, str] | None,
    flags: str,
) -> tuple[PoseSpec, str | None]:
    """(the source, the warning to give when it is a fallback, else None)."""
    if present is None:
        present = topics(list(paths))
    if spec.topic is not None:
        if spec.topic not in present:
            there = ", ".join(pose_topics(present)) or "none"
            raise TopicError(
                f"{spec.topic}: no such topic (pose topics there: {there})", path=paths[0]
            )
        return spec, None
    if spec.tf is not None:
        return spec, None
    for index, default in enumerate(defaults):
        found = default.tf is not None and any(t in present for t in ("/tf", "/tf_static"))
        if found or default.topic in present:
            chosen = replace(default, time_source=spec.time_source)
            if index == 0:
                return chosen, None
            return chosen, f"{defaults[0].name} absent; {what}: using {chosen.name}"
    found_topics = pose_topics(present)
    if only_topic and len(found_topics) == 1:
        only = PoseSpec(topic=found_topics[0], time_source=spec.time_source)
        return only, f"{what}: using the only pose topic {found_topics[0]}"
    tried = ", ".join(d.name for d in defaults)
    if not found_topics and not any(t in present for t in ("/tf", "/tf_static")):
        # a benchmarking box's state log: the 2015 mocap logger wrote the poses to its own
        # files, which are further BAGs (as `rescore` gives them), not a topic of this one
        raise TopicError(
            f"no {what}" + (f": {tried} absent" if tried else "") + "; the log holds no poses "
            "at all (a state log?): give the mocap logger's files too, as further BAGs "
            "(`ertools timeline FOLDER` pairs them)",
            path=paths[0],
        )
    raise TopicError(
        f"no {what}"
        + (f": {tried} absent" if tried else "")
        + f" (pose topics there: {', '.join(found_topics) or 'none'}); choose one with {flags}",
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
    flags: str = "--topic TOPIC or --tf PARENT:CHILD",
    allow_empty: bool = False,
) -> PoseStream:
    """Choose the source (:func:`choose_source`) and read its poses, warning on a fallback.

    ``allow_empty``: a window with no pose is the caller's to report (per run, say), not an
    error of the source.

    Raises:
        TopicError: no source, or the chosen one holds no pose (unless ``allow_empty``).
    """
    present = topics(list(paths))
    chosen, fallback = _choose(paths, spec, defaults, what, only_topic, present, flags)
    try:
        poses = read_pose_source(list(paths), pose_source(chosen), start_ns=start_ns, end_ns=end_ns)
    except TopicError as err:
        if fallback is None:
            raise
        # the usual source is absent and the fallback fails too: one line saying both
        raise TopicError(
            f"no {what}: {defaults[0].name} absent and {chosen.name}: {err.message}; "
            f"choose one with {flags}",
            path=paths[0],
        ) from err
    if fallback is not None:
        log.warning("%s", fallback)
    headerless = time_source_fallback(chosen, present)
    if headerless is not None:
        # A warning when the user chose the topic or the time: what they asked for is not
        # what they get. A command's own default topic being Pose2D is the 2015 setup (the
        # nodes read the pose2d topics live): said with -v only, not on every run.
        loud = spec.topic is not None or spec.time_source_given
        log.log(logging.WARNING if loud else logging.INFO, "%s", headerless)
    if len(poses) == 0 and not allow_empty:
        raise TopicError(f"{poses.source or chosen.describe()}: no pose messages", path=paths[0])
    return poses
