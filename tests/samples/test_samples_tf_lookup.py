"""The simulator's model of the RSBB scripts' tf lookups (``ertools.simulator.tf_lookup``):
planar cases worked out by hand, and agreement with the replays' independent tf2 buffer
(``tests/helpers/rsbb_replay/tf2.py``) on random rotations."""

from __future__ import annotations

import math

import numpy as np
import pytest

from ertools.simulator.tf_lookup import Link, lookup
from tests.helpers.rsbb_replay.tf2 import Buffer

S = 1_000_000_000
T = 1_555_000_000 * S


def _q(yaw: float) -> tuple[float, float, float, float]:
    return (0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2))


def _link(rows: list[tuple[int, float, float, float, float]]) -> Link:
    """Samples (stamp, x, y, z, yaw)."""
    return Link(
        np.array([r[0] for r in rows], np.int64),
        np.array([[r[1], r[2], r[3]] for r in rows]),
        np.array([_q(r[4]) for r in rows]),
    )


FIXED = ((0.1, 0.05, -0.4), _q(-0.3))


def test_a_sample_stamped_at_the_moment_composed_with_the_fixed_frame() -> None:
    body = _link([(T, 1.0, 2.0, 0.4, 0.5), (T + 10 * S, 9.0, 9.0, 9.0, 2.0)])
    got = lookup(body, T, FIXED)
    # planar: (1, 2) + R(0.5) (0.1, 0.05); z 0.4 - 0.4; yaw 0.5 - 0.3
    c, s = math.cos(0.5), math.sin(0.5)
    assert got.xyz == pytest.approx((1.0 + 0.1 * c - 0.05 * s, 2.0 + 0.1 * s + 0.05 * c, 0.0))
    assert got.yaw == pytest.approx(0.2, abs=1e-12)


def test_between_two_samples_linear_position_and_slerped_yaw() -> None:
    body = _link([(T, 0.0, 0.0, 0.0, 0.2), (T + 8 * S // 1000, 0.8, -0.4, 0.0, 0.6)])
    identity = ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0))
    got = lookup(body, T + 2 * S // 1000, identity)  # a quarter of the way
    assert got.xyz == pytest.approx((0.2, -0.1, 0.0), abs=1e-12)
    assert got.yaw == pytest.approx(0.3, abs=1e-12)  # slerp about one axis: angles linear


def test_the_shortest_way_round_across_pi() -> None:
    # yaw 3.0 and -3.0 (the second stored with the opposite sign): half way is pi, not 0
    q2 = tuple(-v for v in _q(-3.0))
    body = Link(
        np.array([T, T + S], np.int64),
        np.zeros((2, 3)),
        np.array([_q(3.0), q2]),
    )
    got = lookup(body, T + S // 2, ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0)))
    assert abs(got.yaw) == pytest.approx(math.pi, abs=1e-12)


def test_in_another_bodys_frame() -> None:
    # a table at (1, 2) turned 0.4; a positioner on it; an item 0.14 m behind, turned -pi/4
    table = _link([(T, 1.0, 2.0, 0.75, 0.4), (T + S, 1.0, 2.0, 0.75, 0.4)])
    c, s = math.cos(0.4), math.sin(0.4)
    px, py, pyaw = 0.3, 0.4, 0.2  # on the table
    world = (1.0 + c * px - s * py, 2.0 + s * px + c * py)
    positioner = _link(
        [(T, world[0], world[1], 0.77, 0.4 + pyaw), (T + S, world[0], world[1], 0.77, 0.4 + pyaw)]
    )
    got = lookup(positioner, T + S // 3, ((-0.14, 0.0, 0.0), _q(-math.pi / 4)), table)
    want = (px - 0.14 * math.cos(pyaw), py - 0.14 * math.sin(pyaw), pyaw - math.pi / 4)
    assert got.xyz[:2] == pytest.approx(want[:2], abs=1e-12)
    assert got.xyz[2] == pytest.approx(0.02, abs=1e-12)
    assert got.yaw == pytest.approx(want[2], abs=1e-12)


def test_outside_the_samples_is_refused() -> None:
    body = _link([(T, 0.0, 0.0, 0.0, 0.0), (T + S, 0.0, 0.0, 0.0, 0.0)])
    with pytest.raises(ValueError, match="outside"):
        lookup(body, T - 1, FIXED)
    with pytest.raises(ValueError, match="outside"):
        lookup(body, T + S + 1, FIXED)
    assert lookup(body, T + S, FIXED).yaw == pytest.approx(-0.3)  # the last stamp itself


def _random_link(rng: np.random.Generator, stamps: np.ndarray) -> Link:
    q = rng.normal(size=(len(stamps), 4))
    q /= np.linalg.norm(q, axis=1)[:, None]
    return Link(stamps, rng.normal(size=(len(stamps), 3)), q)


def test_agrees_with_the_replays_tf2_buffer() -> None:
    rng = np.random.default_rng(7)
    stamps = T + np.cumsum(rng.integers(7_000_000, 9_500_000, 60)).astype(np.int64)
    body, ref = _random_link(rng, stamps), _random_link(rng, stamps)
    fixed_q = rng.normal(size=4)
    fixed_q /= np.linalg.norm(fixed_q)
    qx, qy, qz, qw = (float(v) for v in fixed_q)
    fixed = ((0.1, -0.2, 0.3), (qx, qy, qz, qw))
    moments = np.sort(rng.integers(int(stamps[0]), int(stamps[-1]), 40)).tolist()
    buf = Buffer()
    clock = int(stamps[-1])
    for k, t in enumerate(stamps.tolist()):
        buf.add("root", "body", t, t, (tuple(body.xyz[k]), tuple(body.quat_xyzw[k])))
        buf.add("root", "ref", t, t, (tuple(ref.xyz[k]), tuple(ref.quat_xyzw[k])))
    for t in moments:
        buf.add("body", "frame", t, t, fixed)
        for target, reference in (("root", None), ("ref", ref)):
            xyz, quat = buf.lookup(target, "frame", t, clock)
            got = lookup(body, t, fixed, reference)
            assert got.xyz == pytest.approx(xyz, abs=1e-12)
            assert got.quat == pytest.approx(quat, abs=1e-12)
