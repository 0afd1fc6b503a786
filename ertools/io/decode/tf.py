"""tf trees from ``/tf`` and ``/tf_static``: the pose of any frame in any other, chains composed.

A chain such as origin <- world -> ref_board (mocap publishes ``world -> origin`` and
``world -> ref_board``) gives ``origin -> ref_board`` as ``inv(T_world_origin) *
T_world_ref_board``.

Time base of a chain: the samples of the link that ends in the requested child frame (the
requested link), so a chain has as many samples as that link has inside the others' spans.
Every other link is interpolated at those times with :func:`ertools.geometry.interpolate_poses`
(linear in position, SLERP in rotation), in its stored direction, and inverted afterwards when
the chain walks it backwards. A static link (from ``/tf_static`` or with a single sample) holds
its value at all times; a moving link contributes only inside its own time span (times before
its first or after its last sample are dropped, never extrapolated). When the requested link
is static the most frequent moving link of the chain gives the time base instead.
"""

from __future__ import annotations

from collections import deque

import numpy as np

from ertools.arrays import F64, I32, I64, Bool
from ertools.errors import TopicError
from ertools.frozen_dataclass import frozen_dataclass
from ertools.geometry import compose, interpolate_poses, invert
from ertools.io.decode.posebatch import PoseBatch
from ertools.streams import PoseStream


def frame_key(name: str) -> str:
    """Frame names as tf2 compares them (no leading slash)."""
    return name.lstrip("/")


def _one_code(codes: I32) -> bool:
    """Whether frame codes are one value broadcast (a bulk read of one frame pair)."""
    return len(codes) > 0 and codes.strides == (0,)


