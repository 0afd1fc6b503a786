"""FBM1 ground truth: the item's pose in the table frame from the two mocap bodies.

T_origin_item = T_world_origin^-1 * T_world_board * T_board_item, where ``origin`` is the
marker set on the FBM1 table (its frame is the table frame the robot answers in),
``ref_board`` the marker set on the reference board and T_board_item the item's transform from
the item list (Listing 9).

The nodes took one tf lookup: ``lookupTransform("/origin", "/item", rospy.Time(0))`` right
after broadcasting the item's transform (``item`` under ``ref_board``) once, stamped ``now``.
tf answers ``Time(0)`` at the latest time common to the chain, and the item link has the one
stamp ``now``: the ground truth is origin and board interpolated (linear, slerp) at ``now``.
The 2015 nodes (``fbm1h``, ``fbm1w``) broadcast it when the result had arrived
(``method="result"``: the BmBox leaving ``WAITING_RESULT``); the 2016-17 @Home node when the
referee had confirmed the placement, before the goal (``method="placed"``: BmBox
``COMPLETED_MANUAL_OPERATION``). The log's state messages give those moments to within the
node's processing time (milliseconds). ertools averages the samples of the stationary window that
ends when the goal is sent and reports their spread (``method="window"``).
"""

from __future__ import annotations

import math

import numpy as np

from ertools.benchmarks.common import motion
from ertools.benchmarks.common.hygiene import drop_invalid
from ertools.benchmarks.fbm1.config import GtOptions
from ertools.configs.items import Item
from ertools.frozen_dataclass import frozen_dataclass
from ertools.geometry import compose, interpolate_poses, invert, mean_pose, yaw_from_quat
from ertools.streams import PoseStream
from ertools.timeutil import NS_PER_S


@frozen_dataclass
class GroundTruth:
    """The item's pose in the table frame for one run.

    Attributes:
        x: metres.
        y: metres.
        z: metres (not scored; a large value means a wrong item transform or board).
        yaw: radians in [-pi, pi].
        quat_xyzw: full orientation.
        board_xy: the board's position in the table frame (for plots).
        position_spread_m: RMS distance of the averaged samples from their mean.
        angle_spread_deg: RMS rotation of the averaged samples from their mean.
        samples: number of samples averaged (1 for the 2015 single lookups).
        start_ns: first sample used.
        end_ns: last sample used (for a lookup: its moment, as ``start_ns``).
        method: how it was measured.
        moment: for a lookup, where its moment came from: ``item tf stamp`` (the node's own
            broadcast of the item, logged on /tf: exact) or ``state message`` (the BmBox state
            that the node acted on; its own clock read up to one 10 Hz heartbeat earlier).
    """

    x: float
    y: float
    z: float
    yaw: float
    quat_xyzw: tuple[float, float, float, float]
    board_xy: tuple[float, float]
    position_spread_m: float
    angle_spread_deg: float
    samples: int
    start_ns: int
    end_ns: int
    method: str
    moment: str = ""

    @property
    def yaw_deg(self) -> float:
        return math.degrees(self.yaw)


class GroundTruthError(Exception):
    """A run whose ground truth cannot be measured (the caller adds the run's name)."""


def board_in_table(origin: PoseStream, board: PoseStream, max_gap_ns: int) -> PoseStream:
    """T_origin_board at each board sample where the origin is known (interpolated).

    Board samples outside the origin's time span, or inside an origin gap longer than
    ``max_gap_ns``, are dropped, and so are the samples of either body that are no
    measurement (NaN, a zero quaternion, physically impossible: the validity counts them).
    """
    origin, board = drop_invalid(origin)[0], drop_invalid(board)[0]
    if len(origin) == 0 or len(board) == 0:
        return PoseStream.empty("origin", "ref_board")
    at = interpolate_poses(origin, board.t_ns, "linear")
    ok = at.inside & (at.gap_ns <= max_gap_ns)
    inv_t, inv_q = invert(at.xyz[ok], at.quat_xyzw[ok])
    xyz, quat = compose(inv_t, inv_q, board.xyz[ok], board.quat_xyzw[ok])
    return PoseStream(board.t_ns[ok], xyz, quat, "origin", "ref_board", board.source)


