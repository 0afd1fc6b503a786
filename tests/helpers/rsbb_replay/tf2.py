"""The scripts' tf listener (tf2's buffer core), as far as their lookups use it.

Each link (parent -> child) keeps its samples (stamp, arrival, translation, rotation); at a
clock only the samples that had arrived count, and of those, as tf2's time cache prunes on
insertion, the ones stamped within 10 s of the newest. A lookup at time t composes the links
from the two frames up to their common ancestor, each link at t: a sample stamped exactly t,
else the two around t interpolated (translation linearly, rotation by tf2's shortest-path
slerp, the ratio in seconds as ``ros::Duration::toSec`` gives it); before the oldest or after
the newest is an extrapolation error. Time 0 is the latest common time: the smallest of the
links' newest stamps. Frame names lose a leading slash, as tf2 strips it.
"""

from __future__ import annotations

import bisect
import math
from dataclasses import dataclass, field

import numpy as np

Vec = tuple[float, float, float]
Quat = tuple[float, float, float, float]

CACHE_NS = 10 * 1_000_000_000


class TfError(Exception):
    """A lookup, connectivity or extrapolation error (what the scripts catch)."""


def frame(name: str) -> str:
    """tf2's spelling of a frame id."""
    return name.lstrip("/")


def _dur_sec(ns: int) -> float:
    sec, nsec = divmod(ns, 1_000_000_000)
    return float(sec) + 1e-9 * float(nsec)


def _slerp(a: Quat, b: Quat, t: float) -> Quat:
    dot = sum(x * y for x, y in zip(a, b, strict=True))
    norms = math.sqrt(sum(x * x for x in a) * sum(x * x for x in b))
    half = math.acos(max(-1.0, min(1.0, abs(dot) / norms)))
    if half == 0.0:
        return a
    d = 1.0 / math.sin(half)
    s0 = math.sin((1.0 - t) * half)
    s1 = math.sin(t * half)
    sign = -1.0 if dot < 0 else 1.0
    return (
        (a[0] * s0 + sign * b[0] * s1) * d,
        (a[1] * s0 + sign * b[1] * s1) * d,
        (a[2] * s0 + sign * b[2] * s1) * d,
        (a[3] * s0 + sign * b[3] * s1) * d,
    )


def _qmul(a: Quat, b: Quat) -> Quat:
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    return (
        aw * bx + ax * bw + ay * bz - az * by,
        aw * by - ax * bz + ay * bw + az * bx,
        aw * bz + ax * by - ay * bx + az * bw,
        aw * bw - ax * bx - ay * by - az * bz,
    )


def _rotate(q: Quat, v: Vec) -> Vec:
    x, y, z, _ = _qmul(_qmul(q, (v[0], v[1], v[2], 0.0)), (-q[0], -q[1], -q[2], q[3]))
    return (x, y, z)


def compose(a: tuple[Vec, Quat], b: tuple[Vec, Quat]) -> tuple[Vec, Quat]:
    """T_a * T_b."""
    ra = _rotate(a[1], b[0])
    return (a[0][0] + ra[0], a[0][1] + ra[1], a[0][2] + ra[2]), _qmul(a[1], b[1])


def invert(a: tuple[Vec, Quat]) -> tuple[Vec, Quat]:
    """T_a^-1."""
    qi = (-a[1][0], -a[1][1], -a[1][2], a[1][3])
    t = _rotate(qi, a[0])
    return (-t[0], -t[1], -t[2]), qi


IDENTITY: tuple[Vec, Quat] = ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0))


