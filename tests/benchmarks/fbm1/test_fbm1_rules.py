"""The 2015 FBM1 scoring rules and their fixes, on numbers computed by hand."""

from __future__ import annotations

import math

import pytest
from hypothesis import given
from hypothesis import strategies as st

from ertools.benchmarks.fbm1.config import ScoreRules
from ertools.benchmarks.fbm1.formula import (
    names_match,
    pose_errors,
    rot_term,
    totals,
    trans_term,
    wrap_deg,
)

FIXED = ScoreRules()
LEGACY = ScoreRules.node_2015()


@pytest.mark.parametrize(
    ("angle", "fixed", "legacy"),
    [
        (10.0, 10.0, 10.0),
        (190.0, -170.0, -170.0),
        (-190.0, 170.0, 170.0),
        (363.0, 3.0, 3.0),
        # 2015 wrapped once: 723 - 360 = 363 stays beyond 180.
        (723.0, 3.0, 363.0),
        (-545.0, 175.0, -185.0),
    ],
)
def test_wrap(angle: float, fixed: float, legacy: float) -> None:
    assert wrap_deg(angle) == pytest.approx(fixed, abs=1e-9)
    assert wrap_deg(angle, legacy=True) == pytest.approx(legacy, abs=1e-9)


@pytest.mark.slow
@given(st.floats(-1e6, 1e6, allow_nan=False))
def test_wrap_range(angle: float) -> None:
    w = wrap_deg(angle)
    assert -180.0 <= w < 180.0
    # Same direction: the difference is a whole number of turns (float error grows with |a|).
    turns = (angle - w) / 360.0
    assert turns == pytest.approx(round(turns), abs=1e-6)


@pytest.mark.parametrize(
    ("error", "fixed", "legacy"),
    [
        (0.3, 0.3, 0.3),
        (1.0, 1.0, 1.0),
        # 1 m < error <= sqrt(2) m: 2015 left it unclipped.
        (1.2, 1.0, 1.2),
        (1.5, 1.0, 1.0),
    ],
)
def test_translation_term(error: float, fixed: float, legacy: float) -> None:
    assert trans_term(error) == fixed
    assert trans_term(error, legacy=True) == legacy


def test_rotation_term_clips_at_one() -> None:
    assert rot_term(90.0) == 0.5
    assert rot_term(-45.0) == 0.25
    assert rot_term(363.0) == 1.0


def test_pose_errors_by_hand() -> None:
    # Answer 3 cm and 4 cm off (5 cm), theta 20 deg off: 1 - 0.05/2 - (20/180)/2.
    e = pose_errors(0.53, 0.24, 50.0, 0.5, 0.2, 30.0, FIXED)
    assert (e.dx, e.dy) == pytest.approx((0.03, 0.04))
    assert e.trans_error_m == pytest.approx(0.05)
    assert e.theta_error_deg == pytest.approx(20.0)
    assert e.pose_score == pytest.approx(1 - 0.025 - 20 / 360)
    assert not e.legacy_differs
    # 1.2 m off: fixed clip gives 1 - 1/2 - 0 = 0.5, 2015 gave 1 - 0.6 = 0.4.
    far = pose_errors(1.7, 0.2, 30.0, 0.5, 0.2, 30.0, FIXED)
    old = pose_errors(1.7, 0.2, 30.0, 0.5, 0.2, 30.0, LEGACY)
    assert far.pose_score == pytest.approx(0.5)
    assert old.pose_score == pytest.approx(0.4)
    assert far.legacy_differs and old.legacy_differs


def test_names() -> None:
    # The 2015 fbm1w.yaml had "Bearing Boxes " with a trailing blank.
    assert names_match("Bearing Boxes", "Bearing Boxes ", FIXED)
    assert not names_match("Bearing Boxes", "Bearing Boxes ", LEGACY)
    assert not names_match("a1", "a2", FIXED)


def test_totals_fixed_and_2015() -> None:
    # execution times in ns: 0.1 + 0.2 + 0.4 s, whose float sum prints 0.7000000000000001
    times_ns = [100_000_000, 200_000_000, 400_000_000]
    args = ([True, False, True], [True, False, False], [0.9, 0.0, 0.6], times_ns)
    t = totals(*args, aborted=1, rules=FIXED)
    assert (t.class_accuracy, t.instance_accuracy) == pytest.approx((2 / 3, 1 / 3))
    assert t.pose_score == pytest.approx(1.5 / 3)
    assert 0.1 + 0.2 + 0.4 != 0.7 and repr(t.execution_time) == "0.7"  # summed in ns
    # 2016-17 @Home: accuracies over 10, pose over the runs counted including the aborted one.
    later = totals(*args, aborted=1, rules=ScoreRules.node_2016())
    assert (later.class_accuracy, later.instance_accuracy) == pytest.approx((0.2, 0.1))
    assert later.pose_score == pytest.approx(1.5 / 4)
    # 2015 (@Home and @Work): everything over the runs counted including the aborted one.
    old = totals(*args, aborted=1, rules=LEGACY)
    assert (old.class_accuracy, old.instance_accuracy) == pytest.approx((0.5, 0.25))
    assert old.pose_score == pytest.approx(1.5 / 4)


def test_totals_with_no_counted_run() -> None:
    t = totals([], [], [], [], aborted=0, rules=FIXED)
    assert t.class_accuracy is None and t.pose_score is None and t.execution_time == 0.0


@pytest.mark.slow
@given(
    st.floats(-2, 2),
    st.floats(-2, 2),
    st.floats(-720, 720),
    st.floats(-2, 2),
    st.floats(-2, 2),
    st.floats(-180, 180),
)
def test_pose_score_bounds(x: float, y: float, th: float, gx: float, gy: float, gth: float) -> None:
    e = pose_errors(x, y, th, gx, gy, gth, FIXED)
    assert 0.0 <= e.pose_score <= 1.0
    assert e.trans_error_m == pytest.approx(math.hypot(x - gx, y - gy))
