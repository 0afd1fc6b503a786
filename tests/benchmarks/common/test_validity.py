"""The validity mask (ertools.benchmarks.common.validity) on a hand-made 120 Hz stream whose
repeated poses, NaNs, clock jump, gap and window are placed by hand: every count, fraction and
span below is computed from where they were put, not from the code under test."""

from __future__ import annotations

import numpy as np
import pytest

from ertools.benchmarks.common.path_gaps import gaps_on_path
from ertools.benchmarks.common.validity import (
    CLOCK_JUMP,
    NAN,
    REASONS,
    TRACKING_LOST,
    VALID,
    coverage,
    coverage_problem,
    lost_spans,
    sample_codes,
    summarise,
    valid_near,
)

T0 = 1_448_013_600 * 1_000_000_000
DT = 8_333_333  # 120 Hz
SPEED = 0.1  # m/s along x: 0.83 mm per frame, every coordinate distinct


def _stream() -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """1000 frames; 100-111 repeat frame 99 (tracking lost, 12), 200-201 NaN, 500 at 499's
    stamp with its own pose (clock jump), 300-348 never arrived (49 frames: a 0.417 s gap).

    Returns t, xyz, quat and the original frame number of every kept sample.
    """
    n = 1000
    frame = np.arange(n)
    t = T0 + DT * frame.astype(np.int64)
    xyz = np.column_stack([SPEED * frame * DT / 1e9, np.full(n, 0.5), np.full(n, 0.8)])
    quat = np.tile([0.0, 0.0, 0.0, 1.0], (n, 1))
    xyz[100:112] = xyz[99]
    xyz[200:202, 0] = np.nan
    t[500] = t[499]
    keep = np.ones(n, dtype=bool)
    keep[300:349] = False
    return t[keep], xyz[keep], quat[keep], frame[keep]


def test_sample_codes_by_hand() -> None:
    t, xyz, quat, frame = _stream()
    mask = sample_codes(t, xyz, quat)
    assert mask.codes.dtype == np.int8
    by_frame = dict(zip(frame.tolist(), mask.codes.tolist(), strict=True))
    assert [f for f, c in by_frame.items() if c == TRACKING_LOST] == list(range(100, 112))
    assert [f for f, c in by_frame.items() if c == NAN] == [200, 201]
    assert [f for f, c in by_frame.items() if c == CLOCK_JUMP] == [500]
    assert int((mask.codes == VALID).sum()) == len(t) - 15
    assert mask.names()[frame.tolist().index(500)] == "clock_jump"


def test_a_sample_recorded_twice_stays_valid() -> None:
    t = T0 + DT * np.arange(4, dtype=np.int64)
    t[2] = t[1]
    # 1 cm a frame (1.2 m/s): a robot's pace (a metre a frame would be impossible: a jump)
    xyz = np.column_stack([0.01 * np.arange(4.0), np.zeros(4), np.zeros(4)])
    xyz[2] = xyz[1]  # same stamp, same pose: a second logger's copy
    assert sample_codes(t, xyz).codes.tolist() == [VALID] * 4


def test_zero_quaternion_and_inf_are_nan() -> None:
    t = T0 + DT * np.arange(3, dtype=np.int64)
    xyz = np.array([[0.0, 0, 0], [1.0, 0, 0], [np.inf, 0, 0]])
    quat = np.array([[0.0, 0, 0, 1], [0.0, 0, 0, 0], [0.0, 0, 0, 1]])
    assert sample_codes(t, xyz, quat).codes.tolist() == [VALID, NAN, NAN]


def test_summary_counts_fraction_and_spans() -> None:
    t, xyz, quat, frame = _stream()
    mask = sample_codes(t, xyz, quat)
    start, end = T0 + 50 * DT, T0 + 900 * DT  # frames 50..900 inclusive
    v = summarise(mask, start, end)
    inside = 851 - 49  # frames 50..900 that arrived
    assert v.samples == inside
    assert v.period_ns == DT
    assert v.invalid_samples == {"tracking_lost": 12, "gap": 49, "nan": 2, "clock_jump": 1}
    assert v.valid_samples == inside - 15
    assert v.valid_fraction == pytest.approx((inside - 15) / 851, abs=1e-15)
    assert v.fields() == {
        "valid_fraction": round((inside - 15) / 851, 6),
        "invalid_samples": {"tracking_lost": 12, "gap": 49, "nan": 2, "clock_jump": 1},
    }
    # two spans longer than 0.1 s: frames 99 -> 112 (13 frames, 12 repeats) and the gap
    # 299 -> 349 (50 frames); the 2 NaNs (3 frames, 25 ms) are no span
    assert [(s.reason, s.start_ns, s.end_ns, s.samples) for s in v.spans] == [
        ("tracking_lost", T0 + 99 * DT, T0 + 112 * DT, 12),
        ("gap", T0 + 299 * DT, T0 + 349 * DT, 0),
    ]
    lost, gap = v.spans
    win = frame[(t >= start) & (t <= end)]
    assert (win[lost.before], win[lost.after]) == (99, 112)
    assert (win[gap.before], win[gap.after]) == (299, 349)
    assert gap.duration_s == pytest.approx(50 * DT / 1e9, abs=1e-12)
    assert coverage(v) == pytest.approx(1 - 63 / 850, abs=1e-12)
    line = v.text("run 2", T0)
    assert line == (
        f"run 2 {(inside - 15) / 851:.1%} valid (12 tracking_lost, 2 nan, 1 clock_jump, "
        f"1 gap {50 * DT / 1e9:.2f} s at {299 * DT / 1e9:.2f} s)"
    )


