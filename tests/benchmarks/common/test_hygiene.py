"""The repeated-pose tests of ertools.benchmarks.common.hygiene, each against a hand-made stream
whose repeats are known, and against the plain ``np.all(a == b, axis=1)`` they replace."""

from __future__ import annotations

import numpy as np

from ertools.benchmarks.common.hygiene import (
    drop_duplicates,
    drop_repeats,
    identical_poses,
    repeated_positions,
    rows_equal,
    same_rows,
)
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
