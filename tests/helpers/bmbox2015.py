"""The 2015 BmBox replayed over a log, for the tests that run a node's loop as written.

Source: ``src/rockin_scoring/BmBox.py`` of rockin-robot-challenge/benchmark_and_scoring_fbm at
7628309 (2015-07-06, its last change: the file every later node imports unchanged, 50b173b of
2015-11-30, 40ba68b of 2017-01-26 and 89dfa75 of 2017-11-10), with its state machine
``src/rockin_scoring/FSM.py`` at 3a41cb2 (its only version). Read line by line at those commits.

What the two files do, and how a log shows it:

- ``FSM.update(s)`` (FSM.py 51-61) changes the state only when ``s`` is in the transitions
  allowed from the current one (BmBox.py 133-142, :data:`ALLOWED`); otherwise it logs an error
  and nothing changes. ``FSM.wait_transition(a, b)`` (42-48) waits while the state is ``a``,
  then, when ``b`` is not None, until it is ``b``.
- The node's own updates (``WaitClient``, ``ManualOperation``, ``SendGoal``, ``WaitResult``)
  are the next logged BmBox change: the replay checks it is the state the code sets (a log that
  shows something else is not this node's log, :class:`NotThisNodeError`). One exception is a
  race the code allows: ``SendGoal`` returns as the BmBox reaches EXECUTING_GOAL and a RefBox
  callback (lines 49-55) may move it to READY before ``WaitResult``'s ``check_state``; the log
  then shows EXECUTING_GOAL -> READY and ``WaitResult`` returned at once (``None``).
- A wait ends at the first logged change that satisfies it; the changes on the way are the
  callbacks' (each checked against :data:`ALLOWED`).
- The node's clock (``time.time()`` or ``rospy.Time.now()`` right after a call returns) is the
  record time of the message that ended the call, the closest the log gets to it.
- ``Timeout()`` / ``Running()`` (lines 114-126) compare the payload of the last RefBox message
  at that moment (the callback stores every message's payload, lines 34-35) with the strings
  ``reason: timeout`` / ``reason: stop``, whole: the seed's bare ``timeout`` / ``halt`` (6.2.3)
  are neither (the 2015 @Home RefBox sent the two strings: rockin-robot-challenge/at_home_rsbb,
  src/core_zone_exec.h, ``phase_post_2``).
- A log that ends while the node still needs the BmBox is the benchmark stopped there
  (issue 23): a RefBox END ``reason: stop`` at the last BmBox message, to which the callback
  answers as lines 43-44 and 53-54 do, through the FSM: back to READY from WAITING_CLIENT,
  WAITING_MANUAL_OPERATION, EXECUTING_GOAL or WAITING_RESULT; refused from
  COMPLETED_MANUAL_OPERATION and TRANSMITTING_GOAL (no such transition), ignored in
  TRANSMITTING_SCORE. Past that moment nothing more can reach the BmBox: the node's own
  updates still happen (through the FSM), and a wait that the state does not already satisfy
  never returns: :class:`Blocked`. The ports catch it where the node's loop is and compute the
  score from what the node had (it never sent one: that is the rule for a cut log).

Nothing here imports ertools: the tests compare what this replay gives with ertools' output.
"""

from __future__ import annotations

from dataclasses import dataclass, field

# BmBoxState codes (rockin_scoring/msg/BmBoxState.msg; seed Listing 6).
START, WAITING_CLIENT, READY, WAITING_MANUAL_OPERATION = 0, 1, 2, 3
COMPLETED_MANUAL_OPERATION, TRANSMITTING_GOAL, EXECUTING_GOAL = 4, 5, 6
WAITING_RESULT, TRANSMITTING_SCORE, END = 7, 8, 9

# BmBox.py 133-142: the transitions FSM.update allows from each state.
ALLOWED: dict[int, tuple[int, ...]] = {
    START: (WAITING_CLIENT, END),
    WAITING_CLIENT: (READY, END),
    READY: (WAITING_MANUAL_OPERATION, TRANSMITTING_GOAL, TRANSMITTING_SCORE, END),
    WAITING_MANUAL_OPERATION: (COMPLETED_MANUAL_OPERATION, READY, END),
    COMPLETED_MANUAL_OPERATION: (TRANSMITTING_GOAL, END),
    TRANSMITTING_GOAL: (EXECUTING_GOAL, END),
    EXECUTING_GOAL: (WAITING_RESULT, READY, END),
    WAITING_RESULT: (READY, END),
    TRANSMITTING_SCORE: (END,),
    END: (END,),
}

# The two strings BmBox.py compares (lines 49, 53, 97, 100, 117, 126), whole.
TIMEOUT_PAYLOAD = "reason: timeout"
STOP_PAYLOAD = "reason: stop"

Msg = tuple[int, int, str]  # record time ns, state code, payload


class NotThisNodeError(AssertionError):
    """The log's BmBox did something the node as written cannot have made it do."""


class Blocked(Exception):  # noqa: N818 (what happens to the node, not an error of the test)
    """The log has ended and the node waits for a BmBox change that can no longer come."""


