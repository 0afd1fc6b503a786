"""ertools.benchmarks.common.motion: still-phase detection on synthetic streams with
hand-computed phases.

All streams are sampled at 10 Hz (100 ms, exact in ns) unless said, so the window ends are
whole samples and the expected phases follow from the motion by hand (worked out in each
test). The speeds on either side of every threshold differ from it by 25 % or more, so the
index/time assertions are exact: no float tolerance is needed.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from ertools.benchmarks.common.motion import (
    rotation_angle,
    runs_mask,
    sample_half_window,
    still_intervals,
    still_mask,
    still_runs,
)
from ertools.geometry import quat_from_yaw
from ertools.streams import Interval

MS = 1_000_000  # ns
STEP = 100 * MS  # 10 Hz


def _ramp(t_s: np.ndarray, t0: float, t1: float, rate: float) -> np.ndarray:
    """0 before t0, rate * (t - t0) during [t0, t1], constant after."""
    return rate * (np.clip(t_s, t0, t1) - t0)


def _stop_go_stop() -> tuple[np.ndarray, np.ndarray]:
    """Still at x=0 for 0-2 s, 1 m/s along x for 2-3 s, still at x=1 m for 3-5 s (51 samples)."""
    t = np.arange(51, dtype=np.int64) * STEP
    x = _ramp(t / 1e9, 2.0, 3.0, 1.0)
    return t, np.column_stack([x, np.zeros_like(x)])


def test_still_and_moving_phases_of_a_stop_go_stop_stream() -> None:
    # centred 0.4 s window = samples i-2..i+2. Sample i is still iff its window lies in a still
    # part: i + 2 <= 20 (i <= 18) or i - 2 >= 30 (i >= 32). Sample 19 sees x(2.1) - x(1.7) =
    # 0.1 m over 0.4 s = 0.25 m/s, sample 31 the same: moving against the 0.1 m/s limit.
    t, xy = _stop_go_stop()
    still = still_mask(t, xy, window_s=0.4, speed=0.1)
    expected = np.zeros(51, dtype=bool)
    expected[:19] = True
    expected[32:] = True
    np.testing.assert_array_equal(still, expected)
    runs = still_runs(t, still)
    assert runs == [(0, 18), (32, 50)]
    assert still_intervals(t, runs) == [Interval(0, 1800 * MS), Interval(3200 * MS, 5000 * MS)]
    np.testing.assert_array_equal(runs_mask(runs, 51), expected)


def test_minimum_duration_keeps_or_drops_phases() -> None:
    t, xy = _stop_go_stop()
    still = still_mask(t, xy, window_s=0.4, speed=0.1)
    # both phases last exactly 1.8 s: kept at a 1.8 s minimum, dropped at 1.8 s + 1 ns
    assert still_runs(t, still, min_duration_ns=1800 * MS) == [(0, 18), (32, 50)]
    assert still_runs(t, still, min_duration_ns=1800 * MS + 1) == []


def test_a_gap_splits_a_phase() -> None:
    # Samples at 0.6..1.3 s removed: 0.5 s and 1.4 s are now 0.9 s apart. The 0.4 s windows
    # around the remaining still samples still see no motion (sample 0.5 s sees 0.3..0.5 s,
    # sample 1.4 s sees 1.4..1.6 s), so the mask is unchanged; a 0.5 s gap limit splits the
    # phase at the hole into 0-0.5 s and 1.4-1.8 s.
    t, xy = _stop_go_stop()
    keep = (t < 600 * MS) | (t > 1300 * MS)
    t, xy = t[keep], xy[keep]
    still = still_mask(t, xy, window_s=0.4, speed=0.1)
    whole = still_intervals(t, still_runs(t, still))
    assert whole == [Interval(0, 1800 * MS), Interval(3200 * MS, 5000 * MS)]
    split = still_intervals(t, still_runs(t, still, max_gap_ns=500 * MS))
    assert split == [
        Interval(0, 500 * MS),
        Interval(1400 * MS, 1800 * MS),
        Interval(3200 * MS, 5000 * MS),
    ]
    # a gap equal to the limit does not split (the limit is "longer than")
    assert still_runs(t, still, max_gap_ns=900 * MS) == still_runs(t, still)
    assert len(still_runs(t, still, max_gap_ns=900 * MS - 1)) == 3
    # the minimum duration applies to the pieces: 0.5 s and 0.4 s pieces fail 0.6 s
    assert still_intervals(
        t, still_runs(t, still, max_gap_ns=500 * MS, min_duration_ns=600 * MS)
    ) == [Interval(3200 * MS, 5000 * MS)]


def test_turning_on_the_spot_is_caught_by_the_yaw_rate_limit() -> None:
    # Position fixed; yaw 0 until 1 s, +0.5 rad/s until 2 s, 0.5 rad after (31 samples).
    # With a 0.4 s window sample i sees yaw(i+2) - yaw(i-2): still iff i <= 8 or i >= 22;
    # samples 9 and 21 see 0.05 rad / 0.4 s = 0.125 rad/s against the 0.1 rad/s limit.
    t = np.arange(31, dtype=np.int64) * STEP
    xy = np.zeros((31, 2))
    yaw = _ramp(t / 1e9, 1.0, 2.0, 0.5)
    assert still_mask(t, xy, window_s=0.4, speed=0.01).all()  # position alone: all still
    still = still_mask(t, xy, window_s=0.4, speed=0.01, yaw=yaw, yaw_rate=0.1)
    assert still_runs(t, still) == [(0, 8), (22, 30)]


def test_yaw_jitter_across_pi_is_still() -> None:
    # +-1 mrad around pi, neighbours compared ("ahead" 0.1 s): the raw difference is ~2 pi
    # (63 rad/s), the wrapped one 2 mrad (0.02 rad/s against 0.1). The last sample has no
    # neighbour ahead.
    t = np.arange(20, dtype=np.int64) * STEP
    yaw = np.where(np.arange(20) % 2 == 0, math.pi - 1e-3, -math.pi + 1e-3)
    still = still_mask(
        t, np.zeros((20, 2)), window_s=0.1, speed=0.01, yaw=yaw, yaw_rate=0.1, kind="ahead"
    )
    np.testing.assert_array_equal(still, [True] * 19 + [False])


def test_ahead_window_reaches_to_the_compared_sample() -> None:
    # Still until 1.0 s, then 1 m/s. "ahead" 0.25 s compares sample i with the first sample at
    # or after t + 0.25 s, i.e. i + 3: still iff i + 3 <= 10 (i <= 7) against a 1 cm limit
    # (sample 8 is 0.1 m from sample 11); the last 3 samples have nothing 0.25 s ahead.
    t = np.arange(21, dtype=np.int64) * STEP
    x = _ramp(t / 1e9, 1.0, 10.0, 1.0)
    xyz = np.column_stack([x, np.zeros_like(x), np.zeros_like(x)])
    xyz[14:] = xyz[13]  # stops again at 1.3 s
    still = still_mask(t, xyz, window_s=0.25, max_move=0.01, kind="ahead", inclusive=True)
    expected = np.zeros(21, dtype=bool)
    expected[:8] = True
    expected[13:18] = True  # i >= 13 compares still samples; 18..20 have no sample ahead
    np.testing.assert_array_equal(still, expected)
    ahead = np.minimum(np.arange(21) + 3, 20)
    # Sample 7 vouches for sample 10 (1.0 s): with reach the phase lasts 1.0 s, else 0.7 s.
    assert still_runs(t, still, min_duration_ns=1000 * MS, reach=ahead) == [(0, 7)]
    assert still_runs(t, still, min_duration_ns=1000 * MS) == []


def test_inclusive_threshold() -> None:
    # 1/64 m steps every 0.1 s (exact in binary); "ahead" 0.1 s compares neighbours, so the
    # displacement equals the limit exactly.
    t = np.arange(5, dtype=np.int64) * STEP
    xyz = np.column_stack([np.arange(5) / 64, np.zeros(5), np.zeros(5)])
    strict = still_mask(t, xyz, window_s=0.1, max_move=1 / 64, kind="ahead")
    incl = still_mask(t, xyz, window_s=0.1, max_move=1 / 64, kind="ahead", inclusive=True)
    assert not strict.any()
    np.testing.assert_array_equal(incl, [True, True, True, True, False])


def test_rotation_limit_uses_the_full_rotation() -> None:
    # A 0.3 rad roll (about x) leaves yaw unchanged but counts with quat_xyzw/max_turn.
    t = np.arange(10, dtype=np.int64) * STEP
    roll = np.where(np.arange(10) >= 5, 0.3, 0.0)
    q = np.column_stack([np.sin(roll / 2), np.zeros(10), np.zeros(10), np.cos(roll / 2)])
    pos = np.zeros((10, 3))
    still = still_mask(t, pos, window_s=0.1, max_move=0.01, quat_xyzw=q, max_turn=0.1, kind="ahead")
    # sample 4 is compared with sample 5 (0.3 rad), sample 9 has nothing ahead
    np.testing.assert_array_equal(still, [True] * 4 + [False] + [True] * 4 + [False])


def test_rotation_angle() -> None:
    a = quat_from_yaw(np.array([0.0, 0.2, 3.0]))
    b = quat_from_yaw(np.array([0.3, -0.2, -3.0]))
    # yaw differences 0.3, 0.4, and 2 pi - 6 across the wrap; to 1e-12 (a few ulp of arctan2)
    np.testing.assert_allclose(rotation_angle(a, b), [0.3, 0.4, 2 * math.pi - 6.0], atol=1e-12)
    # q and -q are one rotation; an unnormalised quaternion is normalised first
    np.testing.assert_allclose(rotation_angle(a, -2.0 * a), 0.0, atol=1e-12)


def test_samples_window_smooths_jitter() -> None:
    # 100 Hz, 1 mm alternating jitter: raw neighbour speed is 0.2 m/s. sample_half_window at
    # 100 Hz for 0.2 s is 10 samples; the 21-sample means around i - 10 and i + 10 (same
    # parity) are equal, so the smoothed speed is 0 in the interior, where the windows are
    # not shrunk at the ends.
    t = np.arange(200, dtype=np.int64) * 10 * MS
    assert sample_half_window(t, 0.2) == 10
    x = np.where(np.arange(200) % 2 == 0, 0.001, -0.001)
    xy = np.column_stack([x, np.zeros(200)])
    still = still_mask(t, xy, window_s=0.2, speed=0.004, kind="samples")
    assert still[20:180].all()
    raw = still_mask(t, xy, window_s=0.01, speed=0.004, kind="ahead")
    assert not raw.any()  # neighbours 2 mm apart over 10 ms: 0.2 m/s; the last has none


def test_nan_is_never_still_and_min_samples() -> None:
    t = np.arange(11, dtype=np.int64) * STEP
    xy = np.zeros((11, 2))
    xy[5] = np.nan
    still = still_mask(t, xy, window_s=0.2, speed=0.1)
    # Windows are i-1..i+1 and only their ends are compared: samples 4 and 6 have the NaN at
    # an end (not still), sample 5 compares 4 with 6 (still, a one-sample phase).
    assert still_runs(t, still) == [(0, 3), (5, 5), (7, 10)]
    assert still_runs(t, still, min_samples=2) == [(0, 3), (7, 10)]


def test_short_and_bad_input() -> None:
    empty = np.zeros(0, dtype=np.int64)
    assert not still_mask(empty, np.zeros((0, 2)), window_s=0.2, speed=0.1).any()
    assert still_runs(empty, np.zeros(0, dtype=bool)) == []
    one = np.zeros(1, dtype=np.int64)
    assert not still_mask(one, np.zeros((1, 2)), window_s=0.2, speed=0.1).any()
    t = np.arange(3, dtype=np.int64) * STEP
    with pytest.raises(ValueError, match="exactly one"):
        still_mask(t, np.zeros((3, 2)), window_s=0.2)
    with pytest.raises(ValueError, match="yaw_rate needs yaw"):
        still_mask(t, np.zeros((3, 2)), window_s=0.2, speed=0.1, yaw_rate=0.1)
