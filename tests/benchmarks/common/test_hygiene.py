"""The repeated-pose tests of ertools.benchmarks.common.hygiene, each against a hand-made stream
whose repeats are known, and against the plain ``np.all(a == b, axis=1)`` they replace."""

from __future__ import annotations

import math
import warnings
from unittest.mock import patch

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from ertools.benchmarks.common import hygiene
from ertools.benchmarks.common.hygiene import (
    _all_valid,
    drop_duplicates,
    drop_invalid,
    drop_repeats,
    identical_poses,
    impossible_samples,
    impossible_warning,
    repeated_positions,
    rows_equal,
    same_rows,
)
from ertools.benchmarks.common.validity import FAR, JUMP, sample_codes
from ertools.streams import PoseStream

T0 = 1_448_013_600 * 1_000_000_000
DT = 8_333_333  # 120 Hz


def _stream() -> PoseStream:
    """Ten poses: 3 repeats 2 exactly (tracking lost), 5 repeats 4's position with a turned
    orientation, 8 repeats 7 exactly with the same stamp (recorded twice)."""
    t = T0 + DT * np.arange(10, dtype=np.int64)
    t[8] = t[7]
    xyz = np.column_stack([np.arange(10.0), np.zeros(10), np.ones(10)])
    quat = np.tile([0.0, 0.0, 0.0, 1.0], (10, 1))
    xyz[3] = xyz[2]
    xyz[5] = xyz[4]
    quat[5] = [0.0, 0.0, np.sin(0.05), np.cos(0.05)]
    xyz[8] = xyz[7]
    return PoseStream(t, xyz, quat)


def test_repeats_by_hand() -> None:
    s = _stream()
    # repeated_positions[k] says whether pose k+1 repeats pose k.
    assert np.flatnonzero(repeated_positions(s)).tolist() == [2, 4, 7]
    assert np.flatnonzero(identical_poses(s)).tolist() == [2, 7]  # 5 turned: not identical
    kept = drop_repeats(s)
    assert len(kept) == 7 and not np.isin(s.t_ns[[3, 5]], kept.t_ns).any()
    once, dropped = drop_duplicates(s)  # only 8: same stamp and pose as 7
    assert dropped == 1 and len(once) == 9
    assert np.array_equal(np.delete(s.t_ns, 8), once.t_ns)


def test_a_repeat_needs_all_three_coordinates_equal() -> None:
    """x repeating alone is no repeat; -0.0 equals 0.0 and NaN equals nothing (IEEE)."""
    nan = np.nan
    xyz = np.array(
        [
            [1.0, 2.0, 3.0],
            [1.0, 2.0, 4.0],  # z moved
            [1.0, 5.0, 4.0],  # y moved
            [1.0, 5.0, 4.0],  # repeat of 2
            [-0.0, 5.0, 4.0],
            [0.0, 5.0, 4.0],  # repeat of 4
            [0.0, nan, 4.0],
            [0.0, nan, 4.0],
            [nan, 1.0, 1.0],
            [nan, 1.0, 1.0],
        ]
    )
    t = np.arange(10, dtype=np.int64) * 8_333_333
    s = PoseStream(t, xyz, np.tile([0.0, 0.0, 0.0, 1.0], (10, 1)))
    assert np.flatnonzero(repeated_positions(s)).tolist() == [2, 4]


def test_short_streams_have_no_repeats() -> None:
    s = _stream()
    one = s.take(slice(0, 1))
    assert repeated_positions(one).shape == (0,) and identical_poses(one).shape == (0,)
    assert drop_repeats(one) is one and drop_duplicates(one) == (one, 0)


def test_rows_equal_is_np_all_including_nan() -> None:
    rng = np.random.default_rng(7)
    a = rng.integers(0, 2, size=(500, 4)).astype(float)
    b = rng.integers(0, 2, size=(500, 4)).astype(float)
    a[::17, 1] = np.nan
    b[::17, 1] = np.nan  # NaN equals nothing, itself included: never a repeat
    assert np.array_equal(rows_equal(a, b), np.all(a == b, axis=1))
    i = rng.integers(0, 500, size=300)
    j = rng.integers(0, 500, size=300)
    assert np.array_equal(same_rows(a, i, j), np.all(a[i] == a[j], axis=1))


# --- physically impossible samples (issue 36, finding 5) ------------------------------------


def _walk(n: int, speed: float, dt: int = DT, seed: int = 3) -> tuple[np.ndarray, np.ndarray]:
    """``n`` samples of a body driving along x at ``speed`` m/s, with 1 mm of mocap noise."""
    t = T0 + dt * np.arange(n, dtype=np.int64)
    rng = np.random.default_rng(seed)
    x = speed * (t - T0) / 1e9
    xyz = np.column_stack([x, np.zeros(n), np.zeros(n)]) + rng.normal(0, 0.001, (n, 3))
    return t, xyz


def test_a_fast_robot_is_possible() -> None:
    """4 m/s (over twice the fastest robot of the leagues), 120 Hz, with noise: nothing."""
    t, xyz = _walk(1200, 4.0)
    found = impossible_samples(t, xyz)
    assert found.count == 0 and found.steps == ()