@dataclass
class BmBoxReplay:
    """``BmBox()`` of the node, driven by the logged messages of the three machines."""

    bmbox: list[Msg]
    refbox: list[Msg]
    client: list[Msg]
    now: int = 0  # the node's clock: the record time of the message that ended the last call
    cut_at: int | None = None  # the log ended while the node needed the BmBox: stopped there
    changes: list[Msg] = field(default_factory=list)
    i: int = -1  # index in ``changes`` of the logged BmBox state in force
    state: int = START  # FSM._state (BmBox.__init__: START)
    manual_message: str = ""  # the payload of the last WAITING_MANUAL_OPERATION the node set
    goals: int = 0  # goals the log shows sent (TRANSMITTING_GOAL)

    def __post_init__(self) -> None:
        for m in self.bmbox:
            if not self.changes or self.changes[-1][1] != m[1]:
                self.changes.append(m)
        self.now = self.bmbox[0][0] if self.bmbox else 0

    # -- what the callbacks stored (lines 20-35) ---------------------------------------------

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

    def _peek(self) -> Msg | None:
        return self.changes[self.i + 1] if self.i + 1 < len(self.changes) else None

    def _take(self) -> None:
        """The next logged change becomes the state in force; the clock moves to it."""
        t, state, _ = self.changes[self.i + 1]
        if self.i >= 0 and state not in ALLOWED[self.state]:
            raise NotThisNodeError(f"BmBox {self.state} -> {state} at {t}: no such transition")
        self.i += 1
        self.state, self.now = state, t

    def _cut(self) -> None:
        """The log has ended: the RefBox's ``reason: stop`` at its last BmBox message, answered
        as BmBox.py 43-44 and 53-54 answer it (through the FSM)."""
        self.cut_at = self.now = max(self.now, self.bmbox[-1][0])
        if self.state != TRANSMITTING_SCORE and READY in ALLOWED[self.state]:
            self.state = READY

    def _own(self, state: int, payload: str | None = None) -> None:
        """``FSM.update(state)`` by the node itself: the next logged change (see above)."""
        if self.cut_at is None and self._peek() is None:
            self._cut()
        if self.cut_at is not None:
            if state in ALLOWED[self.state]:  # FSM._check_transition; else refused, unchanged
                self.state = state
            return
        nxt = self._peek()
        assert nxt is not None
        if nxt[1] != state:
            raise NotThisNodeError(f"BmBox {nxt[1]} at {nxt[0]} where the node set {state}")
        self._take()
        del payload  # what the node published is in the log; the ports read it there

    def _wait(self, from_state: int, to_state: int | None) -> None:
        """``FSM.wait_transition(from_state, to_state)``."""

        def satisfied() -> bool:
            return self.state != from_state and (to_state is None or self.state == to_state)

        while not satisfied():
            if self.cut_at is not None:
                raise Blocked(f"waiting out of {from_state} for {to_state} after the log's end")
            if self._peek() is None:
                self._cut()
                continue
            self._take()

    def sleep(self, seconds: float) -> None:
        """The node's ``time.sleep``: its clock moves on. When nothing more of the BmBox is
        logged (and it had not finished), the node never acted again: the benchmark was stopped
        while it slept, before its next ``Running()``."""
        self.now += round(seconds * 1e9)
        finished = self.bmbox[-1][1] in (TRANSMITTING_SCORE, END)
        if self.cut_at is None and not finished and self._peek() is None:
            self._cut()

    # -- the BmBox API the nodes call (BmBox.py lines 58-126) --------------------------------

    def check_state(self, state: int) -> bool:
        """``FSM.check_state`` (FSM.py 34-39): a wrong state is logged, nothing else."""
        return self.state == state

    def WaitClient(self) -> None:  # noqa: N802 (the 2015 name)
        # A log may begin after START: the BmBox's first logged state is taken as it was.
        while self.cut_at is None and self.state != READY:
            nxt = self._peek()
            if nxt is None:
                self._cut()
                raise Blocked("the log ends before the Client connected")
            if nxt[1] not in (START, WAITING_CLIENT, READY):
                raise NotThisNodeError(f"BmBox {nxt[1]} at {nxt[0]} before READY")
            self.i += 1
            self.state, self.now = nxt[1], nxt[0]

    def ManualOperation(self, message: str | None = None) -> str | None:  # noqa: N802
        if not self.check_state(READY):
            return None
        self._own(WAITING_MANUAL_OPERATION, message)
        if self.cut_at is None:
            self.manual_message = self.changes[self.i][2]
        self._wait(WAITING_MANUAL_OPERATION, None)
        return self.refbox_payload()

    def SendGoal(self, goal: str | None = None) -> None:  # noqa: N802
        if self.state not in (READY, COMPLETED_MANUAL_OPERATION):
            return
        self._own(TRANSMITTING_GOAL, goal)
        if self.cut_at is None:
            self.goals += 1
        self._wait(TRANSMITTING_GOAL, EXECUTING_GOAL)

    def WaitResult(self) -> str | None:  # noqa: N802
        nxt = self._peek()
        if self.state == EXECUTING_GOAL and self.cut_at is None and nxt and nxt[1] == READY:
            # A RefBox callback (lines 49-55) moved the BmBox before check_state ran.
            self._take()
        if not self.check_state(EXECUTING_GOAL):
            return None
        self._own(WAITING_RESULT)
        self._wait(WAITING_RESULT, None)
        return self.client_payload()

    def Timeout(self) -> bool:  # noqa: N802
        return self.refbox_payload() == TIMEOUT_PAYLOAD

    def Running(self) -> bool:  # noqa: N802
        return self.refbox_payload() != STOP_PAYLOAD
