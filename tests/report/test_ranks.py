"""Rank stability (ertools.report.ranks): swap probabilities and tie groups checked against
values computed here by hand from the normal CDF (math.erf), not from the code's NormalDist."""

from __future__ import annotations

import math
import random
import re

import pytest

from ertools.report.rank_plot import LABEL, RIGHT, WIDTH, interval_plot
from ertools.report.ranks import (
    NEXT_NO_INTERVAL,
    NO_INTERVAL,
    OUTSIDE_INTERVAL,
    Contender,
    board_confidence,
    confidence_of,
    interval_of,
    p_swap,
    ranked_key,
    stability,
    summary,
    unscoreable_reason,
    z_value,
)

Z95 = 1.959963984540054  # the two-sided 95 % normal quantile (tables)
Z68 = 0.994457883209753  # ... at 68 %


def phi(x: float) -> float:
    return 0.5 * (1.0 + math.erf(x / math.sqrt(2.0)))


def test_z_values_are_the_tabled_quantiles() -> None:
    assert z_value(0.95) == pytest.approx(Z95, abs=1e-9)
    assert z_value(0.68) == pytest.approx(Z68, abs=1e-9)
    with pytest.raises(ValueError, match="confidence"):
        z_value(1.0)


def test_two_symmetric_normals() -> None:
    # A: 10 +- 2 (95 %): sigma 2/1.96; B: 13 +- 3: sigma 3/1.96; gap 3 in the rule's direction.
    a = Contender("a", 10.0, (8.0, 12.0))
    b = Contender("b", 13.0, (10.0, 16.0))
    sigma = math.sqrt((2 / Z95) ** 2 + (3 / Z95) ** 2)
    expected = phi(-3.0 / sigma)
    assert expected == pytest.approx(0.0515, abs=5e-4)  # written down: Phi(-1.631)
    assert p_swap(a, b, lower_is_better=True) == pytest.approx(expected, rel=1e-12)
    # 5.2 % > 2.5 %: the order is not supported at 95 %, a tie shown "=1".
    board = stability([b, a], lower_is_better=True)
    assert [s.name for s in board] == ["a", "b"]
    assert [s.marker for s in board] == ["=1", "=1"]
    assert board[0].tied_with == ("b",) and board[1].tied_with == ("a",)
    assert board[0].p_swap_next == pytest.approx(expected, rel=1e-12)
    assert board[1].p_swap_next is None and board[1].note == ""  # the last row
    # At 80 % the threshold is 10 %: 5.2 % is below it, the order stands.
    board80 = stability([a, b], lower_is_better=True, confidence=0.80)
    assert [s.marker for s in board80] == ["1", "2"] and not board80[0].tied


def test_narrow_intervals_support_the_order() -> None:
    a = Contender("a", 10.0, (9.5, 10.5))
    b = Contender("b", 13.0, (12.0, 14.0))
    expected = phi(-3.0 / math.hypot(0.5 / Z95, 1.0 / Z95))
    assert expected < 1e-6
    (first, second) = stability([a, b], lower_is_better=True)
    assert first.p_swap_next == pytest.approx(expected, rel=1e-9)
    assert (first.marker, second.marker) == ("1", "2")


def test_skewed_intervals_use_the_facing_sides() -> None:
    # Lower is better. A's interval reaches far up (towards B), B's barely down (towards A):
    # the facing sides are A's 4 above and B's 0.5 below, not the halves of the widths.
    a = Contender("a", 10.0, (9.0, 14.0))
    b = Contender("b", 12.0, (11.5, 20.0))
    expected = phi(-2.0 / math.hypot(4.0 / Z95, 0.5 / Z95))
    assert p_swap(a, b, lower_is_better=True) == pytest.approx(expected, rel=1e-12)
    # Higher is better: the mirror image (A ahead at 14 with 4 below, B at 12 with 0.5 above).
    a_hi = Contender("a", 14.0, (10.0, 15.0))
    b_hi = Contender("b", 12.0, (4.0, 12.5))
    assert p_swap(a_hi, b_hi, lower_is_better=False) == pytest.approx(expected, rel=1e-12)
    board = stability([b_hi, a_hi], lower_is_better=False)
    assert [s.name for s in board] == ["a", "b"]


