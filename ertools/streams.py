"""Streams: frozen dataclasses of NumPy arrays, the currency between IO and computation.

Readers produce them, scorers consume them; nothing here touches a file.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np
import numpy.typing as npt

from ertools.arrays import F64, I64, U8
from ertools.frozen_dataclass import frozen_dataclass
from ertools.geometry import yaw_from_quat

if TYPE_CHECKING:
    import pandas as pd

    from ertools.states import Machine


def _window_slice(t_ns: I64, start_ns: int | None, end_ns: int | None) -> slice:
    """Index range of sorted ``t_ns`` inside [start_ns, end_ns] (both ends inclusive)."""
    lo = 0 if start_ns is None else int(np.searchsorted(t_ns, start_ns, side="left"))
    hi = len(t_ns) if end_ns is None else int(np.searchsorted(t_ns, end_ns, side="right"))
    return slice(lo, max(lo, hi))


@frozen_dataclass
class FrameChange:
    """The parent or child frame name of a pose topic changing between two messages.

    Attributes:
        t_ns: time of the first message with the new name.
        field: ``frame_id`` or ``child_frame_id``.
        old, new: the names before and after.
    """

    t_ns: int
    field: str
    old: str
    new: str


# A stream keeps at most this many changes (a topic alternating frames every message would
# otherwise carry one object per message); the warning says when there were more.
MAX_FRAME_CHANGES = 100


@frozen_dataclass(eq=False)
class PoseStream:
    """A time series of 6-DoF poses of ``child_frame_id`` in ``frame_id``.

    Attributes:
        t_ns: (N,) int64 nanoseconds since the epoch, non-decreasing.
        xyz: (N, 3) float64 positions in metres.
        quat_xyzw: (N, 4) float64 unit quaternions, scalar last.
        frame_id: parent frame (``world`` for mocap), "" when the message has none.
        child_frame_id: the tracked body, "" when unknown.
        source: where it came from, e.g. ``file.bag:/fbm3w/robot_at_work/pose``.
        frame_changes: where the messages' frame names changed (``frame_id`` and
            ``child_frame_id`` above are the first ones); empty for a consistent topic.
        t_s: (N,) float64 seconds as a text trajectory wrote them (TUM, EuRoC), None for a
            bag (ROS's ``sec + nanosec * 1e-9`` of ``t_ns``): evo compares these floats, so
            ``--t-max-diff`` does too (:func:`float_seconds`).
    """

    t_ns: I64
    xyz: F64
    quat_xyzw: F64
    frame_id: str = ""
    child_frame_id: str = ""
    source: str = ""
    frame_changes: tuple[FrameChange, ...] = ()
    t_s: F64 | None = None

    def __post_init__(self) -> None:
        n = self.t_ns.shape[0]
        if self.t_ns.shape != (n,) or self.xyz.shape != (n, 3) or self.quat_xyzw.shape != (n, 4):
            raise ValueError(
                f"PoseStream shapes disagree: t_ns {self.t_ns.shape}, xyz {self.xyz.shape}, "
                f"quat_xyzw {self.quat_xyzw.shape}"
            )
        if self.t_s is not None and self.t_s.shape != (n,):
            raise ValueError(f"PoseStream t_s has shape {self.t_s.shape}, not ({n},)")

    def __len__(self) -> int:
        return int(self.t_ns.shape[0])

    @property
    def start_ns(self) -> int:
        """First time stamp (raises IndexError when empty)."""
        return int(self.t_ns[0])

    @property
    def end_ns(self) -> int:
        """Last time stamp (raises IndexError when empty)."""
        return int(self.t_ns[-1])

    @property
    def yaw(self) -> F64:
        """(N,) yaw angles in radians, in [-pi, pi]."""
        return yaw_from_quat(self.quat_xyzw)

    def take(self, index: slice | npt.NDArray[np.bool_] | npt.NDArray[np.intp]) -> PoseStream:
        """A new stream with the selected samples (slice, boolean mask or indices)."""
        return PoseStream(
            self.t_ns[index],
            self.xyz[index],
            self.quat_xyzw[index],
            self.frame_id,
            self.child_frame_id,
            self.source,
            # Absolute times: still true of the subset (a change outside it is still a change
            # of the topic the subset came from).
            self.frame_changes,
            None if self.t_s is None else self.t_s[index],
        )

    def window(self, start_ns: int | None, end_ns: int | None) -> PoseStream:
        """Samples with start_ns <= t <= end_ns (None leaves that side open)."""
        return self.take(_window_slice(self.t_ns, start_ns, end_ns))

    def to_dataframe(self) -> pd.DataFrame:
        """x, y, z, qx, qy, qz, qw, yaw indexed by a UTC DatetimeIndex named ``time``."""
        import pandas as pd  # lazy: pandas only for DataFrames (~0.2 s to import)

        index = pd.DatetimeIndex(pd.to_datetime(self.t_ns, unit="ns", utc=True), name="time")
        data = np.column_stack([self.xyz, self.quat_xyzw, self.yaw])
        return pd.DataFrame(
            data, index=index, columns=["x", "y", "z", "qx", "qy", "qz", "qw", "yaw"]
        )

    @staticmethod
    def empty(frame_id: str = "", child_frame_id: str = "", source: str = "") -> PoseStream:
        """A stream with no samples."""
        return PoseStream(
            np.empty(0, np.int64),
            np.empty((0, 3)),
            np.empty((0, 4)),
            frame_id,
            child_frame_id,
            source,
        )


def float_seconds(stream: PoseStream) -> F64:
    """The stamps as float64 seconds, computed as evo computes them from the same source.

    A text trajectory keeps the floats its text parses to (evo reads the same text); a bag's
    stamps are ``sec + nanosec * 1e-9`` (evo's reading of a ROS header), which can differ by a
    unit in the last place from ``t_ns / 1e9``: at an exact tie or an exact ``max_diff`` that
    unit decides the pair.
    """
    if stream.t_s is not None:
        return stream.t_s
    sec, nsec = np.divmod(stream.t_ns, 1_000_000_000)
    out: F64 = sec.astype(np.float64) + nsec.astype(np.float64) * 1e-9
    return out


@frozen_dataclass(eq=False)
class StateStream:
    """The messages of one state topic: (t_ns, state, payload) per message.

    Attributes:
        machine: which state machine published it.
        t_ns: (N,) int64 record times (the state messages carry no header).
        state: (N,) uint8 state codes (see :mod:`ertools.states` for the enums).
        payload: N payload strings.
        topic: the topic name.
        source: the file it was read from.
    """

    machine: Machine
    t_ns: I64
    state: U8
    payload: tuple[str, ...]
    topic: str = ""
    source: str = ""

    def __len__(self) -> int:
        return int(self.t_ns.shape[0])

    def take(self, index: slice | npt.NDArray[np.intp]) -> StateStream:
        """A new stream with the selected messages."""
        if isinstance(index, slice):
            payload = self.payload[index]
        else:
            payload = tuple(self.payload[int(i)] for i in index)
        return StateStream(
            self.machine, self.t_ns[index], self.state[index], payload, self.topic, self.source
        )

    def window(self, start_ns: int | None, end_ns: int | None) -> StateStream:
        """Messages with start_ns <= t <= end_ns (None leaves that side open)."""
        return self.take(_window_slice(self.t_ns, start_ns, end_ns))

    def changes(self) -> StateStream:
        """Only the messages where the state or the payload differs from the previous one.

        The 2015 machines re-published their state at 10 Hz; a transition is the first message
        of each run of equal (state, payload).
        """
        n = len(self)
        if n == 0:
            return self
        keep = np.ones(n, dtype=bool)
        keep[1:] = self.state[1:] != self.state[:-1]
        payload_changed = np.fromiter(
            (self.payload[i] != self.payload[i - 1] for i in range(1, n)), dtype=bool, count=n - 1
        )
        keep[1:] |= payload_changed
        return self.take(np.flatnonzero(keep))

    def to_dataframe(self) -> pd.DataFrame:
        """state (int), state_name and payload, indexed by a UTC DatetimeIndex named ``time``."""
        import pandas as pd  # lazy: pandas only for DataFrames (~0.2 s to import)

        from ertools.states import state_name  # lazy: 5 enums, 2 ms, only for state names

        index = pd.DatetimeIndex(pd.to_datetime(self.t_ns, unit="ns", utc=True), name="time")
        return pd.DataFrame(
            {
                "state": self.state.astype(int),
                "state_name": [state_name(self.machine, int(s)) for s in self.state],
                "payload": list(self.payload),
            },
            index=index,
        )


@frozen_dataclass
class Interval:
    """A closed time interval [start_ns, end_ns]."""

    start_ns: int
    end_ns: int

    @property
    def duration_ns(self) -> int:
        return self.end_ns - self.start_ns


@frozen_dataclass
class Provenance:
    """What a result was computed from, for reports and audits.

    ``team`` is who ran the benchmark and ``team_source`` where that name was found
    (``explicit``, ``payload``, ``log name`` or ``transform``: see
    :mod:`ertools.benchmarks.common.teams`); both None when no name was found.
    """

    inputs: tuple[str, ...] = ()
    parameters: tuple[tuple[str, str], ...] = ()
    team: str | None = None
    team_source: str | None = None


def concatenate_poses(streams: Sequence[PoseStream]) -> PoseStream:
    """Join streams end to end (no sorting: see ``ertools.io.merge`` for time-ordered merges)."""
    if not streams:
        return PoseStream.empty()
    first = streams[0]
    changes: list[FrameChange] = [c for s in streams for c in s.frame_changes]
    last = first
    for s in streams[1:]:
        if not len(s):
            continue
        # A split file whose messages name other frames changes the topic's frames too.
        for name, old, new in (
            ("frame_id", last.frame_id, s.frame_id),
            ("child_frame_id", last.child_frame_id, s.child_frame_id),
        ):
            if old != new:
                changes.append(FrameChange(s.start_ns, name, old, new))
        last = s
    changes.sort(key=lambda c: c.t_ns)
    return PoseStream(
        np.concatenate([s.t_ns for s in streams]),
        np.concatenate([s.xyz for s in streams]),
        np.concatenate([s.quat_xyzw for s in streams]),
        first.frame_id,
        first.child_frame_id,
        ";".join(dict.fromkeys(s.source for s in streams)),
        tuple(changes[:MAX_FRAME_CHANGES]),
    )
