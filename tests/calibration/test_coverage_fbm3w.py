"""FBM3@Work's 95% intervals cover the simulator's noiseless truth (issue 28, item 4), on a
small number of simulated executions (``make calibrate`` runs 1,000)."""

from __future__ import annotations

from trials import coverage

TRIALS = 40
DRAWS = 200


def test_fbm3w_intervals_cover_the_noiseless_truth() -> None:
    scores, covered, misses = coverage("fbm3w", TRIALS, DRAWS)
    # 4 scored runs per execution (+ the best, one of them): 160 independent scores. At a true
    # coverage of 95% their covered fraction has sd sqrt(.95 * .05 / 160) = 1.7%: 90% is 3 sd
    # below. At least two misses (P(<= 1 miss) = 0.3% at 95%) catches intervals too wide to
    # be 95% ones.
    assert scores == 5 * TRIALS
    assert covered / scores >= 0.90, misses
    assert scores - covered >= 2, "no interval missed: they are too wide for 95%"
