"""FBM2@Home: when did each segment start and when was its waypoint reached.

Three sources, one result (:class:`ReachedMoments`):

- ``states``: the BmBox/Client/RefBox state topics. The 2015 node took
  ``start_segment_time`` right after ``SendGoal()`` returned (its BmBox out of
  TRANSMITTING_GOAL) and ``end_segment_time`` when ``WaitResult()`` returned (out of
  WAITING_RESULT, once the Client's COMPLETED_GOAL, or the RefBox's ``reason: timeout`` /
  ``reason: stop``, had arrived): the ``bmbox`` clock times segments between those BmBox
  messages, the default ``client`` clock ends them at the Client's report itself. A log that
  ends inside the benchmark is the benchmark stopped there. RefBox END payloads are read by
  :func:`ertools.states.end_reason` (by default the seed's ``timeout`` / ``halt`` too, under
  ``--exact-end-payloads`` only the 2015 BmBox's strings); any other is warned about once, with
  its file and time, and is neither a timeout nor a stop.
- ``timing``: a reached-waypoint timing file (``p0`` starts the run, ``p(k+1)`` closes
  segment ``k``).
- ``auto``: stops detected in the ground truth (speed and yaw rate under thresholds for a
  minimum time), assigned to the waypoints in order.
"""

from __future__ import annotations

from dataclasses import field, replace

import numpy as np
import numpy.typing as npt

from ertools.arrays import F64, I64
from ertools.benchmarks.common import motion
from ertools.benchmarks.common.ending import end_payload_deviation, end_payload_warnings
from ertools.benchmarks.fbm2h.config import StopParams
from ertools.errors import SegmentationError
from ertools.fidelity import Deviation
from ertools.frozen_dataclass import frozen_dataclass
from ertools.states import BmBoxState, ClientState, EndReason, RefBoxState, end_reason
from ertools.streams import StateStream
from ertools.timeutil import ns_to_s

CLOCKS = ("client", "bmbox")

# An :class:`EarlyEnd` kind per RefBox END reading (a NONE or UNKNOWN payload: ``ended``).
_KINDS = {EndReason.TIMEOUT: "timeout", EndReason.STOP: "stop"}


@frozen_dataclass
class EarlyEnd:
    """Why the benchmark stopped before segment ``segment`` was completed.

    Attributes:
        segment: the first segment not completed.
        start_ns: when it started (None when its goal was never sent).
        end_ns: when it ended: the RefBox END (``client`` clock) or the BmBox leaving
            WAITING_RESULT (``bmbox`` clock); for a ``cut`` the log's last BmBox message, the
            stop the cut stands for (None when the segment had not started).
        kind: ``timeout`` or ``stop`` (the RefBox ended it), ``ended`` (a RefBox END whose
            payload says neither, or a score sent early) or ``cut`` (the log ends inside the
            benchmark: taken as the benchmark stopped there, as a stop is).
        payload: the RefBox payload then ("" when none).
    """

    segment: int
    start_ns: int | None
    end_ns: int | None
    kind: str
    payload: str = ""

    @property
    def is_timeout(self) -> bool:
        return self.kind == "timeout"

    @property
    def reason(self) -> str:
        """What ended the benchmark, for the messages."""
        if self.kind == "cut":
            return "the log ends inside the benchmark: taken as the benchmark stopped there"
        if self.payload.strip():
            return f"RefBox END ({self.payload.strip()})"
        return "the benchmark ended without a RefBox reason"


