"""The 2015 FBM2@Home node, ported line by line for the tests, replayed over a log.

Sources (read through the search tool; the port follows their control flow, not ertools'):

- ``scripts/fbm2h`` of rockin-robot-challenge/benchmark_and_scoring_fbm, commit ``0852153``
  (the later of the two 2015 versions stored; ``198dbed`` has the same loop): ``N`` and ``i``
  (l. 44-45), ``benchmark.WaitClient()`` (l. 88), ``while benchmark.Running() and not
  benchmark.Timeout() and i <= N`` (l. 91), ``SendGoal`` (l. 94-97), ``start_segment_time =
  time.time()`` (l. 102), ``WaitResult()`` (l. 106), ``end_segment_time = time.time()`` and
  ``segment_time`` (l. 115-116), the tf lookup of ``/world -> /robot_at_home`` (l. 158), ``if
  benchmark.Timeout(): execution_time = execution_time + segment_time; continue`` (l. 171-175),
  ``if not benchmark.Running(): continue`` (l. 178-181), the errors and sums (l. 206-218), ``i =
  i + 1`` (l. 222), ``position_accuracy = sum_d / N`` and ``orientation_accuracy =
  atan2(sum_sin, sum_cos)`` (l. 226-227).
- ``src/rockin_scoring/BmBox.py`` (svenschneider/benchmark_and_scoring_fbm, commit ``90d5c4d``):
  the RefBox callback moving the BmBox to READY on ``reason: timeout`` (in EXECUTING_GOAL or
  WAITING_RESULT, l. 49-51) and on ``reason: stop`` (any state but TRANSMITTING_SCORE,
  l. 53-55), the Client's COMPLETED_GOAL doing so in WAITING_RESULT (l. 28-29);
  ``WaitClient`` (l. 58-65), ``SendGoal`` (l. 77-86: returns unless READY or
  COMPLETED_MANUAL_OPERATION, else TRANSMITTING_GOAL and waits), ``WaitResult`` (l. 89-103:
  returns at once unless EXECUTING_GOAL, else WAITING_RESULT and waits for any change, returns
  the Client's payload), ``Timeout()`` (l. 114-117: ``_refbox_payload == "reason: timeout"``)
  and ``Running()`` (l. 125-126: ``_refbox_payload != "reason: stop"``).

What the final 2015 version changed (Listing 13 of the seed: segments numbered from 0 to N-1,
N the number of waypoints of the goal list; the pose through the team's
``marker_to_robot_transform``, tf at the moment the result was handled; ``timeout_segments:
0`` and ``timeout: false`` "always", ``timeout_time`` "not used in the benchmark" in Listing 10)
is followed here: no ``segment_time > timeout_time`` rule, no ``result != i`` check (the final
Client payload is ``waypoint: k``, not ``int``).

The replay: the node's state is what its BmBox published (the recorded BmBox messages, in
record order with the RefBox's and the Client's); a wait returns when the BmBox message that
ends it is read, and ``time.time()`` right after is that message's record time (the log's
clock; the node's own clock is not in the log). ``_refbox_payload`` and ``_client_payload``
are the payloads of the last RefBox and Client messages read. The log ending inside a wait is
the benchmark stopped there (the RefBox's ``reason: stop``: the BmBox back to READY).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from scipy.spatial.transform import Rotation, Slerp

from ertools.states import BmBoxState as B
from ertools.states import Machine

STOP = "reason: stop"
TIMEOUT = "reason: timeout"

Message = tuple[int, Machine, int, str]  # (record time ns, machine, state, payload)


class Replay:
    """The BmBox as the node saw it, read from the recorded state messages."""

    def __init__(self, messages: Sequence[Message]) -> None:
        self._msgs = sorted(messages, key=lambda m: m[0])
        self._pos = 0
        self.state = int(B.START)  # BmBox.__init__: FSM(..., BmBoxState.START)
        self.refbox_payload = ""  # BmBox.__init__
        self.client_payload = ""
        self.now = self._msgs[0][0] if self._msgs else 0
        self.log_ended = False

    def _read_one(self) -> bool:
        if self._pos >= len(self._msgs):
            if not self.log_ended:
                # The log ends inside the benchmark: as if the RefBox had sent a stop.
                self.log_ended = True
                self.refbox_payload = STOP
                self.state = int(B.READY)
            return False
        t, machine, state, payload = self._msgs[self._pos]
        self._pos += 1
        self.now = t
        if machine is Machine.BMBOX:
            self.state = state
        elif machine is Machine.REFBOX:
            self.refbox_payload = payload
        else:
            self.client_payload = payload
        return True

    def wait_transition(self, frm: int) -> None:
        """FSM.wait_transition(frm, ...): until the BmBox is no longer in ``frm``."""
        while self.state == frm and self._read_one():
            pass

    def update(self, to: int) -> None:
        """The node's own FSM.update(to): published as the BmBox's next state change (or a
        callback's, when it won the race: FSM.py is not stored, so which one is not known)."""
        del to
        self.wait_transition(self.state)

    # -- BmBox.py's methods, as written
    def WaitClient(self) -> None:  # noqa: N802 (the 2015 names)
        if self.state != B.START:
            return
        self.update(B.WAITING_CLIENT)
        self.wait_transition(B.WAITING_CLIENT)

    def SendGoal(self) -> None:  # noqa: N802
        if self.state not in (B.READY, B.COMPLETED_MANUAL_OPERATION):
            return
        self.update(B.TRANSMITTING_GOAL)
        self.wait_transition(B.TRANSMITTING_GOAL)

    def WaitResult(self) -> str | None:  # noqa: N802
        if self.state != B.EXECUTING_GOAL:
            return None
        self.update(B.WAITING_RESULT)
        self.wait_transition(B.WAITING_RESULT)
        return self.client_payload

    def Timeout(self) -> bool:  # noqa: N802
        return self.refbox_payload == TIMEOUT

    def Running(self) -> bool:  # noqa: N802
        return self.refbox_payload != STOP


@dataclass
class TfPoses:
    """``world -> robot_at_home`` as tf held it: stamps (ns), positions, quaternions."""

    t_ns: np.ndarray
    xyz: np.ndarray
    quat: np.ndarray

    def at(self, t: int) -> tuple[np.ndarray, Rotation]:
        """tf's lookup at ``t``: linear between the samples around it, SLERP for rotation."""
        j = int(np.searchsorted(self.t_ns, t, side="right")) - 1
        if self.t_ns[j] == t:
            return self.xyz[j], Rotation.from_quat(self.quat[j])
        f = (t - self.t_ns[j]) / (self.t_ns[j + 1] - self.t_ns[j])
        rot = Slerp([0.0, 1.0], Rotation.from_quat(self.quat[j : j + 2]))([f])[0]
        return self.xyz[j] + f * (self.xyz[j + 1] - self.xyz[j]), rot


@dataclass
class Score2015:
    position_accuracy: float
    orientation_accuracy: float
    execution_time: float
    timeout_segments: int
    details: dict[int, dict[str, Any]] = field(default_factory=dict)


def node_2015(
    replay: Replay,
    tf: TfPoses,
    waypoints: Sequence[Sequence[float]],
    marker_to_robot: tuple[Sequence[float], Sequence[float]],
) -> Score2015:
    """scripts/fbm2h's main(), from ``WaitClient()`` to the score (see the module docstring)."""
    benchmark = replay
    r_mr = Rotation.from_quat(list(marker_to_robot[1]))
    N = len(waypoints)
    i = 0
    sum_d = 0.0
    sum_sin = 0.0
    sum_cos = 0.0
    execution_time = 0.0
    timeouts = 0
    segments_detail: dict[int, dict[str, Any]] = {}

    benchmark.WaitClient()
    while benchmark.Running() and not benchmark.Timeout() and i < N:
        benchmark.SendGoal()
        segments_detail[i] = {}
        start_segment_time = benchmark.now  # time.time()
        segments_detail[i]["start_segment_time"] = start_segment_time
        result_yaml = benchmark.WaitResult()
        segments_detail[i]["result_payload"] = result_yaml
        end_segment_time = benchmark.now  # time.time()
        # Seconds as the node's float subtraction would give them, from the log's int clock.
        segment_time = (end_segment_time - start_segment_time) / 1e9
        segments_detail[i]["end_segment_time"] = end_segment_time
        segments_detail[i]["segment_time"] = segment_time

        if benchmark.Timeout():
            execution_time = execution_time + segment_time
            segments_detail[i]["refbox_timeout"] = True
            continue
        segments_detail[i]["refbox_timeout"] = False

        if not benchmark.Running():
            continue

        # tf world -> actual_robot at the moment: the marker pose composed with the transform.
        p_m, r_m = tf.at(end_segment_time)
        p_r = p_m + r_m.apply(list(marker_to_robot[0]))
        theta = float((r_m * r_mr).as_euler("xyz")[2])  # euler_from_quaternion, static xyz
        rp = (float(p_r[0]), float(p_r[1]), theta)
        tp = waypoints[i]
        segments_detail[i]["robot_pose"] = rp

        d_error = math.sqrt((rp[0] - tp[0]) ** 2 + (rp[1] - tp[1]) ** 2)
        sum_d = sum_d + d_error
        sin_error = math.sin(math.fabs(rp[2] - tp[2]))
        sum_sin = sum_sin + sin_error
        cos_error = math.cos(math.fabs(rp[2] - tp[2]))
        sum_cos = sum_cos + cos_error
        segments_detail[i]["dinstance_error"] = d_error
        segments_detail[i]["orientation_error"] = math.atan2(sin_error, cos_error)
        execution_time = execution_time + segment_time
        i = i + 1

    return Score2015(
        position_accuracy=sum_d / N,
        orientation_accuracy=math.atan2(sum_sin, sum_cos),
        execution_time=execution_time,
        timeout_segments=timeouts,
        details=segments_detail,
    )