@dataclass
class Link:
    """One parent -> child link's samples (kept sorted by stamp; arrays rebuilt on change)."""

    parent: str
    stamps: list[int] = field(default_factory=list)
    arrivals: list[int] = field(default_factory=list)
    values: list[tuple[Vec, Quat]] = field(default_factory=list)
    _arrays: tuple[np.ndarray, np.ndarray] | None = None

    def add(self, stamp: int, arrival: int, value: tuple[Vec, Quat]) -> None:
        k = bisect.bisect_right(self.stamps, stamp)
        self.stamps.insert(k, stamp)
        self.arrivals.insert(k, arrival)
        self.values.insert(k, value)
        self._arrays = None

    def _np(self) -> tuple[np.ndarray, np.ndarray]:
        if self._arrays is None:
            self._arrays = (np.asarray(self.stamps, np.int64), np.asarray(self.arrivals, np.int64))
        return self._arrays

    def known(self, clock: int) -> np.ndarray:
        """Indices (in stamp order) of the samples held at ``clock``: arrived, not pruned."""
        stamps, arrivals = self._np()
        arrived = arrivals <= clock
        if not arrived.any():
            return np.empty(0, np.intp)
        newest = stamps[arrived].max()
        return np.flatnonzero(arrived & (stamps + CACHE_NS >= newest))

    def newest(self, clock: int) -> int | None:
        held = self.known(clock)
        return int(self._np()[0][held].max()) if held.size else None

    def first_arrival_from(self, t: int) -> int | None:
        """The earliest arrival of a sample stamped at or after ``t``."""
        stamps, arrivals = self._np()
        later = stamps >= t
        return int(arrivals[later].min()) if later.any() else None

    def at(self, t: int, clock: int) -> tuple[Vec, Quat]:
        held = self.known(clock)
        if held.size == 0:
            raise TfError("no data for the link")
        stamps = self._np()[0][held]
        exact = np.flatnonzero(stamps == t)
        if exact.size:
            return self.values[int(held[exact[-1]])]
        if t < stamps[0]:
            raise TfError("extrapolation into the past")
        if t > stamps[-1]:
            raise TfError("extrapolation into the future")
        k = int(np.searchsorted(stamps, t, side="right"))
        before, after = int(held[k - 1]), int(held[k])
        a, b = self.values[before], self.values[after]
        ratio = _dur_sec(t - self.stamps[before]) / _dur_sec(
            self.stamps[after] - self.stamps[before]
        )
        s = 1.0 - ratio
        xyz = (
            s * a[0][0] + ratio * b[0][0],
            s * a[0][1] + ratio * b[0][1],
            s * a[0][2] + ratio * b[0][2],
        )
        return xyz, _slerp(a[1], b[1], ratio)


@dataclass
class Buffer:
    """The listener's buffer: links by child frame."""

    links: dict[str, Link] = field(default_factory=dict)

    def add(
        self, parent: str, child: str, stamp: int, arrival: int, value: tuple[Vec, Quat]
    ) -> None:
        name = frame(child)
        link = self.links.get(name)
        if link is None:
            link = self.links[name] = Link(frame(parent))
        if link.parent != frame(parent):
            # tf2 re-parents a frame to its latest parent; the scripts never do this.
            raise ValueError(f"frame {child} under two parents")
        link.add(stamp, arrival, value)

    def _chain(self, name: str) -> list[str]:
        out = [frame(name)]
        while out[-1] in self.links:
            out.append(self.links[out[-1]].parent)
            if len(out) > 64:
                raise ValueError("tf loop")
        return out

    def _path(self, target: str, source: str) -> tuple[list[str], list[str]]:
        """Frames whose links lead from ``source`` and from ``target`` to a common ancestor."""
        up_s, up_t = self._chain(source), self._chain(target)
        common = next((f for f in up_s if f in up_t), None)
        if common is None:
            raise TfError(f"{target} and {source} are not connected")
        return up_s[: up_s.index(common)], up_t[: up_t.index(common)]

    def latest_common_time(self, target: str, source: str, clock: int) -> int:
        links_s, links_t = self._path(target, source)
        newest = [self.links[f].newest(clock) for f in links_s + links_t]
        if any(n is None for n in newest):
            raise TfError("a link has no data")
        return min(n for n in newest if n is not None) if newest else 0

    def lookup(self, target: str, source: str, t: int, clock: int) -> tuple[Vec, Quat]:
        """Pose of ``source`` in ``target`` at ``t`` (0: latest common time), data held at
        ``clock``."""
        when = self.latest_common_time(target, source, clock) if t == 0 else t
        links_s, links_t = self._path(target, source)
        pose_s = IDENTITY
        for f in reversed(links_s):
            pose_s = compose(pose_s, self.links[f].at(when, clock))
        pose_t = IDENTITY
        for f in reversed(links_t):
            pose_t = compose(pose_t, self.links[f].at(when, clock))
        return compose(invert(pose_t), pose_s)

    def can_transform(self, target: str, source: str, t: int, clock: int) -> bool:
        try:
            self.lookup(target, source, t, clock)
        except TfError:
            return False
        return True

    def ready_at(self, target: str, source: str, t: int, clock: int, until: int) -> int | None:
        """When a wait from ``clock`` for ``t`` returns: the moment the last link got a sample
        stamped at or after ``t`` (or ``clock``), if that is at most ``until`` and ``t`` can be
        looked up then; else None."""
        try:
            links_s, links_t = self._path(target, source)
        except TfError:
            return None
        firsts = [self.links[f].first_arrival_from(t) for f in links_s + links_t]
        if any(m is None for m in firsts):
            return None
        ready = max([clock, *(m for m in firsts if m is not None)])
        if ready > until or not self.can_transform(target, source, t, ready):
            return None
        return ready
