"""The public reading functions: pose, tf and state streams, topics (every message of a topic as
a Python object is :mod:`ertools.io.messages`').

Every function takes one path or a list (a logger's split files), reads each file, and merges
the results in time order. Pose topics go through the bulk NumPy decoder where the format and
type allow it (:mod:`ertools.io.decode.fast`) and through rosbags' deserializer otherwise.
"""

from __future__ import annotations

import logging
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
import numpy.typing as npt

from ertools.errors import BagError, TopicError
from ertools.frozen_dataclass import frozen_dataclass
from ertools.io.bagfile import BagFile
from ertools.io.bulk import States, bulk_states_many, try_fast_batches
from ertools.io.decode.posebatch import PoseBatch, batch_from_messages, concat_batches
from ertools.io.decode.tf import Edge, chain_pose, edges_overlap, split_edges
from ertools.io.decode.typestore import Deserializer
from ertools.io.files import open_bag
from ertools.io.formats import bag_paths
from ertools.io.merge import merge_poses, sort_poses
from ertools.io.model import (
    POSE_TYPES,
    TF_TYPES,
    BenchmarkStates,
    Conn,
    PoseSource,
)
from ertools.io.pipeline import Request
from ertools.streams import MAX_FRAME_CHANGES, FrameChange, PoseStream, StateStream

if TYPE_CHECKING:
    from ertools.states import Machine

log = logging.getLogger("ertools.io.reader")

PathsLike = str | Path | Sequence[str | Path]

# Header stamps of mocap messages trail or lead the record time by milliseconds; a window on
# header time reads the records of this much more on each side, then cuts on the stamps.
HEADER_WINDOW_MARGIN_NS = 60 * 1_000_000_000

TF_TOPICS = ("/tf", "/tf_static")


def path_list(paths: PathsLike) -> list[Path]:
    """The bag files of one path or a list (a logger's split files), as the readers take them."""
    if isinstance(paths, (str, Path)):
        return bag_paths(paths)
    return bag_paths(list(paths))


def topics(paths: PathsLike) -> dict[str, str]:
    """topic -> message type (``pkg/Type``) over all files, sorted by topic."""
    out: dict[str, str] = {}
    for p in path_list(paths):
        with open_bag(p) as bag:
            for c in bag.connections:
                out.setdefault(c.topic, c.msgtype)
    return dict(sorted(out.items()))


def _pose_topic_list(found: dict[str, str]) -> str:
    names = [t for t, ty in found.items() if ty in POSE_TYPES]
    return ", ".join(names) if names else "none"


def topic_error(paths: list[Path], topic: str, what: str = "pose topic") -> TopicError:
    """The unknown-topic error: lists the pose topics there are (or all topics when the
    caller was not after poses)."""
    found = topics(paths)
    where = str(paths[0]) if len(paths) == 1 else f"{len(paths)} files ({paths[0]}...)"
    if what in ("pose topic", "tf topic"):
        listing = f"pose topics there: {_pose_topic_list(found)}"
    else:
        listing = f"topics there: {', '.join(found) or 'none'}"
    return TopicError(f"{what} {topic} not in {where}; {listing}")


def load_pose_batch(
    bag: BagFile, conns: Sequence[Conn], start_ns: int | None, end_ns: int | None
) -> PoseBatch:
    """Pose rows of ``conns`` with record time in [start_ns, end_ns], in reference order.

    Tries the bulk decoder first; falls back to rosbags per message (logged at INFO).
    """
    return load_pose_batches(bag, [Request(tuple(conns), start_ns, end_ns)])[0]


def load_pose_batches(bag: BagFile, requests: Sequence[Request]) -> list[PoseBatch]:
    """:func:`load_pose_batch` of several requests, read in bulk from one pass over the file
    (those the bulk decoder cannot read are read per message afterwards)."""
    fast = try_fast_batches(bag, requests)
    return [
        b if b is not None else slow_pose_batch(bag, r.conns, r.lo, r.hi)
        for b, r in zip(fast, requests, strict=True)
    ]


