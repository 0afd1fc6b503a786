"""A HOPF run's goals found in its events: the script's iterations (docs/hopf.md, "Control
flow"), each with its manual operations, the moment of its ground-truth lookup and its goal.

An iteration begins with the first manual operation (``Place the positioner and the ...``,
naming the item drawn); ``The position of the positioner could not be acquired!`` follows
each failed lookup; ``Remove the positioner`` ends the placing; the goal comes after. The
script's successful lookup broadcast ``/item`` stamped with its moment: the last broadcast
between the placement and the removal is the ground truth's moment.
"""

from __future__ import annotations

import numpy as np

from ertools.arrays import I64
from ertools.benchmarks.hopf.items import REMOVE_TEXT, RETRY_PREFIX, placed_id
from ertools.frozen_dataclass import frozen_dataclass
from ertools.rsbb.log import GoalEvent, ManualOperationEvent, RsbbRun

# A lookup's ``now`` precedes the RefBox message the script's clock is read from by a few ms
# (the BmBox acknowledges before the RefBox publishes): a broadcast this much before the
# manual operation's completion belongs to the lookup after it.
LOOKUP_SLACK_NS = 50_000_000


@frozen_dataclass
class Iteration:
    """One iteration of the script's loop (one item shown).

    Attributes:
        index: the script's ``i`` (from 1).
        item_id: the id the placement request names (None: a request in another form).
        place: the first manual operation.
        retries: the manual operations after failed lookups, in order.
        remove: the second manual operation (None: the iteration ended before it).
        lookup_ns: the moment of the successful lookup (its ``/item`` broadcast), None when
            none is logged.
        goal: the goal (None: the iteration ended before it).
    """

    index: int
    item_id: int | None
    place: ManualOperationEvent
    retries: tuple[ManualOperationEvent, ...] = ()
    remove: ManualOperationEvent | None = None
    lookup_ns: int | None = None
    goal: GoalEvent | None = None

    @property
    def placed_ns(self) -> int | None:
        """When the last placement before the lookup was confirmed (None: not confirmed)."""
        last = self.retries[-1] if self.retries else self.place
        return last.t_done_ns


@frozen_dataclass
class HopfRuns:
    """The iterations of a run and what did not fit the script's flow."""

    iterations: tuple[Iteration, ...]
    problems: tuple[str, ...] = ()


def _window_end(run: RsbbRun, nxt: ManualOperationEvent | None) -> int:
    if nxt is not None:
        return nxt.t_request_ns
    if run.t_end_ns is not None:
        return run.t_end_ns
    return int(np.iinfo(np.int64).max)


def find_iterations(run: RsbbRun, lookups_ns: I64) -> HopfRuns:
    """The run's iterations, from its manual operations, goals and ``/item`` broadcasts."""
    problems: list[str] = []
    groups: list[list[ManualOperationEvent]] = []
    for k, op in enumerate(run.manual_operations):
        if placed_id(op.request) is not None:
            groups.append([op])
        elif groups and (op.request.startswith(RETRY_PREFIX) or op.request == REMOVE_TEXT):
            groups[-1].append(op)
        else:
            problems.append(f"manual operation {k + 1} is not one of HOPF's: {op.request!r}")
    stamps = np.sort(np.asarray(lookups_ns, dtype=np.int64))
    goals = list(run.goals)
    out: list[Iteration] = []
    for n, ops in enumerate(groups):
        place = ops[0]
        nxt = groups[n + 1][0] if n + 1 < len(groups) else None
        end = _window_end(run, nxt)
        retries = tuple(o for o in ops[1:] if o.request.startswith(RETRY_PREFIX))
        removes = [o for o in ops[1:] if o.request == REMOVE_TEXT]
        if len(removes) > 1:
            problems.append(f"goal {n + 1}: 'Remove the positioner' asked {len(removes)} times")
        remove = removes[0] if removes else None
        mine = [g for g in goals if place.t_request_ns <= g.t_request_ns < end]
        for g in mine:
            goals.remove(g)
        if len(mine) > 1:
            problems.append(f"goal {n + 1}: {len(mine)} goals sent for one item")
        goal = mine[0] if mine else None
        placed = (retries[-1] if retries else place).t_done_ns
        lookup: int | None = None
        if placed is not None:
            until = remove.t_request_ns if remove is not None else end
            lo = np.searchsorted(stamps, placed - LOOKUP_SLACK_NS, side="left")
            hi = np.searchsorted(stamps, until, side="right")
            if hi > lo:
                lookup = int(stamps[hi - 1])
        out.append(Iteration(n + 1, placed_id(place.request), place, retries, remove, lookup, goal))
    for g in goals:
        problems.append(f"goal {g.index + 1} was sent outside a placement: not HOPF's flow")
    return HopfRuns(tuple(out), tuple(problems))
