"""The object's height over the table during a goal: at the 2019 script's 10 Hz checks, or at
every mocap sample (ertools' reading, rule ``hgmf.grasp-sampling``), vectorised.

The script (l. 176, 261-274) starts a ``rospy.Timer`` of 0.1 s when the goal starts; each tick
takes ``now``, waits up to 0.1 s until ``table_origin -> actor_markerset`` can be looked up at
``now``, then looks it up at time 0: tf's *latest common time* of the two bodies, the older of
their newest samples held then. None of these moments is logged: they are inferred from the
goal's logged start (the ticks at start + k * 0.1 s, up to its end) and the samples' record
times (when the script's listener had them), as the replays' World does.
"""

from __future__ import annotations

import numpy as np

from ertools.arrays import F64, I64, Bool
from ertools.benchmarks.hgmf.config import CHECK_PERIOD_NS, CHECK_WAIT_NS
from ertools.frozen_dataclass import frozen_dataclass
from ertools.rsbb.tf import TfTrack, script_poses

IDENTITY = ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0))
#: tf2's time cache keeps 10 s of samples behind the newest.
CACHE_NS = 10_000_000_000
_NEVER = np.iinfo(np.int64).max


@frozen_dataclass(eq=False)
class Heights:
    """The object's height in the table's frame at some moments.

    Attributes:
        t_ns: (M,) the moments the height is of (a check's latest common time, or a sample).
        z: (M,) heights (NaN where no lookup succeeded).
        ok: (M,) the lookup succeeded.
        checked_ns: (M,) when each check was made (the tick; a sample's own stamp).
    """

    t_ns: I64
    z: F64
    ok: Bool
    checked_ns: I64


def object_heights(actor: TfTrack, table: TfTrack, t_ns: I64) -> tuple[F64, Bool]:
    """``actor_markerset`` in ``table_origin`` at ``t_ns`` as tf composes it: its z, and
    whether both bodies had samples around each moment."""
    poses = script_poses(actor, np.asarray(t_ns, dtype=np.int64), IDENTITY, reference=table)
    return poses.z, poses.inside


def timer_ticks(start_ns: int, end_ns: int) -> I64:
    """The timer's ticks: start + k * 0.1 s for k >= 1, up to and including the end."""
    if end_ns < start_ns + CHECK_PERIOD_NS:
        return np.empty(0, np.int64)
    count = (end_ns - start_ns) // CHECK_PERIOD_NS
    return start_ns + CHECK_PERIOD_NS * np.arange(1, count + 1, dtype=np.int64)


def _ready(track: TfTrack, t_ns: I64) -> I64:
    """When data stamped at or after each moment first arrived (never: int64 max)."""
    suffix = np.minimum.accumulate(track.arrival_ns[::-1])[::-1]
    k = np.searchsorted(track.t_ns, t_ns, side="left")
    out = np.full(t_ns.shape, _NEVER, dtype=np.int64)
    inside = k < len(track)
    out[inside] = suffix[k[inside]]
    return out


def _newest_held(track: TfTrack, clock_ns: I64) -> I64:
    """The newest stamp among the samples arrived by each clock (-1: none)."""
    order = np.argsort(track.arrival_ns, kind="stable")
    newest = np.maximum.accumulate(track.t_ns[order])
    k = np.searchsorted(track.arrival_ns[order], clock_ns, side="right") - 1
    return np.where(k >= 0, newest[np.maximum(k, 0)], -1)


def _held_before(track: TfTrack, t_ns: I64, clock_ns: I64, newest: I64) -> Bool:
    """A sample stamped at or before each moment is held at the clock (arrived, and within
    the cache's 10 s of the newest): tf2 can interpolate at the moment, not extrapolate."""
    k = np.searchsorted(track.t_ns, t_ns, side="right") - 1
    ok = k >= 0
    kk = np.maximum(k, 0)
    return np.asarray(
        ok & (track.arrival_ns[kk] <= clock_ns) & (track.t_ns[kk] + CACHE_NS >= newest)
    )


def timer_heights(actor: TfTrack, table: TfTrack, ticks: I64) -> Heights:
    """The script's checks at ``ticks``: the wait (0.1 s) for both bodies at the tick, then
    the lookup at their latest common time as held when the wait returned."""
    t = np.asarray(ticks, dtype=np.int64)
    ready = np.maximum(t, np.maximum(_ready(actor, t), _ready(table, t)))
    waited = ready <= t + CHECK_WAIT_NS
    clock = np.where(waited, ready, t)
    newest_a, newest_t = _newest_held(actor, clock), _newest_held(table, clock)
    ok = waited & _held_before(actor, t, clock, newest_a) & _held_before(table, t, clock, newest_t)
    common = np.minimum(newest_a, newest_t)
    z, inside = object_heights(actor, table, np.where(ok, common, t))
    ok = ok & inside
    return Heights(common, np.where(ok, z, np.nan), ok, t)


def sample_heights(actor: TfTrack, table: TfTrack, start_ns: int, end_ns: int) -> Heights:
    """The height at every sample of the object's marker set stamped from ``start_ns`` to
    ``end_ns`` (the table interpolated at its stamp)."""
    lo = int(np.searchsorted(actor.t_ns, start_ns, side="left"))
    hi = int(np.searchsorted(actor.t_ns, end_ns, side="right"))
    t = actor.t_ns[lo:hi]
    z, inside = object_heights(actor, table, t)
    return Heights(t, np.where(inside, z, np.nan), inside, t)