def slow_pose_batch(
    bag: BagFile, conns: Sequence[Conn], start_ns: int | None, end_ns: int | None
) -> PoseBatch:
    """The reference decoder: rosbags' deserializer, one message at a time."""
    deser = Deserializer(conns, bag.path)
    batches = []
    types = {c.msgtype for c in conns}
    for msgtype in sorted(types):
        records = [
            (t, deser(raw, conn))
            for conn, t, raw in bag.raw(conns, start_ns, end_ns)
            if conn.msgtype == msgtype
        ]
        try:
            batches.append(batch_from_messages(msgtype, records))
        except AttributeError as err:
            # the stored definition names the type but not its fields (a damaged or foreign
            # definition): the messages decode without the fields a pose needs
            raise BagError(
                f"{conns[0].topic}: stored definition of {msgtype} lacks a pose field ({err})",
                path=bag.path,
            ) from err
    return concat_batches(batches)


def _check_pose_conns(conns: list[Conn], topic: str, path: Path) -> str:
    types = sorted({c.msgtype for c in conns})
    if len(types) != 1:
        raise TopicError(f"topic {topic} carries several types ({', '.join(types)})", path=path)
    msgtype = types[0]
    if msgtype not in POSE_TYPES:
        raise TopicError(
            f"topic {topic} has type {msgtype}, not a pose type "
            f"({', '.join(t for t in POSE_TYPES)})",
            path=path,
        )
    return msgtype


def _batch_to_stream(batch: PoseBatch, msgtype: str, time_source: str, source: str) -> PoseStream:
    use_header = time_source == "header" and msgtype != "geometry_msgs/Pose2D"
    t = batch.t_header if use_header else batch.t_record
    fi, ci = batch.frame_idx, batch.child_idx
    frame = batch.frames[fi[0]] if len(fi) else ""
    child = batch.frames[ci[0]] if len(ci) else ""
    changes: tuple[FrameChange, ...] = ()
    if len(fi) and (_varies(fi) or _varies(ci)):
        changes = _frame_changes(batch, t)
        used = {batch.frames[i] for i in np.unique(np.concatenate([fi, ci]))}
        log.warning(
            "%s: frame ids change within the topic (%s); using the first, %r -> %r",
            source,
            ", ".join(sorted(used)),
            frame,
            child,
        )
    return PoseStream(t, batch.xyz, batch.quat_xyzw, frame, child, source, changes)


def _varies(codes: npt.NDArray[np.int32]) -> bool:
    """Whether the frame codes of a batch differ (a bulk read's codes of one frame pair are
    one value broadcast: nothing to compare)."""
    if codes.strides == (0,):
        return False
    return bool(np.any(codes != codes[0]))


def _frame_changes(batch: PoseBatch, t: npt.NDArray[np.int64]) -> tuple[FrameChange, ...]:
    """Where the frame names change, in time order (only called when they do change)."""
    order = np.argsort(t, kind="stable")
    ts = t[order]
    out: list[FrameChange] = []
    for name, codes in (
        ("frame_id", batch.frame_idx[order]),
        ("child_frame_id", batch.child_idx[order]),
    ):
        at = np.flatnonzero(codes[1:] != codes[:-1])[:MAX_FRAME_CHANGES] + 1
        out.extend(
            FrameChange(int(ts[k]), name, batch.frames[codes[k - 1]], batch.frames[codes[k]])
            for k in at.tolist()
        )
    out.sort(key=lambda c: c.t_ns)
    return tuple(out[:MAX_FRAME_CHANGES])


def read_poses(
    paths: PathsLike,
    topic: str,
    *,
    time_source: str = "header",
    start_ns: int | None = None,
    end_ns: int | None = None,
) -> PoseStream:
    """The poses of one pose topic, merged over all files, time-ordered.

    Args:
        paths: one bag or a logger's split files.
        topic: a ``PoseStamped``, ``Pose2D``, ``TransformStamped``,
            ``PoseWithCovarianceStamped``, ``Odometry`` or single-child TF topic.
        time_source: ``header`` (message stamp, default) or ``record`` (bag record time).
            ``Pose2D`` has no header and always uses the record time.
        start_ns, end_ns: keep samples with start_ns <= t <= end_ns (t as chosen above).

    Raises:
        BagError: missing or unreadable file.
        TopicError: topic absent from every file (the message lists the pose topics there are),
            or not a pose type.
    """
    return _read_sources(paths, [_TopicRead(topic, time_source)], start_ns, end_ns)[0]


@frozen_dataclass
class _TopicRead:
    """A pose topic read as a stream (:func:`read_poses`)."""

    topic: str
    time_source: str


@frozen_dataclass
class _TfRead:
    """A frame's pose from ``/tf`` and ``/tf_static`` (:func:`read_tf`)."""

    parent: str
    child: str


