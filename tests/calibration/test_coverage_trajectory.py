"""The trajectory intervals cover the simulator's noiseless truth as often as they claim
(issue 28, item 4): a small version of ``bench/calibrate.py``'s 1,000 trials.

Each trial is one simulated robot log (bench/calibration/trajectory.py: the robotlog
scenario with the robot's error drawn per trial, scored with ``--offset auto
--apply-offset``; the truth is the robot's estimate against the noiseless pose at each
compared moment, computed there with plain NumPy).
"""

from __future__ import annotations

import pytest
from calibration import trajectory
from scipy.stats import binom

pytestmark = pytest.mark.slow

TRIALS = 40
DRAWS = 100


def test_95_percent_intervals_cover_the_truth_95_percent_of_the_time() -> None:
    covered = {"position_error": 0, "orientation_error": 0}
    for seed in range(TRIALS):
        for key, true, low, high in trajectory.trial(1000 + seed, DRAWS):
            if key in covered:
                covered[key] += low <= true <= high
    # The statistics of one log share its noise: each trial is one Bernoulli trial per
    # statistic. 40 trials: the 99.9% binomial band around 95% is 33 to 40; an interval
    # that ignored the noise's bias or the clock offset covers far less often.
    lo = binom.ppf(0.0005, TRIALS, 0.95)
    for key, n in covered.items():
        assert n >= lo, f"{key}: {n}/{TRIALS} covered"


def test_intervals_follow_their_statistics_and_draws_0_gives_none() -> None:
    result, _ = trajectory.score(7, 100)
    d = result.to_dict()
    keys = list(d)
    for key in ("position_error", "orientation_error", "rmse", "median", "max"):
        assert keys.index(f"{key}_interval") == keys.index(key) + 1
        low, high = d[f"{key}_interval"]
        assert low <= high
    assert "p95_interval" in d["percentiles"]
    assert [s["name"] for s in d["uncertainty"]["sources"]] == [
        "mocap_noise",
        "time_association",
    ]
    # the GT noise is measured from the moving GT: the simulator's 0.2 mm within 10%
    sigma = d["uncertainty"]["sources"][0]["value"]
    assert abs(sigma - 2e-4) < 2e-5
    none, _ = trajectory.score(7, 0)
    assert none.intervals == {} and "uncertainty" not in none.to_dict()
