"""Hand-built timelines for the replays' own tests: bodies held still (or moved) at known poses,
sampled at 100 Hz and arriving 1 ms after their stamps, so that every number is known."""

from __future__ import annotations

import math
from collections.abc import Callable

from tests.helpers.rsbb_replay.tf2 import Buffer, Quat, Vec

S = 1_000_000_000
MS = 1_000_000
T0 = 1_500_000_000 * S
PERIOD = 10 * MS


def yaw_quat(yaw: float) -> Quat:
    """The rotation about z by ``yaw`` (exact for 0 and pi)."""
    if yaw == 0.0:
        return (0.0, 0.0, 0.0, 1.0)
    if yaw == math.pi:
        return (0.0, 0.0, 1.0, 0.0)
    return (0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2))


def body(
    buf: Buffer,
    name: str,
    pose: Callable[[int], tuple[Vec, Quat]],
    start: int = T0,
    end: int = T0 + 100 * S,
    gaps: tuple[tuple[int, int], ...] = (),
    parent: str = "testbed_origin",
) -> None:
    """Samples of ``name`` every 10 ms from ``start`` to ``end`` (none inside the ``gaps``);
    the default span, 100 s, holds the hand-built runs."""
    t = start
    while t <= end:
        if not any(a <= t < b for a, b in gaps):
            buf.add(parent, name, t, t + MS, pose(t))
        t += PERIOD


def still(xyz: Vec, yaw: float = 0.0) -> Callable[[int], tuple[Vec, Quat]]:
    """A body that does not move."""
    value = (xyz, yaw_quat(yaw))
    return lambda _t: value


def steps(*pieces: tuple[int, Vec, float]) -> Callable[[int], tuple[Vec, Quat]]:
    """A body at ``pieces[k]``'s pose from its time on (times ascending)."""

    def pose(t: int) -> tuple[Vec, Quat]:
        current = pieces[0]
        for piece in pieces:
            if piece[0] <= t:
                current = piece
        return current[1], yaw_quat(current[2])

    return pose