def _read_sources(
    paths: PathsLike,
    reads: Sequence[_TopicRead | _TfRead],
    start_ns: int | None,
    end_ns: int | None,
) -> list[PoseStream]:
    """Pose topics and tf frames of the same files, each file read once for all of them (one
    pass over its index and chunks, :func:`load_pose_batches`)."""
    for r in reads:
        if isinstance(r, _TopicRead) and r.time_source not in ("header", "record"):
            raise ValueError(f"time_source must be 'header' or 'record', not {r.time_source!r}")
    plist = path_list(paths)
    parts: list[list[PoseStream]] = [[] for _ in reads]
    per_edge: dict[tuple[str, str], list[PoseStream]] = {}
    static_edges: set[tuple[str, str]] = set()
    tf = any(isinstance(r, _TfRead) for r in reads)
    for p in plist:
        with open_bag(p) as bag:
            requests: list[Request] = []
            topic_plan: list[tuple[int, int, str]] = []  # (read, request, msgtype)
            for i, r in enumerate(reads):
                if not isinstance(r, _TopicRead):
                    continue
                conns = bag.topic_conns(r.topic)
                if not conns:
                    continue
                msgtype = _check_pose_conns(conns, r.topic, p)
                margin = HEADER_WINDOW_MARGIN_NS if r.time_source == "header" else 0
                lo = None if start_ns is None else start_ns - margin
                hi = None if end_ns is None else end_ns + margin
                topic_plan.append((i, _want(requests, conns, lo, hi), msgtype))
            tf_plan: list[tuple[str, list[Conn], tuple[int | None, int | None], list[int]]] = []
            if tf:
                lo = None if start_ns is None else start_ns - HEADER_WINDOW_MARGIN_NS
                hi = None if end_ns is None else end_ns + HEADER_WINDOW_MARGIN_NS
                for topic in TF_TOPICS:
                    tf_conns = [c for c in bag.topic_conns(topic) if c.msgtype in TF_TYPES]
                    if tf_conns:
                        window = (None, None) if topic == "/tf_static" else (lo, hi)
                        # One request per publisher: its transforms are one class to the
                        # decoder and usually one edge, with no merge of the publishers'
                        # messages to undo when the edges are split.
                        wants = [_want(requests, [c], *window) for c in tf_conns]
                        tf_plan.append((topic, tf_conns, window, wants))
            batches = load_pose_batches(bag, requests)
            shared = {k for _i, k, _t in topic_plan}
            tf_found = []
            for topic, tf_conns, window, wants in tf_plan:
                tf_batches = [batches[k] for k in wants]
                # (a topic read of the same request keeps the batch's rows)
                owns = [k not in shared for k in wants]
                if edges_overlap(tf_batches):
                    # Publishers sharing an edge: their transforms are needed in the order of
                    # one read of them all (each format orders ties its own way).
                    tf_batches, owns = [load_pose_batch(bag, tf_conns, *window)], [True]
                tf_found.append((topic, tf_conns, tf_batches, owns))
        for i, k, msgtype in topic_plan:
            r = reads[i]
            assert isinstance(r, _TopicRead)
            source = f"{p}:{r.topic}"
            stream = _batch_to_stream(batches[k], msgtype, r.time_source, source)
            parts[i].append(sort_poses(stream, source).window(start_ns, end_ns))
        for topic, tf_conns, tf_batches, owns in tf_found:
            for batch, own in zip(tf_batches, owns, strict=True):
                _add_tf_edges(per_edge, static_edges, p, topic, tf_conns, batch, own)
    edges: dict[tuple[str, str], Edge] = {}
    for key, found in per_edge.items():
        merged = merge_poses(found, f"tf {key[0]} -> {key[1]}")
        edges[key] = Edge(merged, key in static_edges or len(merged) == 1)
    out = []
    for r, found in zip(reads, parts, strict=True):
        if isinstance(r, _TopicRead):
            if not found:
                raise topic_error(plist, r.topic)
            out.append(merge_poses(found, r.topic))
        else:
            out.append(_tf_chain(plist, edges, r.parent, r.child, start_ns, end_ns))
    return out


def _want(requests: list[Request], conns: Sequence[Conn], lo: int | None, hi: int | None) -> int:
    """The index of the request for ``conns`` in [lo, hi] (added unless there already)."""
    req = Request(tuple(conns), lo, hi)
    if req not in requests:
        requests.append(req)
    return requests.index(req)


