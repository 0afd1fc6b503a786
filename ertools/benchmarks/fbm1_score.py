"""The FBM1 scoring rules of the 2015 node, with its bugs fixed unless asked for.

Per run (2015 ``fbm1h``/``fbm1w``): x and y errors in metres, theta error in degrees wrapped to
[-180, 180]; translation term t = hypot(dx, dy) clipped at 1 m, rotation term
r = |dtheta| / 180 clipped at 1; pose_score = 1 - t/2 - r/2. Class and instance are right when
the names match. Totals: class_accuracy and instance_accuracy = positives / runs, pose_score =
mean over the runs, execution_time = sum of the runs' goal-to-result times (seconds).

2015 quirks, reproduced by the ``legacy`` switches:

- ``clip``: the node compared t with the table diagonal sqrt(2) m and set larger errors to 1,
  leaving errors between 1 and 1.41 m unclipped, so a pose score could drop below 0.
- ``wrap``: theta errors were wrapped by a single +-360, so answers beyond +-540 deg kept a
  rotation term of 1 however close they were.
- ``names``: classes and instances were compared exactly; the 2015 ``fbm1w.yaml`` has the class
  ``"Bearing Boxes "`` with a trailing blank that no robot answer matched.
- ``totals``: the newest @Home node divided the accuracies by 10 (its number of runs) even when
  fewer runs were played, and both nodes counted a run aborted before its goal.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

# The 2015 @Home node played at most this many runs and divided the accuracies by it.
BENCHMARK_RUNS_2015 = 10
# The 2015 "maximum pose error": the diagonal of a 1 m x 1 m table.
MAX_POSE_ERROR_2015 = math.sqrt(2.0)


@dataclass(frozen=True)
class ScoreRules:
    """Which 2015 quirks to reproduce (all False: the fixed rules)."""

    legacy_clip: bool = False
    legacy_wrap: bool = False
    legacy_names: bool = False
    legacy_totals: bool = False

    @staticmethod
    def all_2015() -> ScoreRules:
        return ScoreRules(True, True, True, True)


@dataclass(frozen=True)
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
    dtheta = wrap_deg(raw, legacy=rules.legacy_wrap)
    t = trans_term(dist, legacy=rules.legacy_clip)
    r = rot_term(dtheta)
    score = 1.0 - t / 2.0 - r / 2.0
    old = 1.0 - trans_term(dist, legacy=True) / 2.0 - rot_term(wrap_deg(raw, legacy=True)) / 2.0
    new = 1.0 - trans_term(dist) / 2.0 - rot_term(wrap_deg(raw)) / 2.0
    return PoseErrors(dx, dy, dist, dtheta, t, r, score, abs(old - new) > 1e-12)


def names_match(answer: str, truth: str, rules: ScoreRules) -> bool:
    """Class or instance equality; blanks around names are ignored unless ``legacy_names``."""
    return answer == truth if rules.legacy_names else answer.strip() == truth.strip()


@dataclass(frozen=True)
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
    execution_times: list[float],
    *,
    aborted: int,
    benchmark: str,
    rules: ScoreRules,
) -> Totals:
    """Totals over the counted runs (every list has one entry per run that reached its goal).

    Runs without answer enter with False, False and pose score 0, as in 2015.
    """
    played = len(class_ok)
    acc_runs = played
    pose_runs = played
    if rules.legacy_totals:
        pose_runs = played + aborted
        acc_runs = BENCHMARK_RUNS_2015 if benchmark == "fbm1h" else pose_runs

    def ratio(num: float, den: int) -> float | None:
        return num / den if den else None

    return Totals(
        ratio(sum(class_ok), acc_runs),
        ratio(sum(instance_ok), acc_runs),
        ratio(math.fsum(pose_scores), pose_runs),
        math.fsum(execution_times),
        acc_runs,
        pose_runs,
    )
