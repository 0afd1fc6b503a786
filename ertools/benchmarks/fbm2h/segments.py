"""FBM2@Home: when did each segment start and when was its waypoint reached.

Three sources, one result (:class:`ReachedMoments`):

- ``states``: the BmBox/Client state topics, as the 2015 node ran. The node took
  ``start_segment_time`` right after ``SendGoal()`` returned (the BmBox in EXECUTING_GOAL) and
  ``end_segment_time`` when ``WaitResult()`` returned (the Client's COMPLETED_GOAL).
- ``timing``: a reached-waypoint timing file (``p0`` starts the run, ``p(k+1)`` closes
  segment ``k``).
- ``auto``: stops detected in the ground truth (speed and yaw rate under thresholds for a
  minimum time), assigned to the waypoints in order.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import numpy.typing as npt

from ertools.arrays import F64, I64
from ertools.benchmarks.common import motion
from ertools.errors import SegmentationError
from ertools.states import BmBoxState, ClientState, RefBoxState
from ertools.streams import StateStream
from ertools.timeutil import ns_to_s


@dataclass(frozen=True)
class EarlyEnd:
    """A segment the RefBox ended: started at ``start_ns``, ended by END at ``end_ns``.

    Attributes:
        segment: the segment's index.
        start_ns: when its goal had been sent (the BmBox in EXECUTING_GOAL).
        end_ns: the RefBox END message.
        payload: END's payload (``timeout``, ``halt``...).
    """

    segment: int
    start_ns: int
    end_ns: int
    payload: str

    @property
    def is_timeout(self) -> bool:
        return "timeout" in self.payload.lower()


@dataclass(frozen=True, eq=False)
class ReachedMoments:
    """Start and reached (end) time of each segment that was driven.

    Attributes:
        method: ``states``, ``timing`` or ``auto``.
        start_ns: (K,) segment starts.
        end_ns: (K,) moments the waypoint was reached (the pose is taken here).
        payloads: K result payloads (the Client's COMPLETED_GOAL payload, "" otherwise).
        goal_payload: the goal list sent with the first goal (states only), or None.
        unreached: reasons for the segments after the K-th that were never completed (the
            RefBox ended the benchmark early); empty when all were reached.
        notes: what was detected, for the referee.
        early_end: the segment that was started and never completed because the RefBox ended
            the benchmark (states only), None otherwise.
    """

    method: str
    start_ns: I64
    end_ns: I64
    payloads: tuple[str, ...]
    goal_payload: str | None = None
    unreached: tuple[str, ...] = ()
    notes: tuple[str, ...] = field(default_factory=tuple)
    early_end: EarlyEnd | None = None

    def __len__(self) -> int:
        return int(self.end_ns.shape[0])


def _first_at_or_after(t: I64, mask: npt.NDArray[np.bool_], t0: int, t1: int | None) -> int | None:
    """Index of the first message with ``mask`` in [t0, t1), or None."""
    hit = mask & (t >= t0)
    if t1 is not None:
        hit &= t < t1
    idx = np.flatnonzero(hit)
    return int(idx[0]) if idx.size else None


def from_states(
    bmbox: StateStream,
    client: StateStream | None,
    refbox: StateStream | None = None,
) -> ReachedMoments:
    """Segments from the state topics (BmBox required, Client preferred for the end moment)."""

    bm = bmbox.changes()
    goals = np.flatnonzero(bm.state == BmBoxState.TRANSMITTING_GOAL)
    if goals.size == 0:
        raise SegmentationError(
            f"{bm.topic}: the BmBox never entered TRANSMITTING_GOAL, no segment to score; "
            "use --reached timing FILE or --reached auto",
            path=bm.source or None,
        )
    cl = client.changes() if client is not None and len(client) else None
    starts: list[int] = []
    ends: list[int] = []
    payloads: list[str] = []
    notes: list[str] = []
    early: EarlyEnd | None = None
    goal_payload = bm.payload[int(goals[0])] or None
    t_goals = bm.t_ns[goals]
    for k, g in enumerate(goals):
        t_goal = int(bm.t_ns[g])
        t_next = int(t_goals[k + 1]) if k + 1 < len(goals) else None
        i_exec = _first_at_or_after(bm.t_ns, bm.state == BmBoxState.EXECUTING_GOAL, t_goal, t_next)
        # 2015 read time.time() when SendGoal() returned, i.e. once the BmBox was executing.
        t_start = int(bm.t_ns[i_exec]) if i_exec is not None else t_goal
        t_end: int | None = None
        payload = ""
        if cl is not None:
            i_done = _first_at_or_after(
                cl.t_ns, cl.state == ClientState.COMPLETED_GOAL, t_start, t_next
            )
            if i_done is not None:
                t_end = int(cl.t_ns[i_done])
                payload = cl.payload[i_done]
        if t_end is None:
            # No Client topic: the BmBox leaving WAITING_RESULT for READY is WaitResult returning.
            i_wait = _first_at_or_after(
                bm.t_ns, bm.state == BmBoxState.WAITING_RESULT, t_start, t_next
            )
            i_ready = (
                _first_at_or_after(
                    bm.t_ns, bm.state == BmBoxState.READY, int(bm.t_ns[i_wait]), t_next
                )
                if i_wait is not None
                else None
            )
            if i_ready is not None:
                t_end = int(bm.t_ns[i_ready])
                if cl is None:
                    notes.append(f"segment {k}: end from BmBox READY (no Client topic)")
        if t_end is None:
            end = _early_end(refbox, t_start)
            reason = None if end is None else f"RefBox END ({end[1]})"
            if end is not None:
                early = EarlyEnd(k, t_start, end[0], end[1])
            if reason is None:
                raise SegmentationError(
                    f"{bm.topic}: segment {k} (goal sent at "
                    f"{ns_to_s(t_goal - int(bm.t_ns[0])):.3f} s) was never completed and the "
                    "RefBox did not end the benchmark; the log may be truncated",
                    path=bm.source or None,
                )
            notes.append(f"segment {k}: not completed ({reason})")
            break
        starts.append(t_start)
        ends.append(t_end)
        payloads.append(payload)
    return ReachedMoments(
        "states",
        np.asarray(starts, dtype=np.int64),
        np.asarray(ends, dtype=np.int64),
        tuple(payloads),
        goal_payload=goal_payload,
        notes=tuple(notes),
        early_end=early,
    )


def _early_end(refbox: StateStream | None, after_ns: int) -> tuple[int, str] | None:
    """(time, payload) of the RefBox END that ended the benchmark early, if any."""

    if refbox is None or len(refbox) == 0:
        return None
    rb = refbox.changes()
    i = _first_at_or_after(rb.t_ns, rb.state == RefBoxState.END, after_ns, None)
    if i is None:
        return None
    payload = rb.payload[i].strip()
    # A normal END (after the score) has no payload; timeout/halt end the benchmark early.
    if not any(word in payload.lower() for word in ("timeout", "halt", "stop", "abort")):
        return None
    return int(rb.t_ns[i]), payload


def _early_end_reason(refbox: StateStream | None, after_ns: int) -> str | None:
    """``RefBox END (timeout)`` and the like, when the RefBox ended the benchmark early."""
    end = _early_end(refbox, after_ns)
    return None if end is None else f"RefBox END ({end[1]})"


def unreached_reasons(
    moments: ReachedMoments, n_waypoints: int, refbox: StateStream | None
) -> tuple[str, ...]:
    """Why the segments after the last completed one have no reached moment."""
    if len(moments) >= n_waypoints:
        return ()
    after = int(moments.end_ns[-1]) if len(moments) else 0
    reason = _early_end_reason(refbox, after)
    if reason is None:
        return ()  # not an early end: the count mismatch is an error (see compute)
    return tuple(
        f"segment {k}: waypoint never reached ({reason})" for k in range(len(moments), n_waypoints)
    )


def from_timing(t_ns: I64, labels: tuple[str, ...]) -> ReachedMoments:
    """Segments from resolved timing-file moments: segment k runs from t[k] to t[k+1]."""
    t = np.asarray(t_ns, dtype=np.int64)
    return ReachedMoments(
        "timing",
        t[:-1].copy(),
        t[1:].copy(),
        tuple("" for _ in range(len(t) - 1)),
        notes=tuple(f"{labels[k + 1]} closes segment {k}" for k in range(len(t) - 1)),
    )


@dataclass(frozen=True)
class StopParams:
    """Thresholds of the ``auto`` stop detector.

    Attributes:
        speed: m/s; the robot counts as stopped below it (mocap jitter on a still marker set
            gives ~1 mm over the window, i.e. a few mm/s; the 2015 test robot crept at a few
            cm/s while "standing" at its waypoints).
        yaw_rate: rad/s; also required, so a robot turning on the spot is not "stopped".
        min_duration_s: a stop lasts at least this long (the 2015 robot paused 0.7 to 3 s).
        window_s: speeds are displacements over this window (per-sample differences of 120 Hz
            mocap are dominated by jitter).
        radius: metres; a stop is assigned to a waypoint only if it lies this close to it.
    """

    speed: float = 0.05
    yaw_rate: float = 0.1
    min_duration_s: float = 0.5
    window_s: float = 0.5
    radius: float = 0.5


def detect_stops(
    t_ns: I64, xy: F64, yaw: F64, params: StopParams, max_gap_ns: int
) -> list[tuple[int, int]]:
    """(first, last) sample index of every stationary run lasting >= ``min_duration_s``."""

    still = motion.still_mask(
        t_ns, xy, window_s=params.window_s, speed=params.speed, yaw=yaw, yaw_rate=params.yaw_rate
    )
    # A tracking gap breaks a run: nothing is known about the robot in between.
    return motion.still_runs(
        t_ns, still, min_duration_ns=int(params.min_duration_s * 1e9), max_gap_ns=max_gap_ns
    )


def from_stops(
    stream_t_ns: I64,
    xy: F64,
    yaw: F64,
    waypoints_xy: F64,
    params: StopParams,
    max_gap_ns: int,
    origin_ns: int | None = None,
) -> tuple[ReachedMoments, tuple[str, ...]]:
    """Assign detected stops to waypoints in order; returns moments and unassigned waypoints.

    Waypoint k takes the first stop after the one given to waypoint k-1 that lies within
    ``radius`` of it; the reached moment is one speed window after that stop began.
    Segment 0 starts when the
    robot first moves (the end of an initial stop) or at the first sample. The notes count
    time from ``origin_ns`` (the log's first message, as the score's table), else from the
    first pose.
    """
    runs = detect_stops(stream_t_ns, xy, yaw, params, max_gap_ns)
    t0 = int(stream_t_ns[0]) if origin_ns is None else origin_ns
    since = "from the first pose" if origin_ns is None else "from the log's first message"
    notes = [
        f"stop {i} ({since}): {ns_to_s(int(stream_t_ns[s]) - t0):.3f} s to "
        f"{ns_to_s(int(stream_t_ns[e]) - t0):.3f} s at "
        f"({xy[s : e + 1, 0].mean():.3f}, {xy[s : e + 1, 1].mean():.3f})"
        for i, (s, e) in enumerate(runs)
    ]
    t_first = int(stream_t_ns[0])
    t_start0 = t_first
    next_run = 0
    if runs and runs[0][0] == 0:
        t_start0 = int(stream_t_ns[runs[0][1]])
        next_run = 1
    ends: list[int] = []
    missing: list[str] = []
    for k, wp in enumerate(waypoints_xy):
        chosen = None
        for j in range(next_run, len(runs)):
            s, e = runs[j]
            centre = xy[s : e + 1].mean(axis=0)
            if float(np.hypot(*(centre - wp))) <= params.radius:
                chosen = j
                break
        if chosen is None:
            missing.append(
                f"segment {k}: no stop of >= {params.min_duration_s} s within "
                f"{params.radius} m of waypoint {k} after the previous waypoint"
            )
            break
        # The first still sample's window is centred on it, so the robot may still creep (by
        # less than speed * window) during the next half window: one full window later it is
        # at rest, which is also when a Client would report the waypoint reached.
        s, e = runs[chosen]
        ends.append(min(int(stream_t_ns[s]) + int(params.window_s * 1e9), int(stream_t_ns[e])))
        next_run = chosen + 1
    end_arr = np.asarray(ends, dtype=np.int64)
    start_arr = np.concatenate([[t_start0], end_arr[:-1]]).astype(np.int64)[: len(end_arr)]
    moments = ReachedMoments(
        "auto", start_arr, end_arr, tuple("" for _ in ends), notes=tuple(notes)
    )
    if not runs:
        raise SegmentationError(
            f"no stop of >= {params.min_duration_s} s (speed < {params.speed} m/s, yaw rate < "
            f"{params.yaw_rate} rad/s) found in the ground truth; use --reached timing FILE"
        )
    return moments, tuple(missing)