def test_a_one_frame_spike_of_one_metre_is_a_jump() -> None:
    t, xyz = _walk(1200, 0.5)
    xyz[600, 1] += 1.0
    found = impossible_samples(t, xyz)
    assert np.flatnonzero(found.jump).tolist() == [600] and not found.far.any()
    assert found.steps == ()


def test_an_excursion_and_the_repeats_inside_it_are_left_out() -> None:
    """Mistaken for another body for 0.3 s (36 frames), Motive re-sending its pose 5 times
    there: all 36 out; the way back lands where the body had got to, so the rest stays."""
    t, xyz = _walk(1200, 0.5)
    xyz[500:536] += np.array([3.0, -2.0, 0.0])
    xyz[510:515] = xyz[509]
    found = impossible_samples(t, xyz)
    assert np.flatnonzero(found.jump).tolist() == list(range(500, 536))


def test_a_step_that_stays_is_said_not_dropped() -> None:
    """Half the log 2 m away from the other half: which half is wrong cannot be told."""
    t, xyz = _walk(1200, 0.2)
    xyz[700:] += np.array([0.0, 2.0, 0.0])
    found = impossible_samples(t, xyz)
    assert found.count == 0
    assert len(found.steps) == 1 and found.steps[0].t_ns == int(t[700])
    # 2 m in one frame: 240 m/s; by hand 2 + 0.2/120 along x (the hypotenuse) ~ 2.0000007
    assert abs(found.steps[0].distance_m - 2.0) < 0.01
    assert abs(found.steps[0].speed_m_s - found.steps[0].distance_m * 120) < 1.0


def test_tracking_regained_after_a_loss_is_no_jump() -> None:
    """Motive repeats the last pose while the body is lost (1 s, moving 0.5 m meanwhile); the
    first new pose is 0.5 m from the repeats one frame later, but 1 s after the last
    measurement: 0.5 m/s."""
    t, xyz = _walk(1200, 0.5)
    xyz[400:520] = xyz[399]
    assert impossible_samples(t, xyz).count == 0


def test_stamp_jitter_is_no_jump() -> None:
    """Two samples 10 microseconds apart (a logger's burst), 2 mm apart: 200 m/s by their
    stamps, but below JUMP_MIN_M and measured over at least a frame period."""
    t, xyz = _walk(1200, 0.2)
    t[301] = t[300] + 10_000
    assert impossible_samples(t, xyz).count == 0


def test_far_and_beyond_any_frame() -> None:
    t, xyz = _walk(1200, 0.2)
    xyz[10] = [1e300, 0.0, 0.0]
    xyz[20] = [0.0, 5000.0, 0.0]
    xyz[30] = [np.nan, 0.0, 0.0]  # not finite: invalid already, neither far nor a jump
    found = impossible_samples(t, xyz)
    assert np.flatnonzero(found.far).tolist() == [10, 20]
    assert not found.jump.any()


def test_a_frame_far_from_its_origin_is_possible() -> None:
    """A consistent stream 4e6 m from its origin (a UTM frame): the median is there too."""
    t, xyz = _walk(1200, 0.5)
    assert impossible_samples(t, xyz + np.array([4e6, 5e6, 0.0])).count == 0


def test_a_robot_estimate_may_jump() -> None:
    t, xyz = _walk(120, 0.5, dt=100_000_000)  # 10 Hz
    xyz[60, 0] += 1.0
    assert impossible_samples(t, xyz, jumps=False).count == 0
    assert impossible_samples(t, xyz).count == 1


def test_drop_invalid_and_the_validity_codes_agree() -> None:
    t, xyz = _walk(1200, 0.5)
    xyz[100] = [1e300, 0, 0]
    xyz[600, 1] += 1.0
    quat = np.tile([0.0, 0.0, 0.0, 1.0], (1200, 1))
    kept, dropped = drop_invalid(PoseStream(t, xyz, quat))
    assert dropped == 2 and len(kept) == 1198
    codes = sample_codes(t, xyz, quat).codes
    assert codes[100] == FAR and codes[600] == JUMP and int(np.count_nonzero(codes)) == 2


def test_impossible_samples_found_once_serve_the_warning_and_the_drop() -> None:
    """What the trajectory benchmark does with an hour of GT: the impossible samples found
    once, given to both; the same warning and the same stream as each finding them again."""
    t, xyz = _walk(1200, 0.5)
    xyz[100] = [1e300, 0, 0]  # every value finite: found column by column
    xyz[600, 1] += 1.0
    stream = PoseStream(t, xyz, np.tile([0.0, 0.0, 0.0, 1.0], (1200, 1)), source="gt")
    found = impossible_samples(t, xyz)
    assert np.flatnonzero(found.far).tolist() == [100]
    assert np.flatnonzero(found.jump).tolist() == [600]
    warning = impossible_warning(stream, found=found)
    assert warning is not None and warning == impossible_warning(stream)
    kept, dropped = drop_invalid(stream, found=found)
    again, dropped_again = drop_invalid(stream)
    assert dropped == dropped_again == 2
    assert np.array_equal(kept.t_ns, again.t_ns) and np.array_equal(kept.xyz, again.xyz)
    assert np.array_equal(kept.t_ns, np.delete(t, [100, 600]))