def coverage_problem(
    stream: PoseStream, name: str, start_ns: int, end_ns: int, max_gap_ns: int, t0_ns: int = 0
) -> str | None:
    """Why ``stream`` does not cover [start_ns, end_ns] within ``max_gap_ns``, or None."""
    t = stream.t_ns
    if len(t) == 0:
        return f"no {name} pose in the log"
    inside = t[(t >= start_ns) & (t <= end_ns)]
    lo = np.searchsorted(t, start_ns, side="right") - 1
    hi = np.searchsorted(t, end_ns, side="left")
    # Samples bracketing the interval count too: tracking ending 2 ms before is fine.
    edges = [t[lo]] if lo >= 0 else []
    after = [t[hi]] if hi < len(t) else []
    pts = np.concatenate([np.asarray(edges, np.int64), inside, np.asarray(after, np.int64)])
    if len(pts) == 0 or pts[0] > start_ns + max_gap_ns or pts[-1] < end_ns - max_gap_ns:
        first, last = (pts[0], pts[-1]) if len(pts) else (t[0], t[-1])
        if last < start_ns or first > end_ns:
            return (
                f"{name} not tracked (no pose between {_s(start_ns - t0_ns)} "
                f"and {_s(end_ns - t0_ns)})"
            )
        return (
            f"{name} lost (poses cover {_s(first - t0_ns)}..{_s(last - t0_ns)}, "
            f"needed {_s(start_ns - t0_ns)}..{_s(end_ns - t0_ns)})"
        )
    clipped = np.clip(pts, start_ns, end_ns)
    gaps = np.diff(clipped)
    if len(gaps) and int(gaps.max()) > max_gap_ns:
        k = int(np.argmax(gaps))
        return (
            f"{name} lost for {gaps[k] / NS_PER_S:.2f} s from {_s(int(clipped[k]) - t0_ns)} "
            f"(longer than {max_gap_ns / NS_PER_S:g} s)"
        )
    return None


def tracked_problem(
    stream: PoseStream, name: str, at_ns: int, max_gap_ns: int, t0_ns: int = 0
) -> str | None:
    """Why ``stream`` was not tracked at ``at_ns`` (no sample in the max_gap before it)."""
    t = stream.t_ns
    if len(t) == 0:
        return f"no {name} pose in the log"
    k = int(np.searchsorted(t, at_ns, side="right")) - 1
    if k < 0:
        return f"{name} not tracked yet at {_s(at_ns - t0_ns)} (first pose {_s(int(t[0]) - t0_ns)})"
    age = at_ns - int(t[k])
    if age > max_gap_ns:
        return (
            f"{name} lost at {_s(at_ns - t0_ns)} (last pose {age / NS_PER_S:.2f} s before, "
            f"at {_s(int(t[k]) - t0_ns)})"
        )
    return None


def _s(ns: int) -> str:
    """Seconds with ms (times in messages are relative to the log's start)."""
    return f"t={ns / NS_PER_S:.3f} s"


def _item_poses(rel: PoseStream, item: Item) -> tuple[np.ndarray, np.ndarray]:
    assert item.trans is not None and item.rot is not None
    n = len(rel)
    t_item = np.tile(np.asarray(item.trans, dtype=np.float64), (n, 1))
    q_item = np.tile(np.asarray(item.rot, dtype=np.float64), (n, 1))
    return compose(rel.xyz, rel.quat_xyzw, t_item, q_item)