def test_outside_window_and_edge_gaps() -> None:
    t, xyz, quat, _ = _stream()
    mask = sample_codes(t, xyz, quat)
    # a window reaching 0.5 s past the last sample: 60 frames missing at its end
    v = summarise(mask, T0 + 900 * DT, T0 + 1059 * DT, outside=7)
    assert v.samples == 100  # frames 900..999
    assert v.invalid_samples == {"gap": 60, "outside_window": 7}
    assert v.valid_fraction == pytest.approx(100 / 167, abs=1e-15)
    (edge,) = v.spans
    assert (edge.reason, edge.before, edge.after) == ("gap", 99, -1)
    # an empty window: every frame it should hold is missing
    empty = summarise(mask, T0 + 2000 * DT, T0 + 2010 * DT)
    assert empty.samples == 0
    assert empty.invalid_samples == {"gap": 11}
    assert empty.valid_fraction == 0.0


def test_gaps_on_path_and_lost_spans() -> None:
    t, xyz, quat, _ = _stream()
    mask = sample_codes(t, xyz, quat)
    start, end = T0 + 50 * DT, T0 + 900 * DT
    v = summarise(mask, start, end)
    xy = xyz[(t >= start) & (t <= end), :2]
    drawn = gaps_on_path(v, xy, T0)
    assert drawn[0].start_xy == pytest.approx((SPEED * 99 * DT / 1e9, 0.5))
    assert drawn[0].end_xy == pytest.approx((SPEED * 112 * DT / 1e9, 0.5))
    assert drawn[1].start_s == pytest.approx(299 * DT / 1e9)
    # the marker moved 10.8 mm while its pose was frozen: lost
    assert lost_spans(v, xy, 0.002) == v.spans
    # the same frozen stretch on a still marker set hid no motion
    still = xyz.copy()
    still[:, 0] = 0.0
    still[200:202, 0] = np.nan
    keep_moving = still[:, 1] + np.arange(len(still)) * 1e-9  # distinct rows, 1 nm apart
    still[:, 1] = keep_moving
    still[100:112] = still[99]
    v2 = summarise(sample_codes(t, still, quat), start, end)
    xy2 = still[(t >= start) & (t <= end), :2]
    assert [s.reason for s in lost_spans(v2, xy2, 0.002)] == ["gap"]


def test_coverage_verdicts() -> None:
    t, xyz, quat, _ = _stream()
    mask = sample_codes(t, xyz, quat)
    v = summarise(mask, T0 + 50 * DT, T0 + 900 * DT)
    assert coverage_problem(v, 0.9) is None  # 92.6% covered
    below = coverage_problem(v, 0.95)
    assert below is not None and "covers only 92.6% of the window" in below
    mid = coverage_problem(v, 0.9, max_inner_gap_s=0.4)
    assert mid is not None and mid.startswith("0.42 s without valid data in the middle")
    assert coverage_problem(v, 0.9, max_inner_gap_s=0.5) is None


def test_valid_near() -> None:
    t, xyz, quat, _ = _stream()
    mask = sample_codes(t, xyz, quat)
    at = T0 + DT * np.array([105, 320, 600, 1100], dtype=np.int64)
    # 105 is 6 frames from 99 and 7 from 112; 320 is 21 frames from 299 and 29 from 349
    assert valid_near(mask, at, 7 * DT).tolist() == [True, False, True, False]
    assert valid_near(mask, at, 6 * DT).tolist() == [True, False, True, False]
    assert valid_near(mask, at, 5 * DT).tolist() == [False, False, True, False]
    assert valid_near(mask, at, 101 * DT).tolist() == [True, True, True, True]


def test_reason_names_are_the_contract() -> None:
    assert REASONS == (
        "valid",
        "tracking_lost",
        "gap",
        "outside_window",
        "nan",
        "clock_jump",
        "occluded",
        "far",
        "jump",
    )