def _add_tf_edges(
    per_edge: dict[tuple[str, str], list[PoseStream]],
    static_edges: set[tuple[str, str]],
    path: Path,
    topic: str,
    conns: Sequence[Conn],
    batch: PoseBatch,
    own: bool,
) -> None:
    """The transforms of one tf topic of one file, split by (parent, child) edge (``own``: the
    batch is this function's to consume)."""
    static = topic == "/tf_static"
    for key, count, s in split_edges(batch, str(path), own):
        per_edge.setdefault(key, []).append(sort_poses(s, f"{path}:{topic} {key}"))
        if static or (any(c.latching for c in conns) and count == 1):
            static_edges.add(key)


def _tf_chain(
    plist: list[Path],
    edges: dict[tuple[str, str], Edge],
    parent: str,
    child: str,
    start_ns: int | None,
    end_ns: int | None,
) -> PoseStream:
    if not edges:
        raise topic_error(plist, "/tf", "tf topic")
    source = f"{plist[0]}:/tf" if len(plist) == 1 else f"{len(plist)} files:/tf"
    try:
        stream = chain_pose(edges, parent, child, source)
    except TopicError as err:
        raise TopicError(f"{err.message} (in {source})") from err
    return stream.window(start_ns, end_ns)


def read_tf(
    paths: PathsLike,
    parent: str,
    child: str,
    *,
    start_ns: int | None = None,
    end_ns: int | None = None,
) -> PoseStream:
    """Pose of ``child`` in ``parent`` from ``/tf`` and ``/tf_static``, chains composed.

    Accepts ``tf/tfMessage`` and ``tf2_msgs/TFMessage``; times are the transforms' header
    stamps. Frame names match with or without a leading slash. A chain (e.g. origin <- world ->
    ref_board) is sampled at the times of its link into ``child`` and the other links are
    interpolated there (see :mod:`ertools.io.decode.tf` for the exact rule).

    Raises:
        TopicError: no tf topic, an unknown frame, or no chain between the frames.
    """
    return _read_sources(paths, [_TfRead(parent, child)], start_ns, end_ns)[0]


def read_pose_source(
    paths: PathsLike,
    source: PoseSource,
    *,
    start_ns: int | None = None,
    end_ns: int | None = None,
) -> PoseStream:
    """A pose topic, or a tf frame when ``source.topic`` is None or a tf topic."""
    return read_pose_sources(paths, [source], start_ns=start_ns, end_ns=end_ns)[0]


def read_pose_sources(
    paths: PathsLike,
    sources: Sequence[PoseSource],
    *,
    start_ns: int | None = None,
    end_ns: int | None = None,
) -> list[PoseStream]:
    """Several pose sources of the same bags (:func:`read_pose_source` each), every file
    read once for all of them: one pass over its index and one over the chunks any of them
    touches (the GT hour's PoseStamped, Pose2D and /tf topics cost one read of the file).

    Raises:
        TopicError: a source not in the bags, as :func:`read_poses` and :func:`read_tf` say.
    """
    reads: list[_TopicRead | _TfRead] = []
    for source in sources:
        if source.topic is not None and source.topic not in TF_TOPICS:
            reads.append(_TopicRead(source.topic, source.time_source))
            continue
        if not source.frame:
            raise TopicError("a tf pose source needs a frame (the tf child frame)")
        reads.append(_TfRead(source.parent, source.frame))
    return _read_sources(paths, reads, start_ns, end_ns)


def _machine_of(topic: str, msgtype: str) -> Machine | None:
    from ertools.states import MSG_TYPES, STATE_TOPIC_SUFFIXES  # lazy: 5 enums, 2 ms, states only

    for machine, name in MSG_TYPES.items():
        if msgtype == name:
            return machine
    leaf = topic.rstrip("/").rsplit("/", 1)[-1]
    for machine, suffixes in STATE_TOPIC_SUFFIXES.items():
        if leaf in suffixes:
            return machine
    return None


def read_states(paths: PathsLike, topic: str) -> StateStream:
    """A BmBox/RefBox/Client state topic as (record time, state code, payload), time-ordered.

    The machine comes from the message type (``rockin_scoring/BmBoxState`` ...) or, failing
    that, from the topic name (``.../bmbox_state``). Messages in the 2015 layout (``uint8
    state``, ``string payload``) are decoded in bulk; anything else goes through rosbags.

    Raises:
        TopicError: topic absent, or not a state topic (no ``state``/``payload`` fields).
    """
    return _read_states(path_list(paths), [topic])[0]


