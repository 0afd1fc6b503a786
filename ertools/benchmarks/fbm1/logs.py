"""FBM1 log reading: the item list, answers and state topics (:func:`read_logs`), and the table
and board poses (:func:`read_body` chooses where a body's poses come from); what
:func:`ertools.benchmarks.fbm1.pipeline.find_runs` finds in them (:class:`Fbm1Runs`)."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

from ertools.benchmarks.common.sources import PoseSpec, read_source, tf, topic
from ertools.benchmarks.fbm1.answers import ResultsFile, parse_results
from ertools.benchmarks.fbm1.config import Fbm1Options
from ertools.benchmarks.fbm1.runs import RunsFound
from ertools.configs._yaml import load_yaml
from ertools.configs.items import ItemList, load_items
from ertools.errors import ConfigError, SegmentationError
from ertools.frozen_dataclass import frozen_dataclass
from ertools.io.model import BenchmarkStates
from ertools.io.reader import read_benchmark_states, read_pose_source
from ertools.io.summary import summary
from ertools.streams import PoseStream

if TYPE_CHECKING:
    from ertools.io.model import PoseSource


# Ground-truth methods that are one tf lookup, as the nodes made it: their poses come from /tf
# first (the nodes never read the pose topics).
TF_LOOKUPS = ("result", "placed", "goal")


def read_body(
    paths: Sequence[Path],
    source: PoseSource | None,
    default_topic: str,
    frame: str,
    window: tuple[int | None, int | None] = (None, None),
    tf_first: bool = False,
) -> PoseStream:
    """A body's poses: the given source, else the 2015 topic, else its /tf frame (the one
    chooser, :func:`ertools.benchmarks.common.sources.read_source`).

    ``tf_first``: the /tf frame first, then the topic: what the nodes looked up (``--gt
    result|placed|goal``, and so ``--rules 2015|2016``); the chooser warns when it falls back.
    """

    start, end = window
    if source is not None:
        stream: PoseStream = read_pose_source(paths, source, start_ns=start, end_ns=end)
        return stream
    flag = frame.replace("_", "-")
    return read_source(
        paths,
        PoseSpec(),
        (tf(frame), topic(default_topic)) if tf_first else (topic(default_topic), tf(frame)),
        what=f"{frame} poses",
        start_ns=start,
        end_ns=end,
        flags=f"--{flag}-topic TOPIC or --{flag}-tf PARENT:CHILD",
        allow_empty=True,  # a body lost around every run fails those runs, one by one
    )


@frozen_dataclass(eq=False)
class Fbm1Logs:
    """What :func:`read_logs` read: the log files, the item list, the answers file (if any), the
    benchmark state streams and the log's first message time."""

    paths: tuple[Path, ...]
    items: ItemList
    results: ResultsFile | None
    states: BenchmarkStates
    t0_ns: int


@frozen_dataclass(eq=False)
class Fbm1Runs:
    """What :func:`ertools.benchmarks.fbm1.pipeline.find_runs` found: the runs, and the table
    and board poses around them (read only there), with the node's item broadcasts when the
    ground truth needs them."""

    found: RunsFound
    origin: PoseStream
    board: PoseStream
    item_tf: PoseStream | None


def read_logs(paths: Sequence[Path], options: Fbm1Options) -> Fbm1Logs:
    """Read the item list, the answers file and the state topics.

    Raises:
        ConfigError: no item list, a bad item list or results file.
        SegmentationError: no BmBox state messages.
    """

    plist = tuple(Path(p) for p in paths)
    ns = options.benchmark
    if options.items is None:
        raise ConfigError(f"scoring {ns} needs the item list: give --items FILE")
    items = load_items(options.items)
    results = None
    if options.results is not None:
        results = parse_results(load_yaml(options.results, "results"), str(options.results))
    states = read_benchmark_states(list(plist), ns)
    if states.bmbox is None or len(states.bmbox) == 0:
        raise SegmentationError(
            f"no /{ns}/bmbox_state messages: the runs cannot be found "
            f"(is this an {ns} log? `ertools info` lists its topics)",
            path=plist[0],
        )
    t0 = min(summary(p).start_ns for p in plist)
    return Fbm1Logs(plist, items, results, states, t0)
