"""FBM1 log reading: the item list, answers and state topics (``load``), then the runs and the
table and board poses around them (``locate_runs``); ``read_body`` chooses where a body's poses
come from."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from ertools.benchmarks.common.sources import PoseSpec, read_source, tf, topic
from ertools.benchmarks.fbm1.answers import ResultsFile, parse_results
from ertools.benchmarks.fbm1.config import Fbm1Options
from ertools.benchmarks.fbm1.runs import RunsFound, find_runs
from ertools.configs._yaml import load_yaml
from ertools.configs.items import ItemList, load_items
from ertools.errors import ConfigError, SegmentationError, TopicError
from ertools.io.clock import check_header_clock
from ertools.io.model import BenchmarkStates
from ertools.io.reader import read_benchmark_states, read_pose_source, read_tf
from ertools.io.summary import summary
from ertools.streams import PoseStream
from ertools.timeutil import NS_PER_S

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


@dataclass(frozen=True, eq=False)
class Fbm1Logs:
    """What :func:`load` read: the log files, the item list, the answers file (if any), the
    benchmark state streams and the log's first message time."""

    paths: tuple[Path, ...]
    items: ItemList
    results: ResultsFile | None
    states: BenchmarkStates
    t0_ns: int


@dataclass(frozen=True, eq=False)
class Fbm1Runs:
    """What :func:`locate_runs` found: the runs, and the table and board poses around them
    (read only there), with the node's item broadcasts when the ground truth needs them."""

    found: RunsFound
    origin: PoseStream
    board: PoseStream
    item_tf: PoseStream | None


def load(paths: Sequence[Path], options: Fbm1Options) -> Fbm1Logs:
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


def locate_runs(logs: Fbm1Logs, options: Fbm1Options) -> Fbm1Runs:
    """The runs from the states, then the table and board poses around them.

    Raises:
        SegmentationError: no Client states and no results file (the answers are unknown).
        TopicError: a body's poses are nowhere.
        ClockError: header-stamped poses on another clock than the state messages.
    """
    ns = options.benchmark
    plist = list(logs.paths)
    states = logs.states
    assert states.bmbox is not None
    found = find_runs(
        states.bmbox,
        states.refbox,
        states.client,
        benchmark=ns,
        items_order=list(options.items_order) if options.items_order is not None else None,
        t0_ns=logs.t0_ns,
        exact_2015=options.exact_end_payloads,
    )
    if states.client is None and logs.results is None:
        # Scoring every run as unanswered would be a silent wrong score.
        raise SegmentationError(
            f"no /{ns}/client_state in the log: the robot's answers are unknown; "
            "give them with --results FILE",
            path=plist[0],
        )
    if not found.runs:
        # nothing to score; a bare min() below would fail as a bug
        raise SegmentationError(
            f"/{ns}/bmbox_state: no run found (the benchmarking box sent no goal in "
            f"{len(states.bmbox.t_ns)} state messages)",
            path=plist[0],
        )
    # Read the bodies only around the runs (windowed reads touch only those chunks).
    pad = round((options.gt.max_window_s + options.gt.max_gap_s + 2.0) * NS_PER_S)
    lo = min(r.start_ns for r in found.runs) - pad
    hi = max(r.end_ns for r in found.runs) + pad
    src = options.sources
    tf_first = options.gt.method in TF_LOOKUPS
    origin = read_body(plist, src.origin, f"/{ns}/origin/pose", "origin", (lo, hi), tf_first)
    board = read_body(plist, src.board, f"/{ns}/ref_board/pose", "ref_board", (lo, hi), tf_first)

    for body, source in ((origin, src.origin), (board, src.board)):
        if source is None or source.time_source == "header":
            check_header_clock(plist, body, "state messages")
    item_tf = None
    if options.gt.method != "window":
        try:
            item_tf = read_tf(plist, "ref_board", "item", start_ns=lo, end_ns=hi)
        except TopicError:
            item_tf = None  # not logged: the state messages give the moments
    return Fbm1Runs(found, origin, board, item_tf)