def edge_keys(batch: PoseBatch) -> set[tuple[str, str]]:
    """The (parent, child) edges of a tf batch, frame names as tf2 compares them."""
    if not len(batch):
        return set()
    frames = [frame_key(f) for f in batch.frames]
    if _one_code(batch.frame_idx) and _one_code(batch.child_idx):
        return {(frames[int(batch.frame_idx[0])], frames[int(batch.child_idx[0])])}
    pairs = batch.frame_idx.astype(np.int64) * len(frames) + batch.child_idx
    codes = np.flatnonzero(np.bincount(pairs, minlength=len(frames) ** 2)).tolist()
    return {(frames[c // len(frames)], frames[c % len(frames)]) for c in codes}


def edges_overlap(batches: list[PoseBatch]) -> bool:
    """Whether two of the batches (a topic's publishers) hold the same edge."""
    seen: set[tuple[str, str]] = set()
    for batch in batches:
        keys = edge_keys(batch)
        if keys & seen:
            return True
        seen |= keys
    return False


def split_edges(
    batch: PoseBatch, source: str, own: bool
) -> list[tuple[tuple[str, str], int, PoseStream]]:
    """The transforms of a tf batch as one stream per (parent, child) edge, with its number
    of rows, in the order of the edges' frame codes. With ``own`` (the batch is the caller's
    to consume) the edge of most rows (a body beside a static transform) is moved up in the
    batch's own arrays rather than copied."""
    frames = [frame_key(f) for f in batch.frames]
    if _one_code(batch.frame_idx) and _one_code(batch.child_idx):
        # one edge (a publisher of one transform): its rows are the batch's, nothing to split
        key = (frames[int(batch.frame_idx[0])], frames[int(batch.child_idx[0])])
        t, xyz, quat = batch.t_header, batch.xyz, batch.quat_xyzw
        if not own:
            t, xyz, quat = t.copy(), xyz.copy(), quat.copy()
        return [(key, len(batch), PoseStream(t, xyz, quat, key[0], key[1], source))]
    pairs = batch.frame_idx.astype(np.int64) * len(frames) + batch.child_idx
    # a few (parent, child) pairs: one comparison each rather than a sort of every row
    counts = np.bincount(pairs, minlength=len(frames) ** 2) if len(pairs) else pairs
    codes = np.flatnonzero(counts).tolist()
    biggest = max(codes, key=lambda c: int(counts[c])) if codes else -1
    found: dict[int, tuple[I64, F64, F64]] = {}
    for code in codes:
        if code != biggest or not own:
            rows = pairs == code
            found[code] = (batch.t_header[rows], batch.xyz[rows], batch.quat_xyzw[rows])
    if codes and own:
        found[biggest] = _compacted(batch, pairs == biggest if len(codes) > 1 else None)
    out = []
    for code in codes:
        key = (frames[code // len(frames)], frames[code % len(frames)])
        t, xyz, quat = found[code]
        out.append((key, int(counts[code]), PoseStream(t, xyz, quat, key[0], key[1], source)))
    return out


# Rows moved per step when an edge is compacted in place (a temporary of this many rows).
_COMPACT_ROWS = 1 << 16


def _compacted(batch: PoseBatch, keep: Bool | None) -> tuple[I64, F64, F64]:
    """The stamps and poses of the rows ``keep`` (None: all), moved to the front of the
    batch's own arrays a block at a time: the rows of a block are taken (whole rows at a time)
    before any is written, and each row only moves forward, past rows already read."""
    arrays = (batch.t_header, batch.xyz, batch.quat_xyzw)
    if keep is None:
        return arrays
    rows = np.flatnonzero(keep)
    for start in range(0, len(rows), _COMPACT_ROWS):
        part = rows[start : start + _COMPACT_ROWS]
        for a in arrays:
            a[start : start + len(part)] = np.take(a, part, axis=0)
    n = len(rows)
    return batch.t_header[:n], batch.xyz[:n], batch.quat_xyzw[:n]


@frozen_dataclass
class Edge:
    """One parent -> child link as published, with whether it is static."""

    stream: PoseStream
    static: bool


@frozen_dataclass
class _Step:
    """One link of a chain, walked as stored or backwards."""

    edge: Edge
    inverted: bool


def find_chain(edges: dict[tuple[str, str], Edge], parent: str, child: str) -> list[_Step]:
    """The shortest chain of links from ``parent`` to ``child`` (breadth-first).

    Raises:
        TopicError: no chain connects the two frames.
    """
    adjacency: dict[str, list[tuple[str, _Step]]] = {}
    for (p, c), edge in edges.items():
        adjacency.setdefault(p, []).append((c, _Step(edge, False)))
        adjacency.setdefault(c, []).append((p, _Step(edge, True)))
    if parent not in adjacency or child not in adjacency:
        missing = [f for f in (parent, child) if f not in adjacency]
        raise TopicError(
            f"tf frame(s) {', '.join(missing)} not in /tf or /tf_static; frames there: "
            f"{', '.join(sorted(adjacency)) or 'none'}"
        )
    previous: dict[str, tuple[str, _Step] | None] = {parent: None}
    queue = deque([parent])
    while queue:
        node = queue.popleft()
        if node == child:
            break
        for nxt, step in adjacency[node]:
            if nxt not in previous:
                previous[nxt] = (node, step)
                queue.append(nxt)
    if child not in previous:
        raise TopicError(f"no tf chain connects {parent} to {child}")
    steps: list[_Step] = []
    node = child
    while (link := previous[node]) is not None:
        node, step = link
        steps.append(step)
    return steps[::-1]


def _time_base(steps: list[_Step]) -> int:
    if not steps[-1].edge.static:
        return len(steps) - 1
    moving = [i for i, s in enumerate(steps) if not s.edge.static]
    if not moving:
        return len(steps) - 1
    return max(moving, key=lambda i: len(steps[i].edge.stream))


def compose_chain(steps: list[_Step], parent: str, child: str, source: str) -> PoseStream:
    """The poses of ``child`` in ``parent`` along ``steps`` (see the module docstring)."""

    base = steps[_time_base(steps)].edge.stream
    t = base.t_ns
    keep = np.ones(len(t), dtype=bool)
    parts = []
    for step in steps:
        stream = step.edge.stream
        if len(stream) == 0:
            return PoseStream.empty(parent, child, source)
        if stream is base:
            xyz, quat = stream.xyz, stream.quat_xyzw
        else:
            at = interpolate_poses(stream, t, "linear")
            xyz, quat = at.xyz, at.quat_xyzw
            if not step.edge.static and len(stream) > 1:
                keep &= at.inside
        if step.inverted:
            xyz, quat = invert(xyz, quat)
        parts.append((xyz, quat))
    xyz, quat = parts[0]
    for nxt_xyz, nxt_quat in parts[1:]:
        xyz, quat = compose(xyz, quat, nxt_xyz, nxt_quat)
    return PoseStream(t[keep], xyz[keep], quat[keep], parent, child, source)


def chain_pose(
    edges: dict[tuple[str, str], Edge], parent: str, child: str, source: str = ""
) -> PoseStream:
    """Pose stream of ``child`` in ``parent`` from tf links keyed by (parent, child)."""
    p, c = frame_key(parent), frame_key(child)
    if p == c:
        raise TopicError(f"tf parent and child are the same frame {p!r}")
    steps = find_chain(edges, p, c)
    if len(steps) == 1 and not steps[0].inverted:
        s = steps[0].edge.stream
        return PoseStream(s.t_ns, s.xyz, s.quat_xyzw, p, c, source)
    return compose_chain(steps, p, c, source)
