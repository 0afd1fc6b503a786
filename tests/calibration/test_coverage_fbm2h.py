"""FBM2@Home's 95% intervals cover the simulator's noiseless truth (issue 28, item 4), on a
small number of simulated executions (``make calibrate`` runs 1,000)."""

from __future__ import annotations

import pytest

from tests.calibration.trials import coverage

pytestmark = pytest.mark.slow

TRIALS = 40
DRAWS = 200


def test_fbm2h_intervals_cover_the_noiseless_truth() -> None:
    scores, covered, misses = coverage("fbm2h", TRIALS, DRAWS)
    # 12 scores per execution (2 accuracies, 5 distance and 5 orientation errors) that share
    # the execution's transform error: counted as 40 x 5 = 200 independent ones, the covered
    # fraction at 95% has sd sqrt(.95 * .05 / 200) = 1.5%; 90% is over 3 sd below. At least
    # 4 misses of 480 (P(<= 3 of 200 independent) < 0.1% at 95%) catches intervals too wide.
    assert scores == 12 * TRIALS
    assert covered / scores >= 0.90, misses
    assert scores - covered >= 4, "hardly any interval missed: they are too wide for 95%"
