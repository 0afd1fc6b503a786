"""The 2015 BmBox replayed over a log, for the tests that run a 2015 node's loop as written.

``rockin_scoring/BmBox.py`` (svenschneider/benchmark_and_scoring_fbm at 90d5c4d; its FSM in
``rockin_benchmarking/FSM.py``) is a state machine the node drives: each call updates the
state (``ManualOperation``: READY -> WAITING_MANUAL_OPERATION, ...) and then blocks in
``FSM.wait_transition`` until a RefBox or Client callback moves the state on. A log holds what
the BmBox published (10 Hz, plus each change), so here:

- a node's own update is the next logged change of BmBox state (the replay checks it is the
  state the code sets: a log that shows something else is not this node's log);
- a wait ends at the first logged BmBox change that satisfies it (``wait_transition(s, None)``:
  any change; ``wait_transition(s, t)``: the change to t);
- the node's clock (``time.time()`` after a call returns) is the record time of that message,
  the closest the log gets to it;
- ``Timeout()`` / ``Running()`` compare the payload of the last RefBox message at that moment
  (the callback stored every message's payload, lines 34-35), with the strings of lines 117 and
  126, exactly, as written: the seed's bare ``timeout`` / ``halt`` (6.2.3) are neither string,
  so to this BmBox they are no timeout and no stop (the 2015 @Home RefBox sent the two strings
  themselves: rockin-robot-challenge/at_home_rsbb, src/core_zone_exec.h, ``phase_post_2``);
- a log that ends while the node waits is the benchmark stopped there (issue 23's rule): a
  RefBox ``reason: stop`` at the last BmBox message, to which the BmBox answers as lines 53-54
  do (back to READY; from TRANSMITTING_GOAL, where the FSM would refuse READY and the real node
  would hang, the wait is released the same way: the run is over either way).

Nothing here imports ertools: the tests compare what this replay gives with ertools' output.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

# BmBoxState codes (rockin_scoring/msg/BmBoxState.msg; seed Listing 6).
START, WAITING_CLIENT, READY, WAITING_MANUAL_OPERATION = 0, 1, 2, 3
COMPLETED_MANUAL_OPERATION, TRANSMITTING_GOAL, EXECUTING_GOAL = 4, 5, 6
WAITING_RESULT, TRANSMITTING_SCORE, END = 7, 8, 9

# The two strings BmBox.py compares (lines 49, 53, 97, 100, 117, 126), whole.
TIMEOUT_PAYLOAD = "reason: timeout"
STOP_PAYLOAD = "reason: stop"

Msg = tuple[int, int, str]  # record time ns, state code, payload


class NotThisNodeError(AssertionError):
    """The log's BmBox did something the node as written cannot have made it do."""


@dataclass
class BmBoxReplay:
    """``BmBox()`` of the 2015 node, driven by the logged messages of the three machines."""

    bmbox: list[Msg]
    refbox: list[Msg]
    client: list[Msg]
    now: int = 0  # the node's clock: the record time of the message that ended the last call
    cut_at: int | None = None  # the log ended inside a wait: the benchmark stopped there
    changes: list[Msg] = field(default_factory=list)
    i: int = -1  # index in ``changes`` of the BmBox state in force
    manual_message: str = ""  # the payload of the last WAITING_MANUAL_OPERATION the node set
    goals: int = 0  # goals sent (TRANSMITTING_GOAL in the log)

    def __post_init__(self) -> None:
        for m in self.bmbox:
            if not self.changes or self.changes[-1][1] != m[1]:
                self.changes.append(m)
        self.now = self.bmbox[0][0] if self.bmbox else 0

    # -- what the callbacks stored -----------------------------------------------------------

    def state(self) -> int:
        if self.cut_at is not None:
            return READY
        return self.changes[self.i][1] if self.i >= 0 else START

    def state_payload(self) -> str:
        """The BmBox's own payload in force (the manual operation's message, the goal)."""
        return self.changes[self.i][2] if self.i >= 0 else ""

    def _last(self, msgs: list[Msg]) -> Msg | None:
        last = None
        for m in msgs:
            if m[0] > self.now:
                break
            last = m
        return last

    def refbox_payload(self) -> str:
        if self.cut_at is not None:
            return STOP_PAYLOAD
        last = self._last(self.refbox)
        return "" if last is None else last[2]

    def client_payload(self) -> str:
        last = self._last(self.client)
        return "" if last is None else last[2]

    # -- moving along the log ----------------------------------------------------------------

    def _next(self, accept: Callable[[int], bool], what: str) -> bool:
        """Move to the next logged change; False when the log ends first (then: stopped)."""
        if self.cut_at is not None:
            return False
        if self.i + 1 >= len(self.changes):
            self.cut_at = self.now = self.bmbox[-1][0]
            return False
        t, state, _ = self.changes[self.i + 1]
        if not accept(state):
            raise NotThisNodeError(f"BmBox {state} at {t} where the node expected {what}")
        self.i += 1
        self.now = t
        return True

    def _own(self, state: int) -> bool:
        return self._next(lambda s: s == state, f"its own update to {state}")

    def _wait(self, from_state: int, to_state: int | None) -> None:
        """``FSM.wait_transition(from_state, to_state)``."""
        if to_state is None:
            self._next(lambda s: s != from_state, f"a change from {from_state}")
        else:
            self._next(lambda s: s == to_state, f"the change {from_state} -> {to_state}")

    def sleep(self, seconds: float) -> None:
        """The node's ``time.sleep``: its clock moves on; a log that ends before it wakes
        (with the BmBox not finished) is the benchmark stopped meanwhile."""
        self.now += round(seconds * 1e9)
        last_t, last_state, _ = self.bmbox[-1]
        finished = last_state in (TRANSMITTING_SCORE, END)
        # Nothing the BmBox did after the node's last call is in the log, and the log ends
        # before the node woke: the stop came while it slept.
        nothing_after = self.i + 1 >= len(self.changes)
        if self.cut_at is None and not finished and nothing_after and last_t < self.now:
            self.cut_at = last_t

    # -- the BmBox API the nodes call (BmBox.py lines 58-126) --------------------------------

    def WaitClient(self) -> None:  # noqa: N802 (the 2015 name)
        # START -> WAITING_CLIENT (own), then wait for READY; a log may begin after START.
        while self.cut_at is None and self.state() != READY:
            self._next(lambda s: s in (START, WAITING_CLIENT, READY), "START..READY")

    def ManualOperation(self, message: str | None = None) -> str | None:  # noqa: N802
        if self.state() != READY:  # check_state(READY): logerr and return
            return None
        if self._own(WAITING_MANUAL_OPERATION):
            self.manual_message = self.changes[self.i][2]
            self._wait(WAITING_MANUAL_OPERATION, None)
        return self.refbox_payload()

    def SendGoal(self, goal: str | None = None) -> None:  # noqa: N802
        if self.state() not in (READY, COMPLETED_MANUAL_OPERATION):
            return
        if self._own(TRANSMITTING_GOAL):
            self.goals += 1
            self._wait(TRANSMITTING_GOAL, EXECUTING_GOAL)

    def WaitResult(self) -> str | None:  # noqa: N802
        if self.state() != EXECUTING_GOAL:  # check_state(EXECUTING_GOAL)
            return None
        if self._own(WAITING_RESULT):
            self._wait(WAITING_RESULT, None)
        return self.client_payload()

    def Timeout(self) -> bool:  # noqa: N802
        return self.refbox_payload() == TIMEOUT_PAYLOAD

    def Running(self) -> bool:  # noqa: N802
        return self.refbox_payload() != STOP_PAYLOAD