def test_the_all_valid_shortcut_decides_nothing_near_the_limits() -> None:
    """Quaternions near the shortcut's limits (squared norms 1e-17 and 1e300) and one whose
    squares overflow go to the exact test (a norm above 1e-9 whose square is finite),
    silently; its answer is the one kept. One well inside (1e149) takes the shortcut."""
    base = _stream()
    cases = ((1e-150, 1, False), (3e-9, 0, False), (1e149, 0, True), (1e151, 0, False))
    for scale, dropped, shortcut in (*cases, (1e200, 1, False)):
        quat = base.quat_xyzw.copy()
        quat[6] *= scale
        stream = PoseStream(base.t_ns, base.xyz, quat)
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            assert _all_valid(stream) == shortcut
            kept, count = drop_invalid(stream, jumps=False)
        with np.errstate(over="ignore"):
            norm = math.sqrt(float(np.sum(quat[6] ** 2)))
        assert count == dropped == int(not (math.isfinite(norm) and norm > 1e-9))
        assert len(kept) == 10 - dropped
    assert _all_valid(base)


def test_bounded_means_every_coordinate_finite_and_drop_invalid_agrees() -> None:
    """``Impossible.bounded`` (drop_invalid then skips the positions' finiteness) is set only
    where the bounds pass saw every coordinate finite and within MAX_COORD_M; with or without
    ``found``, drop_invalid drops the same samples, NaN and infinite positions included."""
    t, xyz = _walk(1200, 0.5)
    quat = np.tile([0.0, 0.0, 0.0, 1.0], (1200, 1))
    cases = {"clean": None, "nan": np.nan, "inf": np.inf, "-inf": -np.inf, "huge": 2e8}
    for name, bad in cases.items():
        pos = xyz.copy()
        if bad is not None:
            pos[700, 2] = bad
        found = impossible_samples(t, pos)
        assert found.bounded == (name == "clean")
        assert found.bounded == bool(np.isfinite(pos).all() and np.abs(pos).max() <= 1e8)
        stream = PoseStream(t, pos, quat)
        kept, dropped = drop_invalid(stream, found=found)
        plain, dropped_plain = drop_invalid(stream)
        assert dropped == dropped_plain == (0 if bad is None else 1)
        assert np.array_equal(kept.t_ns, plain.t_ns)
        assert len(kept) == 1200 - dropped


@settings(max_examples=300, deadline=None)
@given(
    st.integers(2, 60),
    st.integers(0, 2**32 - 1),
    st.sampled_from([0.0, 0.05, 0.3, 2.0, 50.0]),
    st.sampled_from([0.0, 0.2, 0.5]),
    st.booleans(),
)
def test_the_slow_steps_shortcut_finds_what_the_exact_test_finds(
    n: int, seed: int, leap_m: float, repeat_share: float, shuffle: bool
) -> None:
    """Streams whose rows move far between some rows (leaps, tracking gaps of any length,
    equal stamps, repeats, stamps out of order): impossible_samples with its shortcuts finds
    the same far samples, jumps and steps as its exact test alone (the shortcut taken or not),
    and says bounded only when it took one."""
    rng = np.random.default_rng(seed)
    dt = rng.choice([0, DT, DT, DT, 3 * DT, 60 * DT, 10**9, 30 * 10**9], size=n)
    t = T0 + np.cumsum(dt).astype(np.int64)
    if shuffle:
        t[rng.integers(0, n)] -= 2 * DT
    xyz = np.cumsum(rng.normal(0.0, 0.01, (n, 3)), axis=0)
    leaps = rng.random(n) < 0.2
    xyz += np.cumsum(leaps[:, None] * rng.normal(0.0, leap_m, (n, 3)), axis=0)
    for i in np.flatnonzero(rng.random(n) < repeat_share):
        if i:
            xyz[i] = xyz[i - 1]
    for jumps in (True, False):
        found = impossible_samples(t, xyz, jumps=jumps)
        with patch.object(hygiene, "_all_possible", lambda *a, **k: False):
            exact = impossible_samples(t, xyz, jumps=jumps)
        assert np.array_equal(found.far, exact.far) and np.array_equal(found.jump, exact.jump)
        assert found.steps == exact.steps
        assert not exact.bounded
        if found.bounded:
            assert not exact.count and not exact.steps


def test_blocks_far_apart_in_time_take_the_shortcut() -> None:
    """Blocks of a stream taken seconds apart (the noise's blocks) move metres between blocks,
    slowly: no jump, shown without the exact test; a leap within a block is one."""
    t, xyz = _walk(1200, 0.5)
    rows = np.concatenate([np.arange(k, k + 100) for k in (0, 500, 1000)])
    assert impossible_samples(t[rows], xyz[rows]).bounded
    fast = xyz[rows].copy()
    fast[150:] += 1.0  # a 1 m step within the second block: a jump
    found = impossible_samples(t[rows], fast)
    assert not found.bounded and found.steps