def stationary_tail(
    rel: PoseStream, still_m: float, still_deg: float, max_gap_ns: int | None = None
) -> PoseStream:
    """The samples at the end of ``rel`` that stay within tolerance of its final pose.

    The final pose is the mean of the last 0.2 s, so one noisy last sample does not decide.
    A tracking gap longer than ``max_gap_ns`` ends the tail too: nobody saw the board then.
    """
    from scipy.spatial.transform import Rotation  # lazy: scipy, 300 ms

    if len(rel) == 0:
        return rel
    last = rel.window(rel.end_ns - NS_PER_S // 5, None)
    ref = mean_pose(last.xyz, last.quat_xyzw)
    dist = np.linalg.norm(rel.xyz - ref.xyz, axis=1)
    ang = (Rotation.from_quat(ref.quat_xyzw).inv() * Rotation.from_quat(rel.quat_xyzw)).magnitude()
    # "not beyond" rather than "within": a NaN sample does not end the tail
    still = ~((dist > still_m) | (ang > math.radians(still_deg)))
    # A sample after a long gap starts a new tail.
    runs = motion.still_runs(rel.t_ns, still, max_gap_ns=max_gap_ns)
    n = len(rel)
    start = runs[-1][0] if runs and runs[-1][1] == n - 1 else n
    return rel.take(slice(start, None))


def settled(tail: PoseStream) -> PoseStream:
    """Drop the first samples of a stationary tail, those still settling into place.

    The tail tolerance (millimetres) must be loose against mocap noise, so the last moments
    of the board's approach can pass it and bias the mean. A sample further from the median
    than 3x the median distance (about 4.6 sigma of isotropic noise; at least 0.5 mm and
    0.05 deg) is settling; the tail starts at the first of three consecutive samples that are
    not. Only a leading stretch is dropped: the samples used are exactly those of the reported
    window, so anyone can average the same samples (a noisy sample later on stays, as any
    mocap sample of a still board).
    """
    from scipy.spatial.transform import Rotation  # lazy: scipy, 300 ms

    if len(tail) < 5:
        return tail
    med = np.median(tail.xyz, axis=0)
    dist = np.linalg.norm(tail.xyz - med, axis=1)
    rot = Rotation.from_quat(tail.quat_xyzw)
    ang = (rot.mean().inv() * rot).magnitude()
    ok = (dist <= max(3.0 * float(np.median(dist)), 5e-4)) & (
        ang <= max(3.0 * float(np.median(ang)), math.radians(0.05))
    )
    three = ok[:-2] & ok[1:-1] & ok[2:]
    if not three.any():
        return tail
    start = int(np.argmax(three))
    return tail.take(slice(start, None)) if len(tail) - start >= 3 else tail


def lookup_at(
    origin: PoseStream, board: PoseStream, at_ns: int, max_gap_ns: int, t0_ns: int = 0
) -> PoseStream:
    """T_origin_board at ``at_ns`` as tf's lookup gave it: both bodies interpolated there.

    tf interpolates each link between the samples around the moment (translation linearly,
    rotation by slerp) and waits for a sample past it: a body not seen within ``max_gap_ns``
    on either side is lost (the node's lookup raised and it stopped).

    Raises:
        GroundTruthError: a body not tracked around ``at_ns``.
    """
    at = np.array([at_ns], dtype=np.int64)
    poses = []
    for stream, name in (
        (drop_invalid(origin)[0], "origin"),
        (drop_invalid(board)[0], "ref_board"),
    ):
        if len(stream) == 0:
            raise GroundTruthError(f"no {name} pose in the log")
        got = interpolate_poses(stream, at, "linear")
        if not bool(got.inside[0]) or int(got.gap_ns[0]) > max_gap_ns:
            problem = tracked_problem(stream, name, at_ns, max_gap_ns, t0_ns)
            raise GroundTruthError(
                problem or f"{name} not tracked on both sides of {_s(at_ns - t0_ns)}"
            )
        poses.append(got)
    o, b = poses
    inv_t, inv_q = invert(o.xyz, o.quat_xyzw)
    xyz, quat = compose(inv_t, inv_q, b.xyz, b.quat_xyzw)
    return PoseStream(at, xyz, quat, "origin", "ref_board", board.source)


def measure_ground_truth(
    origin: PoseStream,
    board: PoseStream,
    item: Item,
    *,
    search_start_ns: int,
    goal_ns: int,
    result_ns: int | None,
    options: GtOptions,
    t0_ns: int = 0,
    placed_ns: int | None = None,
    at_ns: int | None = None,
) -> tuple[GroundTruth, list[str]]:
    """The item's ground truth for one run, and warnings.

    Args:
        origin: T_world_origin samples.
        board: T_world_board samples.
        item: the presented item (with its transform).
        search_start_ns: earliest time the board may stand in its final place (the referee was
            asked to place the item).
        goal_ns: the goal was sent.
        result_ns: the result came back (``result`` method only).
        options: method and tolerances.
        t0_ns: times in messages are given relative to this (the log's start).
        placed_ns: the referee confirmed the placement (``placed``; the goal when None).
        at_ns: the lookup's moment when known better than the state messages (the stamp of the
            node's item broadcast on /tf); ignored by ``window``.

    Raises:
        GroundTruthError: a body missing or lost where the measurement needs it.
    """
    max_gap = round(options.max_gap_s * NS_PER_S)
    warnings: list[str] = []
    moment = ""
    if options.method != "window":
        if at_ns is not None:
            at, moment = at_ns, "item tf stamp"
        elif options.method == "result":
            if result_ns is None:
                raise GroundTruthError("no result time for the 2015 lookup when the result came")
            at, moment = result_ns, "state message"
        else:
            moment = "state message"
            at = placed_ns if options.method == "placed" and placed_ns is not None else goal_ns
        used = lookup_at(
            origin.window(at - max_gap, at + max_gap),
            board.window(at - max_gap, at + max_gap),
            at,
            max_gap,
            t0_ns,
        )
    else:
        start = max(search_start_ns, goal_ns - round(options.max_window_s * NS_PER_S))
        end = goal_ns
        for stream, name in ((origin, "origin"), (board, "ref_board")):
            # Both bodies must be seen at the goal; before it the stationary tail stops at gaps.
            problem = tracked_problem(stream, name, goal_ns, max_gap, t0_ns)
            if problem:
                raise GroundTruthError(problem)
        rel = board_in_table(
            origin.window(start - max_gap, end + max_gap), board.window(start, end), max_gap
        )
        if len(rel) == 0:
            raise GroundTruthError(
                f"no ref_board sample with a known origin in {_s(start - t0_ns)}..{_s(end - t0_ns)}"
            )
        used = settled(stationary_tail(rel, options.still_m, options.still_deg, max_gap))
        span = (used.end_ns - used.start_ns) / NS_PER_S
        if span < options.min_still_s:
            warnings.append(
                f"board still for only {span:.2f} s before the goal "
                f"({len(used)} sample(s) averaged; moved more than {options.still_m * 1000:g} mm "
                f"or {options.still_deg:g} deg before)"
            )
    t_item, q_item = _item_poses(used, item)
    mean = mean_pose(t_item, q_item)
    board_mean = used.xyz.mean(axis=0)
    q = mean.quat_xyzw
    gt = GroundTruth(
        x=float(mean.xyz[0]),
        y=float(mean.xyz[1]),
        z=float(mean.xyz[2]),
        yaw=float(yaw_from_quat(q)),
        quat_xyzw=(float(q[0]), float(q[1]), float(q[2]), float(q[3])),
        board_xy=(float(board_mean[0]), float(board_mean[1])),
        position_spread_m=mean.position_std,
        angle_spread_deg=math.degrees(mean.angle_std),
        samples=mean.count,
        start_ns=used.start_ns,
        end_ns=used.end_ns,
        method=options.method,
        moment=moment,
    )
    return gt, warnings


def board_motion(
    origin: PoseStream,
    board: PoseStream,
    board_xy: tuple[float, float],
    start_ns: int,
    end_ns: int,
    max_gap_ns: int,
) -> float | None:
    """Largest distance (m, in the table plane) of the board from ``board_xy`` in a window.

    Used to warn when the board was moved while the robot was looking at it; None when the
    bodies were not tracked then.
    """
    rel = board_in_table(
        origin.window(start_ns - max_gap_ns, end_ns + max_gap_ns),
        board.window(start_ns, end_ns),
        max_gap_ns,
    )
    if len(rel) == 0:
        return None
    return float(np.hypot(rel.xyz[:, 0] - board_xy[0], rel.xyz[:, 1] - board_xy[1]).max())
