"""FBM3@Work's logs: the end-effector poses (the one pose-source chooser) and what
:func:`ertools.benchmarks.fbm3w.pipeline.load` read."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

from ertools.benchmarks.common.sources import PoseSpec, read_source, tf, topic
from ertools.benchmarks.fbm3w.config import (
    DEFAULT_FRAME,
    DEFAULT_TOPIC,
    FALLBACK_TOPIC,
    Fbm3wOptions,
)
from ertools.frozen_dataclass import frozen_dataclass
from ertools.io.model import BenchmarkStates
from ertools.streams import PoseStream


def read_fbm3w_poses(paths: Sequence[Path], options: Fbm3wOptions) -> PoseStream:
    """The end-effector poses: ``--topic``/``--frame``, else pose2d, pose, tf ``robot_at_work``.

    Raises:
        TopicError: none of them is in the bags (the message lists the pose topics there are).
    """
    # the one pose-source chooser (benchmarks/common/sources.py): the given source, else the
    # first of pose2d, pose, the tf frame present, with a warning when not the first
    spec = PoseSpec(
        topic=options.topic,
        tf=None
        if options.topic is not None or options.frame is None
        else (options.tf_parent, options.frame),
        time_source="record" if options.time_source == "record" else "header",
    )
    defaults = (topic(DEFAULT_TOPIC), topic(FALLBACK_TOPIC), tf(DEFAULT_FRAME))
    return read_source(paths, spec, defaults, what="end-effector poses")


@frozen_dataclass(eq=False)
class Fbm3wLogs:
    """What :func:`~ertools.benchmarks.fbm3w.pipeline.load` read: the bags, their end-effector
    poses, span and topics, the run mode and, for ``states``, the benchmark state streams."""

    paths: tuple[Path, ...]
    poses: PoseStream
    bag_start_ns: int
    bag_end_ns: int
    mode: str
    states: BenchmarkStates | None = None