def test_intervals_at_another_confidence_are_read_at_their_own() -> None:
    # A 68 % interval of half-width 1 is sigma 1/0.9945; a 95 % one of half-width 2 is 2/1.96.
    a = Contender("a", 0.0, (-1.0, 1.0), confidence=0.68)
    b = Contender("b", 2.0, (0.0, 4.0), confidence=0.95)
    expected = phi(-2.0 / math.hypot(1.0 / Z68, 2.0 / Z95))
    assert p_swap(a, b, lower_is_better=True) == pytest.approx(expected, rel=1e-12)


def test_ties_chain_into_groups() -> None:
    # 1.0, 1.5, 2.0, each +- 0.6: each adjacent pair P = Phi(-0.5/0.433) = 12 %, tied; A and C
    # alone (Phi(-1/0.433) = 1.0 %) would be told apart, but the chain groups all three.
    # D at 5.0 +- 0.1 stands alone.
    sigma = 0.6 / Z95
    rows = [
        Contender("c", 2.0, (1.4, 2.6)),
        Contender("a", 1.0, (0.4, 1.6)),
        Contender("d", 5.0, (4.9, 5.1)),
        Contender("b", 1.5, (0.9, 2.1)),
    ]
    board = stability(rows, lower_is_better=True)
    assert [s.name for s in board] == ["a", "b", "c", "d"]
    pair = phi(-0.5 / math.hypot(sigma, sigma))
    assert pair == pytest.approx(0.124, abs=1e-3)
    assert phi(-1.0 / math.hypot(sigma, sigma)) < 0.025
    assert [s.p_swap_next for s in board[:2]] == [pytest.approx(pair)] * 2
    assert [s.marker for s in board] == ["=1", "=1", "=1", "4"]
    assert board[1].tied_with == ("a", "c")
    assert [s.rank for s in board] == [1, 2, 3, 4]
    assert summary(board) == "1 of 3 adjacent order(s) supported by the data; tied: a, b, c (=1)"


def test_equal_values_and_missing_intervals() -> None:
    rows = [
        Contender("x", 3.0),  # no interval: kept in the rule's order, not assessed
        Contender("p", 1.0, (0.9, 1.1)),
        Contender("q", 1.0, (0.9, 1.1)),
        Contender("r", 2.0),
    ]
    board = stability(rows, lower_is_better=True)
    assert [(s.name, s.rank, s.marker) for s in board] == [
        ("p", 1, "=1"),
        ("q", 1, "=1"),
        ("r", 3, "3"),
        ("x", 4, "4"),
    ]
    # Equal scores: a coin toss.
    assert board[0].p_swap_next == pytest.approx(0.5)
    assert board[1].p_swap_next is None and board[2].p_swap_next is None
    assert board[2].note == NO_INTERVAL and board[0].note == ""
    assert board[1].note == NEXT_NO_INTERVAL  # q has one, r does not
    assert summary(board) == (
        "0 of 3 adjacent order(s) supported by the data; 2 not assessed "
        f"({NO_INTERVAL}); tied: p, q (=1)"
    )
    # Equal values without any interval are still tied: the rule itself ties them.
    same = stability([Contender("u", 1.0), Contender("v", 1.0)], lower_is_better=False)
    assert [s.marker for s in same] == ["=1", "=1"]


def test_an_interval_that_does_not_hold_its_score_is_not_read() -> None:
    """An older ertools wrote the trajectory's interval of the score at the fitted clock
    offset: 146.6 mm with [17.42, 19.46]. Its sides around the score are no spread of it:
    the row is not assessed (issue 39), the others are as without it."""
    rows = [
        Contender("old", 0.1466, (0.01742, 0.01946)),
        Contender("a", 0.0174, (0.0173, 0.0176)),
        Contender("b", 0.0180, (0.0178, 0.0182)),
    ]
    board = stability(rows, lower_is_better=True)
    assert [s.name for s in board] == ["a", "b", "old"]
    assert board[2].interval is None and board[2].note == OUTSIDE_INTERVAL
    assert board[1].p_swap_next is None and board[1].note == NEXT_NO_INTERVAL
    # a's and b's facing sides 0.2 and 0.2 mm, 0.6 mm apart: Phi(-0.6 / (0.2 sqrt 2) * 1.96)
    sigma = math.hypot(0.0002, 0.0002) / Z95
    assert board[0].p_swap_next == pytest.approx(phi(-0.0006 / sigma))
    assert summary(board) == (
        "1 of 2 adjacent order(s) supported by the data; 1 not assessed "
        f"({NO_INTERVAL}, or {OUTSIDE_INTERVAL})"
    )