@frozen_dataclass(eq=False)
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
        early_end: states only: why segment K (the first not completed) was not, when the
            benchmark stopped before its goals ran out (None for timing and auto).
        clock: states only: ``client`` or ``bmbox`` (see :func:`from_states`).
        warnings: states only: RefBox END payloads of no known form (file and time).
        deviations: states only: seed END payloads the default read unlike the 2015 BmBox.
    """

    method: str
    start_ns: I64
    end_ns: I64
    payloads: tuple[str, ...]
    goal_payload: str | None = None
    unreached: tuple[str, ...] = ()
    notes: tuple[str, ...] = field(default_factory=tuple)
    early_end: EarlyEnd | None = None
    clock: str = "client"
    warnings: tuple[str, ...] = ()
    deviations: tuple[Deviation, ...] = ()

    def __len__(self) -> int:
        return int(self.end_ns.shape[0])


def _first_at_or_after(t: I64, mask: npt.NDArray[np.bool_], t0: int, t1: int | None) -> int | None:
    """Index of the first message with ``mask`` in [t0, t1), or None."""
    hit = mask & (t >= t0)
    if t1 is not None:
        hit &= t < t1
    idx = np.flatnonzero(hit)
    return int(idx[0]) if idx.size else None


def end_kind(payload: str, *, exact_2015: bool = False) -> str:
    """``timeout`` or ``stop`` when a RefBox payload says so (:func:`ertools.states.end_reason`,
    compared whole, never by its words), else ``""``. The 2015 BmBox's ``Timeout()`` and
    ``Running()`` compared the last RefBox payload whatever its state, and so does the
    ``bmbox`` clock."""
    return _KINDS.get(end_reason(payload, exact_2015=exact_2015), "")


def _payload_at(stream: StateStream | None, t_ns: int) -> str:
    """The payload of the last message of ``stream`` recorded at or before ``t_ns``: what the
    2015 BmBox held in ``_refbox_payload`` / ``_client_payload`` then."""
    if stream is None or len(stream) == 0:
        return ""
    i = int(np.searchsorted(stream.t_ns, t_ns, side="right")) - 1
    return stream.payload[i] if i >= 0 else ""


_WAITING = (BmBoxState.EXECUTING_GOAL, BmBoxState.WAITING_RESULT)


def _bmbox_window(
    bm: StateStream, t_goal: int, t_next: int | None
) -> tuple[int | None, int | None]:
    """(start, end) message indices of a segment on the node's own clock.

    ``start``: the first BmBox message no longer TRANSMITTING_GOAL (``SendGoal()`` had
    returned: 2015 read ``time.time()`` then); ``end``: the first after it that is neither
    EXECUTING_GOAL nor WAITING_RESULT (``WaitResult()`` had returned), or ``start`` itself when
    the BmBox was already out of them (``WaitResult()`` then returns at once). None: the log
    ends (or the next goal comes) first.
    """
    i_start = _first_at_or_after(bm.t_ns, bm.state != BmBoxState.TRANSMITTING_GOAL, t_goal, t_next)
    if i_start is None:
        return None, None
    if int(bm.state[i_start]) not in _WAITING:
        return i_start, i_start
    waiting = np.isin(bm.state, np.asarray(_WAITING, dtype=bm.state.dtype))
    i_end = _first_at_or_after(bm.t_ns, ~waiting, int(bm.t_ns[i_start]), t_next)
    return i_start, i_end


def from_states(
    bmbox: StateStream,
    client: StateStream | None,
    refbox: StateStream | None = None,
    *,
    clock: str = "client",
    exact_2015: bool = False,
    t0_ns: int | None = None,
) -> ReachedMoments:
    """Segments from the state topics (BmBox required, Client preferred for the end moment).

    ``clock`` ``client`` (the default): a segment runs from the BmBox EXECUTING_GOAL (else its
    first message past TRANSMITTING_GOAL) to the Client's COMPLETED_GOAL, the moment the robot
    said it had arrived; with no Client topic, to the BmBox leaving WAITING_RESULT. A RefBox
    END before that ends the benchmark there. ``bmbox`` (the 2015 node): from the first BmBox
    message past TRANSMITTING_GOAL to the first past WAITING_RESULT, the node's own transitions,
    and the segment counts as completed unless the RefBox payload then was the node's exact
    ``reason: timeout`` or ``reason: stop`` (by default the seed's ``timeout`` / ``halt`` too;
    ``exact_2015``: the 2015 strings alone, :func:`ertools.states.end_reason`). ``t0_ns``: the
    log's first message, from which the warnings count time (default: the first BmBox message).

    A log that ends inside the benchmark (a segment started and never ended, or fewer goals
    than waypoints and no score sent) is the benchmark stopped there: ``early_end`` of kind
    ``cut``.

    Raises:
        SegmentationError: no BmBox message, a segment the Client never completed that the
            BmBox left for the next goal anyway (an inconsistent log), or an unknown ``clock``.
    """
    if clock not in CLOCKS:
        raise SegmentationError(f"segment clock must be client or bmbox, not {clock!r}")
    bm = bmbox.changes()
    if len(bm) == 0:
        raise SegmentationError(
            f"{bm.topic}: no BmBox state message, no segment to score; "
            "use --reached timing FILE or --reached auto",
            path=bm.source or None,
        )
    goals = np.flatnonzero(bm.state == BmBoxState.TRANSMITTING_GOAL)
    cl = client.changes() if client is not None and len(client) else None
    rb = refbox.changes() if refbox is not None and len(refbox) else None
    t0 = int(bmbox.t_ns[0]) if t0_ns is None else t0_ns
    warnings = tuple(end_payload_warnings(refbox, t0, exact_2015=exact_2015))
    said = end_payload_deviation(refbox, t0, exact_2015=exact_2015)
    starts: list[int] = []
    ends: list[int] = []
    payloads: list[str] = []
    notes: list[str] = []
    early: EarlyEnd | None = None
    goal_payload = bm.payload[int(goals[0])] or None if goals.size else None
    t_goals = bm.t_ns[goals]
    for k, g in enumerate(goals):
        t_goal = int(bm.t_ns[g])
        t_next = int(t_goals[k + 1]) if k + 1 < len(goals) else None
        if clock == "bmbox":
            found = _segment_bmbox(bm, cl, rb, k, t_goal, t_next, exact_2015)
        else:
            found = _segment_client(bm, cl, rb, k, t_goal, t_next, exact_2015)
        if isinstance(found, EarlyEnd):
            early = found
            notes.append(f"segment {k}: not completed ({found.reason})")
            break
        t_start, t_end, payload, note = found
        if note:
            notes.append(note)
        starts.append(t_start)
        ends.append(t_end)
        payloads.append(payload)
    else:
        early = _after_last_goal(bm, rb, len(goals), exact_2015)
        if early is not None:
            after = f"after segment {len(goals) - 1}" if len(goals) else "at all"
            notes.append(f"no goal sent {after} ({early.reason})")
    if early is not None and early.kind == "cut" and early.start_ns is not None:
        # Stopped at the log's last BmBox message: where the 2015 node's wait returned.
        early = replace(early, end_ns=max(early.start_ns, int(bmbox.t_ns[-1])))
    return ReachedMoments(
        "states",
        np.asarray(starts, dtype=np.int64),
        np.asarray(ends, dtype=np.int64),
        tuple(payloads),
        goal_payload=goal_payload,
        notes=tuple(notes),
        early_end=early,
        clock=clock,
        warnings=warnings,
        deviations=() if said is None else (said,),
    )


_Found = tuple[int, int, str, str] | EarlyEnd  # (start, end, result payload, note) or why not


def _segment_bmbox(
    bm: StateStream,
    cl: StateStream | None,
    rb: StateStream | None,
    k: int,
    t_goal: int,
    t_next: int | None,
    exact_2015: bool,
) -> _Found:
    i_start, i_end = _bmbox_window(bm, t_goal, t_next)
    if i_start is None:
        return EarlyEnd(k, None, None, "cut", _payload_at(rb, int(bm.t_ns[-1])))
    t_start = int(bm.t_ns[i_start])
    if i_end is None:
        return EarlyEnd(k, t_start, None, "cut", _payload_at(rb, int(bm.t_ns[-1])))
    t_end = int(bm.t_ns[i_end])
    refbox_payload = _payload_at(rb, t_end)
    kind = end_kind(refbox_payload, exact_2015=exact_2015)
    if kind:
        return EarlyEnd(k, t_start, t_end, kind, refbox_payload)
    if int(bm.state[i_end]) != BmBoxState.READY:
        # Not a result (the BmBox went to END or sent its score): the node stopped here.
        return EarlyEnd(k, t_start, t_end, "ended", refbox_payload)
    return t_start, t_end, _payload_at(cl, t_end), ""


def _segment_client(
    bm: StateStream,
    cl: StateStream | None,
    rb: StateStream | None,
    k: int,
    t_goal: int,
    t_next: int | None,
    exact_2015: bool,
) -> _Found:
    i_exec = _first_at_or_after(bm.t_ns, bm.state == BmBoxState.EXECUTING_GOAL, t_goal, t_next)
    i_start, i_bm_end = _bmbox_window(bm, t_goal, t_next)
    if i_exec is None:
        i_exec = i_start
    if i_exec is None:
        # Never executed: a RefBox END after the goal ended it, else the log ends first.
        i_rb0 = (
            None
            if rb is None
            else _first_at_or_after(rb.t_ns, rb.state == RefBoxState.END, t_goal, t_next)
        )
        if rb is not None and i_rb0 is not None:
            payload = rb.payload[i_rb0]
            kind = end_kind(payload, exact_2015=exact_2015) or "ended"
            return EarlyEnd(k, None, int(rb.t_ns[i_rb0]), kind, payload)
        return EarlyEnd(k, None, None, "cut")
    t_start = int(bm.t_ns[i_exec])
    # A RefBox timeout or stop once the goal is sent ends the segment, whatever comes after it
    # (the robot arriving late). Another END is neither (as to the 2015 BmBox): the segment
    # waits on for the robot's report, and ends there only if none comes.
    i_rb = i_any = None
    if rb is not None:
        is_end = rb.state == RefBoxState.END
        early = np.fromiter(
            (bool(end_kind(p, exact_2015=exact_2015)) for p in rb.payload), bool, len(rb)
        )
        i_rb = _first_at_or_after(rb.t_ns, is_end & early, t_goal, t_next)
        i_any = _first_at_or_after(rb.t_ns, is_end, t_goal, t_next)
    t_rb = None if i_rb is None or rb is None else int(rb.t_ns[i_rb])
    if cl is not None:
        i_done = _first_at_or_after(cl.t_ns, cl.state == ClientState.COMPLETED_GOAL, t_start, t_rb)
        if i_done is not None and (t_next is None or int(cl.t_ns[i_done]) < t_next):
            return t_start, int(cl.t_ns[i_done]), cl.payload[i_done], ""
    elif i_bm_end is not None and int(bm.state[i_bm_end]) == BmBoxState.READY:
        t_end = int(bm.t_ns[i_bm_end])
        if t_rb is None or t_end < t_rb:
            return t_start, t_end, "", f"segment {k}: end from BmBox READY (no Client topic)"
    i_end = i_rb if i_rb is not None else i_any
    if rb is not None and i_end is not None:
        payload, t_end = rb.payload[i_end], int(rb.t_ns[i_end])
        kind = end_kind(payload, exact_2015=exact_2015) or "ended"
        # An END while the goal was still being sent leaves the segment no time of its own.
        return EarlyEnd(k, min(t_start, t_end), t_end, kind, payload)
    if t_next is not None:
        raise SegmentationError(
            f"{bm.topic}: segment {k} was never completed, the RefBox did not end it, and the "
            "BmBox sent the next goal anyway; the log is inconsistent (messages missing?)",
            path=bm.source or None,
        )
    return EarlyEnd(k, t_start, None, "cut")


def _after_last_goal(
    bm: StateStream, rb: StateStream | None, k: int, exact_2015: bool
) -> EarlyEnd | None:
    """Why no goal followed the last completed segment ``k - 1`` (None: a normal end, i.e.
    the BmBox sent its score with no RefBox reason; the waypoint count then decides)."""
    t_last = int(bm.t_ns[-1])
    i_rb = (
        None
        if rb is None
        else _first_at_or_after(rb.t_ns, rb.state == RefBoxState.END, int(bm.t_ns[0]), None)
    )
    score = np.flatnonzero(bm.state == BmBoxState.TRANSMITTING_SCORE)
    t_score = int(bm.t_ns[score[0]]) if score.size else None
    if rb is not None and i_rb is not None:
        payload = rb.payload[i_rb]
        kind = end_kind(payload, exact_2015=exact_2015)
        if kind and (t_score is None or int(rb.t_ns[i_rb]) <= t_score):
            return EarlyEnd(k, None, int(rb.t_ns[i_rb]), kind, payload)
    if t_score is None:
        return EarlyEnd(k, None, None, "cut", _payload_at(rb, t_last))
    return None


def unreached_reasons(
    moments: ReachedMoments, n_waypoints: int, refbox: StateStream | None = None
) -> tuple[str, ...]:
    """Why the segments after the last completed one have no reached moment.

    Empty when every waypoint was reached, or when nothing says why (not from the states, or
    the BmBox sent its score early with no RefBox reason): the count mismatch is then an error
    (see :func:`ertools.benchmarks.fbm2h.pipeline.compute`). ``refbox`` is not needed any
    more (the reason is found with the moments) and kept for callers.
    """
    del refbox
    k = len(moments)
    early = moments.early_end
    if k >= n_waypoints or early is None:
        return ()
    out = [f"segment {k}: not completed ({early.reason})" if early.start_ns is not None else ""]
    if not out[0]:
        out = []
    first = k + len(out)
    out += [
        f"segment {i}: waypoint never reached ({early.reason})" for i in range(first, n_waypoints)
    ]
    return tuple(out)


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
