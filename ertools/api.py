"""The public Python API: what ``import ertools`` offers a notebook or a script.

Every name here is also a top-level name of the package (``ertools.score``, imported on first
use, so that ``import ertools`` stays light). Everything else in ertools is private by
convention (docs/ARCHITECTURE.md, "The public API"): it may change in any release. The
examples below run as doctests in ``make test`` from the repository root, on ``sample_bags/``;
``docs/api.md`` is generated from these docstrings (``python docs/build_api.py``).

Each function raises the same ``ertools.errors.ErtoolsError`` as the command it mirrors,
with the same message (``ertools.errors.UsageError`` for a wrong value, ``BagError`` for an
unreadable file...), and prints nothing: warnings and notes are in the results it returns.
``ertools.errors`` (``ErtoolsError`` and its subclasses) is part of the API, to catch them by.
An argument of the wrong type (a ``bytes`` path, ``config={...}``, ``tf=123``, a dict where
paths are expected) is a ``UsageError`` naming the parameter, raised before anything is read:
``ertools.score: bags=b'run.bag' (bytes): give a bag path (str or pathlib.Path) or a list of
paths``. Paths are ``str`` or ``pathlib.Path``; several paths a list or a tuple of them.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING, Any, cast

from ertools.atomic import write_text
from ertools.auditing.model import Audit
from ertools.auditing.recompute import ScoreInputs, audit_bag, infer_benchmark
from ertools.benchmarks import registry
from ertools.benchmarks.base import rename_former
from ertools.benchmarks.common.sources import read_source
from ertools.benchmarks.common.spec import PoseSpec, TimeSource, parse_tf
from ertools.benchmarks.scoring import score_execution
from ertools.competition.manifest import ManifestError, load_manifest
from ertools.competition.run import rescore_competition
from ertools.errors import ConfigError, UsageError
from ertools.exporting.formats import FORMATS, format_poses
from ertools.io import files
from ertools.io.summary import summary
from ertools.parameters import checked, paths_list, value_of
from ertools.report.figures import figure_specs
from ertools.report.plots_audit import draw_timeline
from ertools.report.plots_timeline import draw_gantt, timeline_figure
from ertools.timelines.model import Timeline
from ertools.timelines.scan import scan

if TYPE_CHECKING:
    from ertools.benchmarks.base import BenchmarkResult
    from ertools.io.bagfile import BagFile
    from ertools.io.model import BagSummary
    from ertools.streams import PoseStream

PathLike = str | Path


@checked
def info(path: PathLike) -> BagSummary:
    """What one bag holds, from its index, as ``ertools info`` shows it: format, times,
    compression and every topic with its type and message count.

    Args:
        path: a ROS1 ``.bag``, an ``.mcap`` file or a rosbag2 folder.

    Raises:
        BagError: missing, empty or unreadable file.

    Example:
        >>> import ertools
        >>> s = ertools.info("sample_bags/fbm3w/log_fbm3w_mocap_2015-11-20-12-00-00_0.bag")
        >>> s.format, len(s.topics) > 0
        ('ros1', True)
        >>> [t.name for t in s.topics if t.name.endswith("bmbox_state")]
        ['/fbm3w/bmbox_state']
    """
    return summary(path)


@checked
def open_bag(path: PathLike) -> BagFile:
    """One bag of any format opened for reading messages: its ``connections`` (topic, type)
    and ``raw(conns)`` records (connection, record time in ns, serialized bytes), in record
    order. Use it as a context manager.

    Raises:
        BagError: missing, empty, unrecognised, truncated or otherwise unreadable file.

    Example:
        >>> import ertools
        >>> log = "sample_bags/fbm2h/log_fbm2h_mocap_2015-11-20-12-00-00_0.bag"
        >>> with ertools.open_bag(log) as bag:
        ...     conns = bag.topic_conns("/fbm2h/bmbox_state")
        ...     records = list(bag.raw(conns))
        >>> conns[0].msgtype, len(records) > 0
        ('rockin_scoring/BmBoxState', True)
    """
    return files.open_bag(path)


@checked
def read_poses(
    paths: PathLike | Sequence[PathLike],
    *,
    topic: str | None = None,
    tf: str | tuple[str, str] | None = None,
    time_source: str = "header",
) -> PoseStream:
    """The poses of one source over one or more bags (a logger's split files), time-ordered,
    as arrays: ``t_ns`` (int64 ns), ``xyz`` (metres), ``quat_xyzw``.

    Args:
        paths: a bag, or several read as one.
        topic: a pose topic (``PoseStamped``, ``Pose2D``, ``TransformStamped``,
            ``PoseWithCovarianceStamped``, ``Odometry``); or
        tf: a frame pair from ``/tf`` and ``/tf_static``, ``"PARENT:CHILD"`` or a tuple.
        time_source: ``header`` (the message stamp) or ``record`` (the bag's record time).

    Raises:
        UsageError: neither or both of ``topic`` and ``tf``.
        TopicError: the source is not in the bags (the message lists the pose topics there are).

    Example:
        >>> import ertools
        >>> poses = ertools.read_poses(
        ...     "sample_bags/fbm3w/log_fbm3w_mocap_2015-11-20-12-00-00_0.bag",
        ...     topic="/fbm3w/robot_at_work/pose")
        >>> len(poses) > 1000, poses.t_ns.dtype.name, poses.xyz.shape[1]
        (True, 'int64', 3)
        >>> bool((poses.t_ns[1:] >= poses.t_ns[:-1]).all())
        True
    """
    if (topic is None) == (tf is None):
        raise UsageError("give topic=TOPIC or tf='PARENT:CHILD' (one of them)")
    pair = parse_tf(tf) if isinstance(tf, str) else None if tf is None else (tf[0], tf[1])
    source = cast(TimeSource, time_source)  # PoseSpec refuses any other word
    spec = PoseSpec(topic=topic, tf=pair, time_source=source, time_source_given=True)
    return read_source(paths_list(paths), spec, what="poses")


def _values(name: str, inputs: Mapping[str, Any]) -> dict[str, Any]:
    bench = registry.get(name)
    declared = {i.name: i for i in bench.inputs}
    inputs = rename_former(bench.inputs, inputs)
    unknown = sorted(set(inputs) - set(declared))
    if unknown:
        raise UsageError(
            f"{name} takes no input {', '.join(unknown)}; its inputs: {', '.join(declared)}"
        )
    return {n: value_of(d, inputs.get(n)) for n, d in declared.items()}


@checked
def score(name: str, bags: PathLike | Sequence[PathLike], **inputs: Any) -> BenchmarkResult:
    """Score one benchmark execution, as ``ertools score NAME BAG... --OPTION VALUE`` does.

    Args:
        name: ``fbm1h``, ``fbm1w``, ``fbm2h``, ``fbm3w`` or ``trajectory``.
        bags: the log (its split files in order); for ``trajectory`` the robot's log first,
            then the GT bags or folders.
        inputs: the benchmark's inputs by name, the options of ``ertools score NAME --help``
            with ``_`` for ``-`` (``goal=...``, ``d_min=0.0005``, ``reached=("timing",
            FILE)``, ``orientation_2015=True``); ``docs/api.md`` lists them.

    Returns:
        The frozen result: ``to_dict()`` (what ``--format json`` prints), ``to_yaml()`` (the
        seed's listing), ``to_frames()`` (every table as a pandas DataFrame), ``warnings``,
        ``deviations`` (every difference from 2015), ``failures`` (runs not scored).

    Raises:
        UsageError: an unknown benchmark or input, or a value the command line would refuse.
        ErtoolsError: unusable data or config (the command's exit 1), with the same message.

    Example:
        >>> import ertools
        >>> result = ertools.score(
        ...     "fbm2h", "sample_bags/fbm2h/log_fbm2h_mocap_2015-11-20-12-00-00_0.bag",
        ...     goal="sample_bags/fbm2h/fbm2h_goal.yaml",
        ...     transform="sample_bags/fbm2h/transform-simbot.yaml")
        >>> round(result.to_dict()["position_accuracy"], 4)  # the sample's truth: 0.0974
        0.0974
        >>> result.to_frames()["segments"]["distance_error_m"].round(3).tolist()
        [0.049, 0.1, 0.025, ...]
        >>> ertools.score("fbm2h", "x.bag", speed=1)
        Traceback (most recent call last):
        ...
        ertools.errors.UsageError: fbm2h takes no input speed; its inputs: ...
    """
    bench = registry.get(name)
    values = _values(name, inputs)
    bag_list = paths_list(bags)
    if not bag_list:
        raise UsageError(f"give at least one bag (the log file) to score {name}")
    return score_execution(bench, bag_list, values).result


@checked
def audit(
    bags: PathLike | Sequence[PathLike],
    *,
    benchmark: str | None = None,
    recompute: bool = True,
    **inputs: Any,
) -> Audit:
    """Reconstruct a benchmark from its state topics, as ``ertools audit`` does: the machines'
    timeline, illegal transitions, heartbeat silences, the live score, and (``recompute``)
    the score recomputed and compared with the live one, key by key.

    Args:
        bags: the log.
        benchmark: the namespace of the state topics; found in the log when None.
        recompute: False: the timeline and checks only.
        inputs: the scoring inputs, as for ``ertools.score`` (``goal=``, ``items=``...).

    Returns:
        The frozen audit: ``to_text()``, ``to_dict()``, ``to_frames()``, ``recomputed``
        (the result), ``comparison``, ``warnings`` (notes such as an input not used).

    Example:
        >>> import ertools
        >>> a = ertools.audit("sample_bags/fbm3w/log_fbm3w_mocap_2015-11-20-12-00-00_0.bag",
        ...                   config="sample_bags/fbm3w/fbm3w.yaml")
        >>> a.benchmark, len(a.illegal_transitions)
        ('fbm3w', 0)
        >>> round(a.recomputed.to_dict()["best_distance_error"], 5)
        0.00064
    """
    plist = paths_list(bags)
    namespace = benchmark or infer_benchmark(plist)
    known = registry.get(namespace).inputs if namespace in registry.names() else ()
    declared = {i.name: i for i in known}
    inputs = rename_former(known, inputs)
    # an input the benchmark does not declare is passed as given: the audit notes it unused
    given = {
        k: value_of(declared[k], v) if k in declared else v
        for k, v in inputs.items()
        if v is not None
    }
    result, notes = audit_bag(
        plist,
        benchmark=namespace,
        inputs=ScoreInputs(other=tuple(given.items())),
        recompute=recompute,
    )
    return replace(result, warnings=(*result.warnings, *notes)) if notes else result


@checked
def timeline(paths: PathLike | Sequence[PathLike], *, check_clocks: bool = True) -> Timeline:
    """Order the bags under ``paths`` (files and folders, searched recursively) by time, as
    ``ertools timeline`` does: sessions, overlaps, gaps, clock problems, copies, which GT files
    go with which benchmark log.

    Returns:
        The frozen timeline: ``bags`` (each with ``kind``, ``start_ns``, ``problems``...),
        ``sessions``, ``problems``, ``to_dict()``.

    Example:
        >>> import ertools
        >>> t = ertools.timeline("sample_bags/fbm2h")
        >>> [b.kind for b in t.bags]
        ['benchmark']
    """
    return scan(paths_list(paths), check_clocks=check_clocks)


@checked
def figures(result: Any) -> list[Any]:
    """The figures of a result as matplotlib Figures, the charts ``--plot`` and the reports
    draw (reports write them as SVG without matplotlib; here matplotlib draws the same charts):
    a benchmark's result (its runs, paths, errors); an audit (the state machines' timeline,
    runs shaded, findings marked); a timeline (one panel per session with the problems
    listed, then the whole day on one axis).

    Example:
        >>> import ertools
        >>> t = ertools.timeline("sample_bags/fbm2h")
        >>> [type(f).__name__ for f in ertools.figures(t)]
        ['Figure', 'Figure']
    """
    from matplotlib.figure import Figure  # lazy: matplotlib, 300 ms

    if isinstance(result, Timeline):
        day = Figure(figsize=(12, 4), layout="constrained")
        draw_gantt(day.add_subplot(), result)
        return [timeline_figure(result), day]
    if isinstance(result, Audit):
        fig = Figure(figsize=(12, 4), layout="constrained")
        draw_timeline(fig.add_subplot(), result)
        return [fig]
    out = []
    for spec in figure_specs(result):
        fig = Figure(figsize=spec.size, layout="constrained")
        ax = fig.add_subplot()
        spec.draw(ax)
        if spec.title:
            ax.set_title(spec.title)
        out.append(fig)
    return out


@checked
def export(
    bags: PathLike | Sequence[PathLike],
    *,
    topic: str | None = None,
    tf: str | tuple[str, str] | None = None,
    format: str = "tum",
    out: PathLike | None = None,
) -> str:
    """One pose source as TUM, KITTI or CSV text, as ``ertools export BAG --topic T`` writes
    it (exact stamps, every digit); written to ``out`` too when given.

    Example:
        >>> import ertools
        >>> text = ertools.export("sample_bags/fbm3w/log_fbm3w_mocap_2015-11-20-12-00-00_0.bag",
        ...                       topic="/fbm3w/robot_at_work/pose", format="tum")
        >>> len(text.splitlines()[0].split())
        8
    """
    if format not in FORMATS:
        raise UsageError(f"format {format!r}: one of {', '.join(FORMATS)}")
    stream = read_poses(bags, topic=topic, tf=tf)
    text = format_poses(stream, format)
    if out is not None:
        target = Path(out)
        if any(target.exists() and target.samefile(p) for p in paths_list(bags)):
            raise UsageError(f"out={target}: that is an input; ertools never overwrites its inputs")
        write_text(target, text)
    return text


@checked
def rescore(
    paths: PathLike | Sequence[PathLike],
    *,
    config: PathLike,
    out: PathLike,
    jobs: int = 1,
    reports: bool = True,
    use_cache: bool = True,
) -> dict[str, Any]:
    r"""Score a whole competition, as ``ertools rescore PATH... --config FILE --out DIR``:
    every execution found in ``paths`` or listed in the manifest, scored through the
    registry, written to ``out`` (``results.json``, ``results.csv``, a report per execution,
    ``index.html``).

    Args:
        paths: folders and files of logs (may be empty when the manifest lists everything).
        config: the competition manifest (docs/rescore.md).
        out: the results folder.
        jobs: worker processes (1: in this process).
        reports: a report folder per execution.
        use_cache: reuse the scores of unchanged executions from ``out/cache``.

    Returns:
        The results document (``results.json``): ``executions``, each with its ``status``
        and ``score``.

    Raises:
        ConfigError: a manifest with problems (every problem named, nothing scored).

    Example:
        >>> import ertools, pathlib, tempfile
        >>> bag = pathlib.Path("sample_bags/fbm3w/log_fbm3w_mocap_2015-11-20-12-00-00_0.bag")
        >>> tmp = pathlib.Path(tempfile.mkdtemp())
        >>> manifest = tmp / "competition.yaml"
        >>> _ = manifest.write_text(
        ...     f"benchmarks:\n  fbm3w: {{inputs: {{config: {bag.parent.resolve()}/fbm3w.yaml}}}}\n"
        ...     f"executions:\n  - {{benchmark: fbm3w, team: robotto, bags: [{bag.resolve()}]}}\n")
        >>> doc = ertools.rescore([], config=manifest, out=tmp / "results", reports=False)
        >>> [(e["team"], e["status"]) for e in doc["executions"]]
        [('robotto', 'scored')]
        >>> round(doc["executions"][0]["score"]["best_distance_error"], 5)
        0.00064
    """
    if jobs < 1:
        raise UsageError(f"jobs={jobs}: give 1 or more worker processes")
    where = paths_list(paths)
    for path in where:
        if not path.exists():
            raise UsageError(f"{path}: no such file or folder")
    target = Path(out)
    try:
        manifest = load_manifest(Path(config))
    except ManifestError as err:
        listed = "; ".join(err.problems)
        raise ConfigError(f"{len(err.problems)} problem(s): {listed}", path=config) from None
    done = rescore_competition(
        where,
        manifest,
        target,
        workers=jobs,
        use_cache=use_cache,
        reports=reports,
        command=["python", "ertools.rescore", *map(str, where)],
    )
    doc: dict[str, Any] = done.doc
    return doc
