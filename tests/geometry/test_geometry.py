"""Geometry: hand-computed cases and hypothesis properties of SE(3) composition."""

from __future__ import annotations

import math
import subprocess
import sys

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays
from scipy.spatial.transform import Rotation, Slerp

from ertools.geometry import (
    angle_error,
    bracket,
    circular_mean,
    compose,
    interpolate_poses,
    invert,
    mean_pose,
    quat_from_yaw,
    row_dot,
    row_norm,
    slerp,
    transform_points,
    unwrap_angles,
    wrap_angle,
    yaw_from_quat,
)
from ertools.streams import PoseStream

finite = st.floats(-10.0, 10.0, allow_nan=False, allow_infinity=False)
vec3 = arrays(np.float64, (3,), elements=finite)
quat = arrays(np.float64, (4,), elements=st.floats(-1, 1)).filter(
    lambda q: float(np.linalg.norm(q)) > 0.1
)


def unit(q: np.ndarray) -> np.ndarray:
    return q / np.linalg.norm(q)


def test_row_norm_by_hand_and_bit_for_bit_numpys_norm() -> None:
    v = np.array([[3.0, 4.0, 0.0], [1.0, 2.0, 2.0], [0.0, 0.0, 0.0]])
    assert row_norm(v).tolist() == [5.0, 3.0, 0.0]
    assert float(row_norm(np.array([1.0, 1.0, 1.0, 1.0]))) == 2.0
    # The scorers' results must not move: the same sums in the same order as numpy's norm.
    rng = np.random.default_rng(3)
    for k in (3, 4):
        a = rng.normal(size=(5000, k)) * 10 ** rng.uniform(-3, 3, (5000, 1))
        assert np.array_equal(row_norm(a), np.linalg.norm(a, axis=1))
        assert np.array_equal(row_norm(a[::3]), np.linalg.norm(a[::3], axis=1))


def test_row_dot_by_hand_and_bit_for_bit_numpys_sum() -> None:
    a = np.array([[1.0, 2.0, 3.0], [0.5, -1.0, 4.0]])
    b = np.array([[4.0, 5.0, 6.0], [2.0, 2.0, 0.25]])
    assert row_dot(a, b).tolist() == [32.0, 0.0]
    rng = np.random.default_rng(5)
    for k in (3, 4):
        x = rng.normal(size=(5000, k)) * 10 ** rng.uniform(-3, 3, (5000, 1))
        y = rng.normal(size=(5000, k))
        assert np.array_equal(row_dot(x, y), np.sum(x * y, axis=1))


def test_bracket_by_hand_and_against_both_binary_searches() -> None:
    t = np.array([0, 10, 10, 20], dtype=np.int64)
    q = np.array([-5, 0, 5, 10, 15, 20, 25], dtype=np.int64)
    lo, hi = bracket(t, q)
    # An exact hit on the doubled stamp 10: lo is the last sample at it, hi the first.
    assert lo.tolist() == [-1, 0, 0, 2, 2, 3, 3]
    assert hi.tolist() == [0, 0, 1, 1, 3, 3, 4]
    rng = np.random.default_rng(4)
    t = np.sort(rng.integers(0, 500, 300))
    q = np.concatenate([rng.integers(-10, 510, 400), t[::7]])
    right = np.searchsorted(t, q, side="right")
    for lo, hi in (bracket(t, q), bracket(t, q, right)):
        assert np.array_equal(lo, right - 1)
        assert np.array_equal(hi, np.searchsorted(t, q, side="left"))
    assert np.array_equal(right, np.searchsorted(t, q, side="right"))  # left as it was


def test_compose_by_hand() -> None:
    # Frame b sits at (1, 0, 0) in a, rotated +90 deg about z; c sits at (1, 0, 0) in b.
    # So c is at (1, 1, 0) in a, rotated +90 deg like b.
    t, q = compose(
        np.array([1.0, 0, 0]), quat_from_yaw(math.pi / 2), np.array([1.0, 0, 0]), quat_from_yaw(0.0)
    )
    np.testing.assert_allclose(t, [1.0, 1.0, 0.0], atol=1e-12)
    assert float(yaw_from_quat(q)) == pytest.approx(math.pi / 2, abs=1e-12)