def _read_states(plist: list[Path], names: Sequence[str]) -> list[StateStream]:
    """:func:`read_states` of several topics, each file read once for all of them."""
    t_parts: list[list[npt.NDArray[np.int64]]] = [[] for _ in names]
    s_parts: list[list[npt.NDArray[np.uint8]]] = [[] for _ in names]
    payloads: list[list[str]] = [[] for _ in names]
    msgtypes = [""] * len(names)
    for p in plist:
        with open_bag(p) as bag:
            present: list[tuple[int, list[Conn]]] = []
            for i, topic in enumerate(names):
                conns = bag.topic_conns(topic)
                if not conns:
                    continue
                msgtypes[i] = msgtypes[i] or conns[0].msgtype
                if _machine_of(topic, conns[0].msgtype) is None:
                    raise TopicError(
                        f"topic {topic} ({conns[0].msgtype}) is not a benchmark state topic "
                        "(bmbox_state, refbox_state, client_state)",
                        path=p,
                    )
                present.append((i, conns))
            bulks = bulk_states_many(bag, [conns for _i, conns in present])
            for (i, conns), bulk in zip(present, bulks, strict=True):
                if bulk is None:
                    bulk = _slow_states(bag, conns, names[i], p)
                t_parts[i].append(bulk[0])
                s_parts[i].append(bulk[1])
                payloads[i].extend(bulk[2])
    out = []
    for i, topic in enumerate(names):
        if not t_parts[i]:
            raise topic_error(plist, topic, "state topic")
        machine = _machine_of(topic, msgtypes[i])
        assert machine is not None
        t = np.concatenate(t_parts[i])
        state = np.concatenate(s_parts[i])
        texts = payloads[i]
        if len(t) > 1 and np.any(t[1:] < t[:-1]):
            log.warning("%s: messages from several files out of time order; sorted", topic)
            order = np.argsort(t, kind="stable")
            t, state, texts = t[order], state[order], [texts[k] for k in order.tolist()]
        src = str(plist[0]) if len(plist) == 1 else ";".join(map(str, plist))
        out.append(StateStream(machine, t, state, tuple(texts), topic, src))
    return out


def _slow_states(bag: BagFile, conns: list[Conn], topic: str, path: Path) -> States:
    """A state topic of one file deserialized by rosbags, message by message."""
    deser = Deserializer(conns, path)
    msgs = [(t, deser(raw, c)) for c, t, raw in bag.raw(conns)]
    if msgs and not (hasattr(msgs[0][1], "state") and hasattr(msgs[0][1], "payload")):
        raise TopicError(
            f"topic {topic}: type {conns[0].msgtype} has no state/payload fields", path=path
        )
    return (
        np.fromiter((t for t, _ in msgs), dtype=np.int64, count=len(msgs)),
        np.fromiter((int(m.state) for _, m in msgs), dtype=np.uint8, count=len(msgs)),
        [str(m.payload) for _, m in msgs],
    )


def read_benchmark_states(paths: PathsLike, namespace: str) -> BenchmarkStates:
    """The BmBox, RefBox and Client state streams of ``namespace`` (e.g. ``fbm3w``).

    A machine whose topic is in none of the files is None. The BmBox topic is looked up as
    ``bmbox_state`` and as the seed's misspelt ``bbbox_state``.
    """
    from ertools.states import STATE_TOPIC_SUFFIXES, Machine  # lazy: 5 enums, 2 ms, states only

    plist = path_list(paths)
    present = topics(plist)
    ns = "/" + namespace.strip("/")
    wanted: dict[Machine, str] = {}
    for machine, suffixes in STATE_TOPIC_SUFFIXES.items():
        topic = next((f"{ns}/{s}" for s in suffixes if f"{ns}/{s}" in present), None)
        if topic is not None:
            wanted[machine] = topic
    # the three topics from one pass over each file
    streams = dict(zip(wanted, _read_states(plist, list(wanted.values())), strict=True))
    found: dict[Machine, StateStream | None] = {m: streams.get(m) for m in STATE_TOPIC_SUFFIXES}
    if all(v is None for v in found.values()):
        log.info("no state topics of %s in %s", ns, plist[0])
    return BenchmarkStates(found[Machine.BMBOX], found[Machine.REFBOX], found[Machine.CLIENT])
