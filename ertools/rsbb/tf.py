"""The RSBB scripts' tf lookups, from a run bag's ``/tf`` (docs/rsbb.md, "Timing in the log").

Every script looks a pose up with the same helper (``Pose2D_from_tf_concatenation``): take
``now``; wait up to a timeout until the mocap body is known at ``now``; broadcast its own frame
(``/robot``, ``/item``, ``/person``, ``/object``) under the body at ``now`` with a fixed
transform; look that frame up in the reference frame; yaw from tf's Euler angles. A failure
costs the timeout; the helper stops after ``max_failed_attempts`` failures or when the
benchmark stops.

This module gives:

- :func:`read_tf_tracks`: ``/tf`` in one pass, each link's samples with their header stamps
  and record times (when the listener had them), and the script's broadcasts;
- :func:`script_poses`: the frame's pose at given moments as tf2 computed it (each link
  interpolated at the moment: linear position with ``ros::Duration::toSec`` ratios, tf2's
  shortest-path slerp; composed with unnormalised Hamilton products; yaw as
  ``euler_from_quaternion``), vectorised;
- :func:`helper_lookup`: the helper's attempts against the logged broadcasts (which attempt
  succeeded, at which ``now``, and the script's clock afterwards).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import field
from pathlib import Path

import numpy as np

from ertools.arrays import F64, I64, Bool
from ertools.errors import TopicError
from ertools.frozen_dataclass import frozen_dataclass
from ertools.io.bagfile import BagFile
from ertools.io.files import open_bag
from ertools.io.model import TF_TYPES
from ertools.io.reader import load_pose_batch
from ertools.rsbb_states import MOCAP_PARENT, ScriptFrame

NS = 1_000_000_000
#: The script's clock is inferred from the RefBox's messages, which follow its own moments by a
#: few milliseconds: a logged lookup stamped up to this before the inferred clock is still the
#: attempt's (the replays' World uses the same slack).
LOOKUP_SLACK_NS = 50_000_000
#: tf.transformations' ``_EPS`` (NumPy's float64 eps times 4).
EULER_EPS = 4.0 * float(np.finfo(np.float64).eps)


def tf_frame(name: str) -> str:
    """A frame as tf2 compares it: no leading slash."""
    return name.lstrip("/")


@frozen_dataclass(eq=False)
class TfTrack:
    """One tf link's samples, sorted by header stamp.

    Attributes:
        parent, child: tf spelling (no leading slash).
        t_ns: (N,) header stamps.
        arrival_ns: (N,) record times (when the recorder, on the scripts' machine, had them).
        xyz: (N, 3) translations as published.
        quat_xyzw: (N, 4) rotations as published (not renormalised, as tf2 keeps them).
        source: where it was read.
    """

    parent: str
    child: str
    t_ns: I64
    arrival_ns: I64
    xyz: F64
    quat_xyzw: F64
    source: str = ""
    _first_arrival: I64 = field(init=False, repr=False)

    def __post_init__(self) -> None:
        # the earliest arrival among the samples stamped at or after each sample's stamp
        suffix = np.minimum.accumulate(self.arrival_ns[::-1])[::-1].copy()
        object.__setattr__(self, "_first_arrival", suffix)

    def __len__(self) -> int:
        return int(self.t_ns.shape[0])

    def ready_ns(self, t_ns: int) -> int | None:
        """When data stamped at or after ``t_ns`` first arrived (a wait for ``t_ns`` returns
        then), or None when none did."""
        k = int(np.searchsorted(self.t_ns, t_ns, side="left"))
        return int(self._first_arrival[k]) if k < len(self) else None


@frozen_dataclass
class TfTracks:
    """A run bag's ``/tf``: every link by (parent, child) and the script's broadcasts."""

    links: dict[tuple[str, str], TfTrack]
    source: str

    def body(self, name: str, parent: str = MOCAP_PARENT) -> TfTrack:
        """The mocap body ``name`` under ``parent``.

        Raises:
            TopicError: the bag's ``/tf`` has no such link.
        """
        key = (tf_frame(parent), tf_frame(name))
        track = self.links.get(key)
        if track is None or len(track) == 0:
            known = sorted(c for p, c in self.links if p == key[0])
            raise TopicError(
                f"no /tf {key[0]} -> {key[1]} in {self.source} (the mocap body was never "
                f"tracked); bodies there: {', '.join(known) or 'none'}"
            )
        return track

    def broadcasts(self, frame: ScriptFrame) -> I64:
        """The stamps (each lookup's ``now``) of the script's broadcasts of ``frame``, sorted;
        empty when it made none."""
        track = self.links.get((tf_frame(frame.parent), tf_frame(frame.child)))
        return np.empty(0, np.int64) if track is None else track.t_ns


def _bag_links(bag: BagFile) -> dict[tuple[str, str], list[TfTrack]]:
    conns = [c for c in bag.topic_conns("/tf") if c.msgtype in TF_TYPES]
    out: dict[tuple[str, str], list[TfTrack]] = {}
    if not conns:
        return out
    batch = load_pose_batch(bag, conns, None, None)
    frames = [tf_frame(f) for f in batch.frames]
    pairs = batch.frame_idx.astype(np.int64) * len(frames) + batch.child_idx
    for code in np.unique(pairs).tolist():
        rows = np.flatnonzero(pairs == code)
        rows = rows[np.argsort(batch.t_header[rows], kind="stable")]
        key = (frames[code // len(frames)], frames[code % len(frames)])
        out.setdefault(key, []).append(
            TfTrack(
                key[0],
                key[1],
                batch.t_header[rows],
                batch.t_record[rows],
                batch.xyz[rows],
                batch.quat_xyzw[rows],
                str(bag.path),
            )
        )
    return out


def read_tf_tracks(paths: str | Path | Sequence[str | Path]) -> TfTracks:
    """``/tf`` of a run bag (or its split files), every link with stamps and arrivals.

    Raises:
        BagError: unreadable bag.
        TopicError: no ``/tf`` in it.
    """
    plist = [Path(paths)] if isinstance(paths, str | Path) else [Path(p) for p in paths]
    parts: dict[tuple[str, str], list[TfTrack]] = {}
    for p in plist:
        with open_bag(p) as bag:
            for key, tracks in _bag_links(bag).items():
                parts.setdefault(key, []).extend(tracks)
    where = str(plist[0]) if len(plist) == 1 else f"{len(plist)} files"
    if not parts:
        raise TopicError(f"no /tf in {where}: the mocap and the script's lookups are on /tf")
    links = {}
    for key, tracks in parts.items():
        t = np.concatenate([x.t_ns for x in tracks])
        order = np.argsort(t, kind="stable")
        links[key] = TfTrack(
            key[0],
            key[1],
            t[order],
            np.concatenate([x.arrival_ns for x in tracks])[order],
            np.concatenate([x.xyz for x in tracks])[order],
            np.concatenate([x.quat_xyzw for x in tracks])[order],
            where,
        )
    return TfTracks(links, where)


# --- tf2's arithmetic, vectorised ----------------------------------------------------------


def duration_sec(ns: I64) -> F64:
    """``ros::Duration::toSec()`` of nanosecond counts: seconds plus nanoseconds times 1e-9."""
    sec, nsec = np.divmod(np.asarray(ns, dtype=np.int64), NS)
    return np.asarray(sec.astype(np.float64) + 1e-9 * nsec.astype(np.float64))


def qmul(a: F64, b: F64) -> F64:
    """Hamilton products of (..., 4) quaternions (x, y, z, w), not normalised."""
    ax, ay, az, aw = (a[..., i] for i in range(4))
    bx, by, bz, bw = (b[..., i] for i in range(4))
    return np.stack(
        [
            aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw,
            aw * bw - ax * bx - ay * by - az * bz,
        ],
        axis=-1,
    )


def _conj(q: F64) -> F64:
    return np.asarray(q * np.array([-1.0, -1.0, -1.0, 1.0]))


def qrotate(q: F64, v: F64) -> F64:
    """``q v q*`` (tf2's ``quatRotate``: the conjugate, not the inverse, of a non-unit q)."""
    v4 = np.concatenate([v, np.zeros((*v.shape[:-1], 1))], axis=-1)
    return np.asarray(qmul(qmul(q, v4), _conj(q))[..., :3])


def tf_compose(t1: F64, q1: F64, t2: F64, q2: F64) -> tuple[F64, F64]:
    """T1 * T2 as tf2 multiplies transforms."""
    return t1 + qrotate(q1, np.broadcast_to(t2, t1.shape)), qmul(q1, q2)


def tf_invert(t: F64, q: F64) -> tuple[F64, F64]:
    """T^-1 as tf2 inverts a transform (conjugate rotation)."""
    qi = _conj(q)
    return -qrotate(qi, t), qi


def tf_slerp(a: F64, b: F64, ratio: F64) -> F64:
    """tf2's ``slerp``: the half angle from ``|a.b| / (|a| |b|)``; ``a`` when it is 0."""
    dot = np.sum(a * b, axis=-1)
    norms = np.sqrt(np.sum(a * a, axis=-1) * np.sum(b * b, axis=-1))
    half = np.arccos(np.clip(np.abs(dot) / norms, -1.0, 1.0))
    same = half == 0.0
    d = 1.0 / np.sin(np.where(same, 1.0, half))
    s0 = np.sin((1.0 - ratio) * half)
    s1 = np.where(dot < 0, -1.0, 1.0) * np.sin(ratio * half)
    mixed = (a * s0[..., None] + b * s1[..., None]) * d[..., None]
    return np.asarray(np.where(same[..., None], a, mixed))


def euler_yaw(q: F64) -> F64:
    """The z angle of ``tf.transformations.euler_from_quaternion`` (static x-y-z axes):
    ``atan2(R10, R00)`` of the normalised rotation matrix, 0 where it is degenerate."""
    nq = np.sum(q * q, axis=-1)
    ok = nq >= EULER_EPS
    s = np.sqrt(2.0 / np.where(ok, nq, 1.0))
    x, y, z, w = (q[..., i] * s for i in range(4))
    m00 = 1.0 - y * y - z * z
    m10 = x * y + z * w
    cy = np.sqrt(m00 * m00 + m10 * m10)
    return np.asarray(np.where(ok & (cy > EULER_EPS), np.arctan2(m10, m00), 0.0))


@frozen_dataclass(eq=False)
class LinkAt:
    """A link evaluated at moments as tf2 does (:func:`link_at`).

    Attributes:
        xyz, quat_xyzw: (M, 3), (M, 4) the link's value (the nearest end sample outside).
        inside: (M,) the moment lies within the samples (else tf2 refuses: extrapolation).
        gap_ns: (M,) the time between the samples around the moment (0 on an exact stamp).
    """

    xyz: F64
    quat_xyzw: F64
    inside: Bool
    gap_ns: I64


def link_at(track: TfTrack, t_ns: I64) -> LinkAt:
    """``track`` at ``t_ns``: a sample stamped exactly then (the last of equal stamps), else the
    two around it interpolated as tf2's time cache does."""
    t = track.t_ns
    n = len(track)
    q_ns = np.asarray(t_ns, dtype=np.int64)
    if n == 0:
        empty = np.zeros(q_ns.shape, dtype=bool)
        return LinkAt(
            np.zeros((*q_ns.shape, 3)),
            np.tile([0.0, 0.0, 0.0, 1.0], (*q_ns.shape, 1)),
            empty,
            np.full(q_ns.shape, np.iinfo(np.int64).max),
        )
    right = np.searchsorted(t, q_ns, side="right")
    exact_lo = right - 1
    exact = (exact_lo >= 0) & (t.take(np.maximum(exact_lo, 0)) == q_ns)
    before = np.clip(right - 1, 0, n - 1)
    after = np.clip(right, 0, n - 1)
    inside = exact | ((right > 0) & (right < n))
    before = np.where(exact, exact_lo.clip(0), before)
    after = np.where(exact, before, after)
    span = t.take(after) - t.take(before)
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = duration_sec(q_ns - t.take(before)) / duration_sec(span)
    ratio = np.where(exact | ~inside, 0.0, ratio)
    a_xyz, b_xyz = track.xyz.take(before, axis=0), track.xyz.take(after, axis=0)
    s = (1.0 - ratio)[..., None]
    xyz = s * a_xyz + ratio[..., None] * b_xyz
    quat = tf_slerp(
        track.quat_xyzw.take(before, axis=0), track.quat_xyzw.take(after, axis=0), ratio
    )
    gap = np.where(inside, span, np.iinfo(np.int64).max)
    return LinkAt(np.asarray(xyz), quat, np.asarray(inside), np.asarray(gap, dtype=np.int64))


@frozen_dataclass(eq=False)
class ScriptPoses:
    """The script's frame looked up at moments (:func:`script_poses`).

    Attributes:
        t_ns: (M,) the moments (each lookup's ``now``).
        xyz: (M, 3) the frame's position in the reference frame.
        quat_xyzw: (M, 4) its rotation there (as tf2 composed it, not renormalised).
        theta: (M,) yaw as ``euler_from_quaternion`` gives it, in [-pi, pi].
        inside: (M,) every link had samples on both sides of (or at) the moment.
        gap_ns: (M,) the widest interval between the samples interpolated across.
    """

    t_ns: I64
    xyz: F64
    quat_xyzw: F64
    theta: F64
    inside: Bool
    gap_ns: I64

    @property
    def x(self) -> F64:
        return np.asarray(self.xyz[:, 0])

    @property
    def y(self) -> F64:
        return np.asarray(self.xyz[:, 1])

    @property
    def z(self) -> F64:
        return np.asarray(self.xyz[:, 2])


def script_poses(
    body: TfTrack,
    t_ns: I64,
    transform: tuple[Sequence[float], Sequence[float]],
    reference: TfTrack | None = None,
) -> ScriptPoses:
    """The script's frame (``transform`` = (translation, quaternion) under the mocap ``body``)
    at ``t_ns``, in the root frame (``reference`` None: ``testbed_origin``) or in the mocap
    body ``reference``, as tf2 returned it to the script."""
    q_ns = np.asarray(t_ns, dtype=np.int64)
    m = int(q_ns.shape[0])
    fixed_t = np.tile(np.asarray(transform[0], dtype=np.float64), (m, 1))
    fixed_q = np.tile(np.asarray(transform[1], dtype=np.float64), (m, 1))
    at = link_at(body, q_ns)
    xyz, quat = tf_compose(at.xyz, at.quat_xyzw, fixed_t, fixed_q)
    inside, gap = at.inside, at.gap_ns
    if reference is not None:
        ref = link_at(reference, q_ns)
        xyz, quat = tf_compose(*tf_invert(ref.xyz, ref.quat_xyzw), xyz, quat)
        inside = inside & ref.inside
        gap = np.maximum(gap, ref.gap_ns)
    return ScriptPoses(q_ns, xyz, quat, euler_yaw(quat), inside, gap)


# --- the helper's attempts ------------------------------------------------------------------


@frozen_dataclass
class HelperOutcome:
    """What one call of the helper did (:func:`helper_lookup`).

    Attributes:
        stamp_ns: the successful attempt's ``now`` (its broadcast's stamp), None: no pose.
        clock_ns: the script's clock when the helper returned.
        failed: failed attempts.
        next_index: the first logged broadcast not yet used.
    """

    stamp_ns: int | None
    clock_ns: int
    failed: int
    next_index: int


def helper_lookup(
    stamps: I64,
    index: int,
    clock_ns: int,
    *,
    attempts: int | None,
    timeout_s: float,
    stop_ns: int | None,
    waits: Sequence[TfTrack] = (),
    until_ns: int | None = None,
) -> HelperOutcome:
    """The helper called at ``clock_ns``, told by the log which attempts succeeded.

    An attempt taken at ``now`` succeeds when a broadcast not yet used (from ``index``) is
    stamped within ``[now - LOOKUP_SLACK_NS, now + timeout)``: its stamp is the ``now``, and the
    clock moves on to when the mocap ``waits`` had data at it. Else it fails and costs the
    timeout. The loop ends after ``attempts`` failures (None: no limit), when the benchmark has
    stopped (``stop_ns``), or, without either, at ``until_ns`` (the log's end).
    """
    timeout = round(timeout_s * NS)
    failed = 0
    n = int(stamps.shape[0])
    while (stop_ns is None or clock_ns < stop_ns) and (until_ns is None or clock_ns <= until_ns):
        if attempts is not None and failed >= attempts:
            break
        k = max(index, int(np.searchsorted(stamps, clock_ns - LOOKUP_SLACK_NS, side="left")))
        if k < n and int(stamps[k]) < clock_ns + timeout:
            stamp = int(stamps[k])
            ready = [r for r in (w.ready_ns(stamp) for w in waits) if r is not None]
            return HelperOutcome(stamp, max(clock_ns, stamp, *ready), failed, k + 1)
        index = k
        clock_ns += timeout
        failed += 1
    return HelperOutcome(None, clock_ns, failed, index)
