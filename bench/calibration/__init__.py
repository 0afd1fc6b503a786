"""Calibration of the score intervals against the simulator (issue 28, item 4).

One module per benchmark (``fbm1``, ``fbm2h``, ``fbm3w``, ``trajectory``), each exposing::

    def trial(seed: int, draws: int) -> list[tuple[str, float, float, float]]

One simulated execution with known noise and a known noiseless truth, seeded by ``seed``
(the same seed, the same execution and the same intervals): the noisy log is scored exactly as
``ertools score`` scores it (the same pure scoring function, the interval sources measured
from the noisy log as in real use, ``draws`` Monte Carlo draws, the default 95% level), and
the true noiseless score is computed from the simulator's truth (the simulator's own formula,
not the scorer under test). Returned: one ``(score key, true value, low, high)`` per score of
the execution (e.g. ``("runs_details.2.distance_error", 0.00081, 0.00074, 0.00089)``); a
score without an interval is left out (the harness counts only intervals it was given).

The modules are listed in :data:`MODULES` (``bench/calibrate.py`` runs them, the tests under
``tests/calibration/`` run a smaller number of trials). A module must import fast (the
simulator on demand) and keep one trial well under a second at 400 draws.

Coverage counts a trial's score as covered when ``low <= true <= high``. Each score of an
execution is one Bernoulli trial; scores of the same execution share its noise phases, so
the tests' tolerances count executions, not scores.
"""

from __future__ import annotations

#: benchmark name -> module under bench/calibration/ (imported by name: a missing module
#: is reported as "not written yet", not a crash).
MODULES = {
    "fbm1": "calibration.fbm1",
    "fbm2h": "calibration.fbm2h",
    "fbm3w": "calibration.fbm3w",
    "trajectory": "calibration.trajectory",
}

#: The four-tuple every trial returns: score key, true noiseless value, interval low, high.
Row = tuple[str, float, float, float]
