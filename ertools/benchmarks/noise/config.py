"""The noise measure's inputs and options: the marker set's pose source, the still phases,
the histogram bin and the factor of the suggested d_min (NumPy-free: the parsers import it)."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from ertools.benchmarks.base import Input, resolve_values, tf_value
from ertools.benchmarks.common.inputs import DEFAULT_BIN, DEFAULT_C
from ertools.benchmarks.common.spec import DEFAULT_TIME_SOURCE, TIME_SOURCES, PoseSpec
from ertools.errors import UsageError
from ertools.frozen_dataclass import frozen_dataclass

# The 2015 noise recordings are of FBM3@Work's marker set: its topics and tf frame, in the
# order FBM3@Work prefers them (noise sits below the benchmarks that use it: not imported).
DEFAULT_TOPIC = "/fbm3w/robot_at_work/pose2d"
FALLBACK_TOPIC = "/fbm3w/robot_at_work/pose"
DEFAULT_FRAME = "robot_at_work"
STATIONARY = ("all", "auto")

INPUTS = (
    Input(
        "topic",
        "str",
        "the marker set: a pose topic (PoseStamped, Pose2D, Odometry, ...) (default: the fbm3w "
        "pose2d, pose, tf world:robot_at_work, else the only pose topic)",
        metavar="TOPIC",
    ),
    Input(
        "tf",
        "str",
        "the marker set: the transform PARENT -> CHILD from /tf and /tf_static",
        metavar="PARENT:CHILD",
        old_flags=("--frame",),
    ),
    Input(
        "time_source",
        "choice",
        f"pose time: the message's header stamp (default {DEFAULT_TIME_SOURCE}; Pose2D has none "
        "and falls back on the record time, with a warning) or the bag's record time",
        choices=TIME_SOURCES,
    ),
    Input(
        "stationary",
        "choice",
        "all: the whole recording is stationary (2015); auto: detect the still phases",
        default="all",
        choices=STATIONARY,
    ),
    Input("bin", "float", "histogram bin (default 0.00015 m)", DEFAULT_BIN, "m", positive=True),
    Input(
        "c",
        "float",
        f"suggested d_min = C * epsilon (default {DEFAULT_C:g})",
        DEFAULT_C,
        positive=True,
        metavar="C",
    ),
)


@frozen_dataclass
class NoiseOptions:
    """What ``ertools noise`` (or ``ertools score noise``) measures: the pose source, whether
    only the still phases count, the histogram bin (m) and the c of ``d_min = c * epsilon``."""

    source: PoseSpec
    stationary: bool = False
    bin: float = DEFAULT_BIN
    c: float = DEFAULT_C


def make_options(values: Mapping[str, Any]) -> NoiseOptions:
    """The values by input name -> options.

    Raises:
        UsageError: a value out of range, or both ``--topic`` and ``--tf``.
    """
    v = resolve_values(INPUTS, values)
    if v["topic"] is not None and v["tf"] is not None:
        raise UsageError(f"give --topic {v['topic']} or --tf {v['tf']}, not both")
    given = v["time_source"]
    source = PoseSpec(
        topic=v["topic"],
        tf=tf_value("--tf", v["tf"]),
        time_source=DEFAULT_TIME_SOURCE if given is None else given,
        time_source_given=given is not None,
    )
    return NoiseOptions(source, v["stationary"] == "auto", float(v["bin"]), float(v["c"]))