def test_invert_by_hand() -> None:
    t, q = invert(np.array([2.0, 0, 0]), quat_from_yaw(math.pi / 2))
    # The inverse maps a's origin into b: rotate (-2, 0, 0) by -90 deg -> (0, 2, 0).
    np.testing.assert_allclose(t, [0.0, 2.0, 0.0], atol=1e-12)
    assert float(yaw_from_quat(q)) == pytest.approx(-math.pi / 2)


@pytest.mark.slow
@settings(max_examples=60, deadline=None)
@given(vec3, quat)
def test_compose_with_inverse_is_identity(t: np.ndarray, q: np.ndarray) -> None:
    q = unit(q)
    ti, qi = invert(t, q)
    t0, q0 = compose(t, q, ti, qi)
    np.testing.assert_allclose(t0, 0.0, atol=1e-9)
    assert abs(abs(q0[3]) - 1.0) < 1e-9


@pytest.mark.slow
@settings(max_examples=60, deadline=None)
@given(vec3, quat, vec3, quat, vec3, quat)
def test_compose_is_associative(
    t1: np.ndarray, q1: np.ndarray, t2: np.ndarray, q2: np.ndarray, t3: np.ndarray, q3: np.ndarray
) -> None:
    q1, q2, q3 = unit(q1), unit(q2), unit(q3)
    ta, qa = compose(*compose(t1, q1, t2, q2), t3, q3)
    tb, qb = compose(t1, q1, *compose(t2, q2, t3, q3))
    np.testing.assert_allclose(ta, tb, atol=1e-9)
    # q and -q are the same rotation.
    assert min(np.abs(qa - qb).max(), np.abs(qa + qb).max()) < 1e-9


@pytest.mark.slow
@settings(max_examples=60, deadline=None)
@given(vec3, quat, vec3)
def test_transform_points_matches_compose(t: np.ndarray, q: np.ndarray, p: np.ndarray) -> None:
    q = unit(q)
    tp, _ = compose(t, q, p, np.array([0.0, 0, 0, 1]))
    np.testing.assert_allclose(transform_points(t, q, p), tp, atol=1e-9)


@pytest.mark.slow
@settings(max_examples=100, deadline=None)
@given(st.floats(-50, 50, allow_nan=False), st.floats(-50, 50, allow_nan=False))
def test_angle_error_in_range_and_symmetric(a: float, b: float) -> None:
    e = float(angle_error(a, b))
    assert 0.0 <= e <= math.pi + 1e-12
    assert e == pytest.approx(float(angle_error(b, a)), abs=1e-9)
    # Equal to the smallest rotation between the headings.
    assert math.cos(e) == pytest.approx(math.cos(a - b), abs=1e-9)


def test_angle_error_across_the_seam() -> None:
    # 179 deg vs -179 deg are 2 deg apart, not 358.
    assert float(angle_error(math.radians(179), math.radians(-179))) == pytest.approx(
        math.radians(2)
    )
    assert float(wrap_angle(3 * math.pi / 2)) == pytest.approx(-math.pi / 2)


def test_circular_mean_by_hand() -> None:
    assert circular_mean(np.radians([350.0, 10.0])) == pytest.approx(0.0, abs=1e-12)
    assert circular_mean(np.array([0.1, 0.3])) == pytest.approx(0.2, abs=1e-12)


@settings(max_examples=60, deadline=None)
@given(st.floats(-math.pi + 1e-6, math.pi - 1e-6))
def test_yaw_round_trip(yaw: float) -> None:
    assert float(yaw_from_quat(quat_from_yaw(yaw))) == pytest.approx(yaw, abs=1e-12)


def _stream() -> PoseStream:
    t = np.array([0, 10, 20, 40], dtype=np.int64)
    xyz = np.array([[0.0, 0, 0], [1, 0, 0], [1, 1, 0], [1, 1, 2]])
    q = quat_from_yaw(np.array([0.0, 0.0, math.pi / 2, math.pi / 2]))
    return PoseStream(t, xyz, q, "world", "body")


def test_interpolate_linear_slerp_by_hand() -> None:
    res = interpolate_poses(_stream(), np.array([5, 15, 30, 20, -5, 50], dtype=np.int64))
    np.testing.assert_allclose(res.xyz[0], [0.5, 0, 0])
    np.testing.assert_allclose(res.xyz[1], [1, 0.5, 0])
    assert float(yaw_from_quat(res.quat_xyzw[1])) == pytest.approx(math.pi / 4)
    np.testing.assert_allclose(res.xyz[2], [1, 1, 1])
    np.testing.assert_allclose(res.xyz[3], [1, 1, 0])  # exact hit
    assert res.gap_ns.tolist()[:4] == [10, 10, 20, 0]
    assert res.inside.tolist() == [True, True, True, True, False, False]