def test_tie_rule_is_the_difference_interval_containing_zero() -> None:
    """P(swap) > alpha/2 exactly when the difference's two-sided interval contains 0: checked
    on random symmetric pairs against the interval of the difference computed here."""
    rng = random.Random(28)
    for _ in range(500):
        sa, sb = rng.uniform(0, 2), rng.uniform(0, 2)
        ha, hb = rng.uniform(0.01, 1), rng.uniform(0.01, 1)
        a = Contender("a", sa, (sa - ha, sa + ha))
        b = Contender("b", sb, (sb - hb, sb + hb))
        board = stability([a, b], lower_is_better=True)
        diff = abs(sb - sa)
        half = Z95 * math.hypot(ha / Z95, hb / Z95)
        if abs(diff - half) < 1e-9:
            continue  # on the edge: float rounding decides
        assert board[0].tied == (diff - half < 0.0), (sa, ha, sb, hb)


def test_reading_results() -> None:
    score = {
        "best_distance_error": 0.0012,
        "best_distance_error_interval": [0.0010, 0.0015],
        "best_run": 2,
        "position_accuracy_interval": [0.2, 0.1],  # low > high: not an interval
        "uncertainty": {"confidence": 0.9, "method": "monte_carlo"},
    }
    assert interval_of(score, "best_distance_error") == (0.0010, 0.0015)
    assert interval_of(score, "position_accuracy") is None
    assert interval_of(score, "best_run") is None
    assert interval_of({"k_interval": [0.1, float("nan")]}, "k") is None
    assert confidence_of(score) == 0.9
    assert confidence_of({"uncertainty": {"confidence": 95}}) is None
    assert confidence_of({}) is None
    assert board_confidence([None, 0.9, 0.95]) == 0.95
    assert board_confidence([None]) == 0.95
    assert ranked_key({"a": 0.8, "b": 0.8}, 0.8, "b (0..1): higher is better") == "b"
    assert ranked_key({"a": 0.8, "b": 0.8}, 0.8) == "a"
    assert unscoreable_reason({"status": "unscoreable", "unscoreable_reason": "no GT"}) == "no GT"
    assert unscoreable_reason({"status": "scored"}) is None


def test_plot_places_dots_and_bars_by_the_numbers() -> None:
    """The SVG from the numbers: scores 0, 5, 10 with intervals; the axis spans [0, 10]
    padded by 6 % each side (-0.6 .. 10.6) over the plot's x range (LABEL .. WIDTH - RIGHT),
    so x(v) = LABEL + (v + 0.6) / 11.2 * (WIDTH - RIGHT - LABEL)."""
    board = stability(
        [
            Contender("a", 0.0, (0.0, 1.0)),
            Contender("b<&>", 5.0, (4.0, 6.0)),
            Contender("c", 10.0, (9.5, 10.0)),
        ],
        lower_is_better=True,
    )
    svg = interval_plot(board, factor=1000.0, unit="mm", decimals=1, axis="error")
    span = WIDTH - RIGHT - LABEL

    def x(v: float) -> str:
        return f"{LABEL + (v + 0.6) / 11.2 * span:.1f}"

    dots = re.findall(r'<circle class="score" cx="([0-9.]+)"', svg)
    assert dots == [x(0.0), x(5.0), x(10.0)]
    # b's bar from 4 to 6 (values shown in mm: factor 1000)
    assert f'x1="{x(4.0)}"' in svg and f'x2="{x(6.0)}"' in svg
    assert "5000.0 [4000.0, 6000.0]" in svg and "error (mm)" in svg
    assert "b&lt;&amp;&gt;" in svg and "b<&>" not in svg  # a team name is text
    # a-b: 5 apart, sides 1 and 1 (95 %): P = Phi(-5 / (sqrt(2) / 1.96)), far below 2.5 %
    assert 'class="tie"' not in svg


def test_infinite_scores_are_not_weighed() -> None:
    board = stability(
        [Contender("a", 1.0, (0.5, 1.5)), Contender("b", float("inf"), (0.0, 2.0))],
        lower_is_better=True,
    )
    assert board[0].p_swap_next is None and not board[0].tied
    assert interval_plot(board).count('class="score"') == 1
