"""The FBM1 scoring rules of the 2015 node, with its bugs fixed unless asked for.

Per run (2015 ``fbm1h``/``fbm1w``): x and y errors in metres, theta error in degrees wrapped to
[-180, 180]; translation term t = hypot(dx, dy) clipped at 1 m, rotation term
r = |dtheta| / 180 clipped at 1; pose_score = 1 - t/2 - r/2. Class and instance are right when
the names match. Totals: class_accuracy and instance_accuracy = positives / runs, pose_score =
mean over the runs, execution_time = sum of the runs' goal-to-result times (seconds).

The nodes' behaviours, each restored by one :class:`ScoreRules` field (named for what it
restores; ``Fbm1Options.for_rules`` selects those of one node):

- ``clip_above_diagonal``: the 2015 and 2016 nodes compared t with the table diagonal sqrt(2) m
  and set only larger errors to 1, leaving errors between 1 and 1.41 m unclipped (a pose score
  below 0); the 2017 node clipped at 1 m.
- ``single_wrap``: both nodes wrapped theta errors by a single +-360, so answers beyond +-540 deg
  kept a rotation term of 1 however close they were.
- ``exact_names``: both nodes compared classes and instances exactly; the 2015 ``fbm1w.yaml``
  has the class ``"Bearing Boxes "`` with a trailing blank that no robot answer matched.
- ``count_aborted``: both nodes counted a run the benchmark stopped before its goal in their
  divisor (``runs`` was incremented before the manual operation).
- ``accuracy_over_10``: the 2016 and 2017 @Home nodes divided the accuracies by
  ``BENCHMARK_RUNS`` (10) even when fewer runs were played; the 2015 nodes divided them by
  ``runs``.
"""

from __future__ import annotations

import math

from ertools.benchmarks.fbm1.config import ScoreRules
from ertools.frozen_dataclass import frozen_dataclass
from ertools.timeutil import ns_to_s

# The @Home nodes played at most this many runs; the 2016-17 one divided the accuracies by it.
BENCHMARK_RUNS_HOME = 10
# The 2015 "maximum pose error": the diagonal of a 1 m x 1 m table.
MAX_POSE_ERROR_2015 = math.sqrt(2.0)


@frozen_dataclass
class PoseErrors:
    """The pose part of one run's score.

    Attributes:
        dx: answer x - ground truth x, metres.
        dy: answer y - ground truth y, metres.
        trans_error_m: hypot(dx, dy).
        theta_error_deg: answer theta - ground truth yaw, degrees, wrapped.
        trans_term: the translation term t of the score (clipped).
        rot_term: the rotation term r of the score (clipped).
        pose_score: 1 - t/2 - r/2.
        legacy_differs: the 2015 and the fixed rules give different pose scores here.
    """

    dx: float
    dy: float
    trans_error_m: float
    theta_error_deg: float
    trans_term: float
    rot_term: float
    pose_score: float
    legacy_differs: bool


def wrap_deg(angle: float, *, legacy: bool = False) -> float:
    """Degrees wrapped to [-180, 180]; ``legacy``: one +-360 step as the 2015 node did."""
    if legacy:
        if angle > 180.0:
            angle -= 360.0
        if angle < -180.0:
            angle += 360.0
        return angle
    wrapped = math.fmod(angle + 180.0, 360.0)
    if wrapped < 0.0:
        wrapped += 360.0
    return wrapped - 180.0


def trans_term(error_m: float, *, legacy: bool = False) -> float:
    """The translation term: min(error, 1); ``legacy``: 1 only above sqrt(2) m (2015)."""
    if legacy:
        return 1.0 if error_m > MAX_POSE_ERROR_2015 else error_m
    return min(error_m, 1.0)


def rot_term(theta_error_deg: float) -> float:
    """The rotation term: |error| / 180 clipped at 1."""
    return min(abs(theta_error_deg) / 180.0, 1.0)


def pose_errors(
    x: float,
    y: float,
    theta_deg: float,
    gt_x: float,
    gt_y: float,
    gt_yaw_deg: float,
    rules: ScoreRules,
) -> PoseErrors:
    """Score an answered pose against the ground truth (2015 ``fbm1h`` formula)."""
    dx = x - gt_x
    dy = y - gt_y
    dist = math.hypot(dx, dy)
    raw = theta_deg - gt_yaw_deg
    dtheta = wrap_deg(raw, legacy=rules.single_wrap)
    t = trans_term(dist, legacy=rules.clip_above_diagonal)
    r = rot_term(dtheta)
    score = 1.0 - t / 2.0 - r / 2.0
    old = 1.0 - trans_term(dist, legacy=True) / 2.0 - rot_term(wrap_deg(raw, legacy=True)) / 2.0
    new = 1.0 - trans_term(dist) / 2.0 - rot_term(wrap_deg(raw)) / 2.0
    return PoseErrors(dx, dy, dist, dtheta, t, r, score, abs(old - new) > 1e-12)


def names_match(answer: str, truth: str, rules: ScoreRules) -> bool:
    """Class or instance equality; blanks around names are ignored unless ``exact_names``."""
    return answer == truth if rules.exact_names else answer.strip() == truth.strip()


@frozen_dataclass
class Totals:
    """The four numbers of the 2015 score and what they were divided by."""

    class_accuracy: float | None
    instance_accuracy: float | None
    pose_score: float | None
    execution_time: float
    accuracy_runs: int
    pose_runs: int


def totals(
    class_ok: list[bool],
    instance_ok: list[bool],
    pose_scores: list[float],
    execution_times_ns: list[int],
    *,
    aborted: int,
    rules: ScoreRules,
) -> Totals:
    """Totals over the counted runs (every list has one entry per run that reached its goal).

    Runs without answer enter with False, False and pose score 0, as in 2015. ``aborted``:
    runs the benchmark stopped before their goal (counted by the nodes' ``runs``).
    """
    played = len(class_ok)
    pose_runs = played + aborted if rules.count_aborted else played
    acc_runs = BENCHMARK_RUNS_HOME if rules.accuracy_over_10 else pose_runs

    def ratio(num: float, den: int) -> float | None:
        return num / den if den else None

    return Totals(
        ratio(sum(class_ok), acc_runs),
        ratio(sum(instance_ok), acc_runs),
        ratio(math.fsum(pose_scores), pose_runs),
        # summed in int64 ns: a sum of float seconds prints binary noise (41.199999999999996)
        ns_to_s(sum(execution_times_ns)),
        acc_runs,
        pose_runs,
    )