def test_interpolate_hold_and_nearest() -> None:
    q = np.array([14, 16, 39], dtype=np.int64)
    hold = interpolate_poses(_stream(), q, "hold")
    np.testing.assert_allclose(hold.xyz, [[1, 0, 0], [1, 0, 0], [1, 1, 0]])
    nearest = interpolate_poses(_stream(), q, "nearest")
    np.testing.assert_allclose(nearest.xyz, [[1, 0, 0], [1, 1, 0], [1, 1, 2]])


def test_mean_pose_spread() -> None:
    xyz = np.array([[1.0, 0, 0], [-1.0, 0, 0]])
    q = quat_from_yaw(np.array([0.1, -0.1]))
    m = mean_pose(xyz, q)
    np.testing.assert_allclose(m.xyz, 0.0, atol=1e-12)
    assert m.position_std == pytest.approx(1.0)
    assert float(yaw_from_quat(m.quat_xyzw)) == pytest.approx(0.0, abs=1e-12)
    assert m.angle_std == pytest.approx(0.1, abs=1e-9)


def test_compose_accepts_read_only_inputs() -> None:
    q = np.broadcast_to(quat_from_yaw(math.pi / 2), (3, 4))
    t = np.broadcast_to(np.array([1.0, 0, 0]), (3, 3))
    tc, _ = compose(t, q, t, q)
    np.testing.assert_allclose(tc, np.tile([1.0, 1.0, 0.0], (3, 1)), atol=1e-12)
    ti, _ = invert(t, q)
    np.testing.assert_allclose(ti, np.tile([0.0, 1.0, 0.0], (3, 1)), atol=1e-12)


@pytest.mark.slow
@settings(max_examples=80, deadline=None)
@given(vec3, quat, vec3, quat)
def test_numpy_compose_matches_scipy(
    t1: np.ndarray, q1: np.ndarray, t2: np.ndarray, q2: np.ndarray
) -> None:
    t, q = compose(t1, q1, t2, q2)
    r1, r2 = Rotation.from_quat(q1), Rotation.from_quat(q2)
    np.testing.assert_allclose(t, t1 + r1.apply(t2), atol=1e-9)
    expected = (r1 * r2).as_quat()
    assert min(np.abs(q - expected).max(), np.abs(q + expected).max()) < 1e-9


@pytest.mark.slow
@settings(max_examples=80, deadline=None)
@given(quat, quat, st.floats(0.0, 1.0))
def test_slerp_matches_scipy(q0: np.ndarray, q1: np.ndarray, alpha: float) -> None:
    # rotations exactly pi apart (orthogonal quaternions) have two shortest arcs, and either
    # library may take either: no answer to compare (a real pose pair 1/120 s apart never is)
    assume(abs(float(np.dot(unit(q0), unit(q1)))) > 1e-6)
    expected = Slerp([0.0, 1.0], Rotation.from_quat(np.stack([q0, q1])))([alpha]).as_quat()[0]
    got = slerp(q0[None], q1[None], np.array([alpha]))[0]
    assert min(np.abs(got - expected).max(), np.abs(got + expected).max()) < 1e-7


@pytest.mark.slow
def test_geometry_import_does_not_load_scipy() -> None:
    code = "import sys, ertools.geometry; print('scipy.spatial' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"


def _plain_wrap(a: np.ndarray) -> np.ndarray:
    return np.asarray((a + np.pi) % (2.0 * np.pi) - np.pi)


@settings(max_examples=200, deadline=None)
@given(arrays(np.float64, st.integers(0, 40), elements=st.floats(width=64)))
def test_wrap_angle_is_the_remainder_to_the_bit(a: np.ndarray) -> None:
    """wrap_angle divides only the angles outside [-pi, pi): the same bits as the remainder
    of every angle, NaN, infinities, -0 and the bounds included."""
    edges = np.array([0.0, -0.0, np.pi, -np.pi, 2 * np.pi, -2 * np.pi, 3 * np.pi, np.nan])
    edges = np.concatenate([edges, np.nextafter(edges, np.inf), np.nextafter(edges, -np.inf)])
    for values in (a, edges, np.concatenate([a, edges]).reshape(-1, 1)):
        with np.errstate(invalid="ignore"):
            got, want = wrap_angle(values), _plain_wrap(values)
        assert got.shape == want.shape and got.dtype == np.float64
        same = (got == want) & (np.signbit(got) == np.signbit(want))
        assert (same | (np.isnan(got) & np.isnan(want))).all()
    assert float(wrap_angle(4.0)) == float(_plain_wrap(np.float64(4.0)))
    assert wrap_angle(4.0).shape == ()


def _plain_slerp(q0: np.ndarray, q1: np.ndarray, alpha: np.ndarray) -> np.ndarray:
    """slerp as first written: a masked negation and both branches selected by np.where."""
    q0 = q0 / np.linalg.norm(q0, axis=-1)[..., None]
    q1 = q1 / np.linalg.norm(q1, axis=-1)[..., None]
    a = np.asarray(alpha, dtype=np.float64)[..., None]
    dot = np.sum(q0 * q1, axis=-1)[..., None]
    q1 = np.broadcast_to(q1, np.broadcast_shapes(q1.shape, dot.shape)).copy()
    np.negative(q1, out=q1, where=dot < 0.0)
    theta = np.arccos(np.clip(np.abs(dot), -1.0, 1.0))
    sin_theta = np.sin(theta)
    close = sin_theta < 1e-6
    safe = np.where(close, 1.0, sin_theta)
    w0 = np.where(close, 1.0 - a, np.sin((1.0 - a) * theta) / safe)
    w1 = np.where(close, a, np.sin(a * theta) / safe)
    mixed = w0 * q0 + w1 * q1
    return np.asarray(mixed / np.linalg.norm(mixed, axis=-1)[..., None])


@settings(max_examples=100, deadline=None)
@given(
    arrays(np.float64, (12, 4), elements=st.floats(-1, 1)),
    arrays(np.float64, (12, 4), elements=st.floats(-1e-7, 1e-7)),
    arrays(np.float64, (12,), elements=st.floats(0, 1)),
    st.integers(0, 2**12 - 1),
    st.integers(0, 2**12 - 1),
)
def test_slerp_is_the_plain_version_to_the_bit(
    q0: np.ndarray, nudge: np.ndarray, alpha: np.ndarray, flips: int, near: int
) -> None:
    """slerp negates only the rows on the other hemisphere and selects the near-pair branch
    only when there is one: the same bits as the plain version, on pairs far apart, nearly
    equal (within 1e-6 rad) or equal, on either hemisphere, and broadcast."""
    assume(bool((np.linalg.norm(q0, axis=1) > 0.1).all()))
    rows = np.arange(12)
    q1 = np.where(((near >> rows) & 1)[:, None] == 1, q0 + nudge, q0[::-1])
    q1 = np.where(((flips >> rows) & 1)[:, None] == 1, -q1, q1)
    assume(bool((np.linalg.norm(q1, axis=1) > 0.1).all()))
    for args in ((q0, q1, alpha), (q0[0], q1, alpha), (q0, q1[3], alpha[5]), (q0[2], q1[2], 0.3)):
        got, want = slerp(*args), _plain_slerp(*args)
        assert got.shape == want.shape
        assert np.array_equal(got, want)


@settings(max_examples=200, deadline=None)
@given(
    arrays(np.float64, st.integers(0, 40), elements=st.floats(-20.0, 20.0)),
    arrays(np.float64, st.integers(0, 40), elements=st.floats(width=64)),
)
def test_unwrap_angles_is_numpys_to_the_bit(small: np.ndarray, anything: np.ndarray) -> None:
    """unwrap_angles skips the remainders np.unwrap discards: the same bits as np.unwrap on
    tracks with steps below, at and above pi, NaN and infinities included."""
    track = np.concatenate([small, np.cumsum(np.full(5, np.pi)), [0.0, np.pi, 0.0, -np.pi]])
    for values in (small, anything, track, np.array([1.0]), np.zeros(0)):
        with np.errstate(invalid="ignore"):
            got, want = unwrap_angles(values), np.unwrap(values)
        assert got.dtype == want.dtype and got.shape == want.shape
        same = (got == want) & (np.signbit(got) == np.signbit(want))
        assert (same | (np.isnan(got) & np.isnan(want))).all()
