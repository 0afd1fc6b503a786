"""HOPF's arithmetic on arrays, once (docs/hopf.md, "Formula"; fbm1_objects_perception.py at
2bb8a41, l. 265-282 and 311-314). No IO, no options parsing: the rules arrive as arguments.

Per completed goal, with the answer (x_a, y_a, theta_a) and the ground truth (x_g, y_g,
theta_g), both in the table frame:

    x_err = x_a - x_g, y_err = y_a - y_g, w_err = theta_a - theta_g wrapped
    t = sqrt(x_err^2 + y_err^2)            (clipped at ``clip`` metres, or not: the script)
    r = min(|w_err| / pi, 1)
    pose_score = 1 - t/2 - r/2

The script's dead bands (``TRANS_ACCURACY``, ``ROT_ACCURACY``) are 0 and change nothing.
Totals: the sums of the correct classes, instances and pose scores over the goals counted,
divided by the divisor the rules give (the script: the goals begun).
"""

from __future__ import annotations

import math

import numpy as np

from ertools.arrays import F64
from ertools.frozen_dataclass import frozen_dataclass


@frozen_dataclass(eq=False)
class PoseTerms:
    """Per goal (n,): the pose errors and the terms of the pose score."""

    x_err: F64
    y_err: F64
    w_err: F64
    translation: F64
    rotation: F64
    pose_score: F64


def wrap_theta(w: F64, *, single: bool) -> F64:
    """The angle error wrapped: one step (the script, l. 269-270) or fully to [-pi, pi).

    A full wrap leaves an error already in [-pi, pi) bit for bit unchanged, so that the two
    agree wherever the single step suffices.
    """
    w = np.asarray(w, dtype=np.float64)
    if single:
        w = np.where(w > math.pi, w - 2 * math.pi, w)
        return np.where(w < -math.pi, w + 2 * math.pi, w)
    outside = (w >= math.pi) | (w < -math.pi)
    wrapped = np.mod(w + math.pi, 2 * math.pi) - math.pi
    return np.where(outside, wrapped, w)


def pose_terms(answer: F64, truth: F64, *, single_wrap: bool, clip: float | None) -> PoseTerms:
    """The errors and pose scores of (n, 3) answers against (n, 3) truths (x, y, theta)."""
    a = np.asarray(answer, dtype=np.float64).reshape(-1, 3)
    g = np.asarray(truth, dtype=np.float64).reshape(-1, 3)
    x_err = a[:, 0] - g[:, 0]
    y_err = a[:, 1] - g[:, 1]
    w_err = wrap_theta(a[:, 2] - g[:, 2], single=single_wrap)
    t = np.sqrt(x_err * x_err + y_err * y_err)
    if clip is not None:
        t = np.where(t > clip, clip, t)
    r = np.abs(w_err) / math.pi
    r = np.where(r > 1, 1.0, r)  # NaN stays NaN, as `if r > 1` left it
    return PoseTerms(x_err, y_err, w_err, t, r, 1 - t / 2 - r / 2)


def running_sum(values: F64) -> float:
    """The sum in order, one addition at a time, as the script's ``+=`` made it (NumPy's
    pairwise ``sum`` may differ in the last bit)."""
    v = np.asarray(values, dtype=np.float64)
    return float(np.cumsum(v)[-1]) if v.size else 0.0


@frozen_dataclass
class Totals:
    """The run's totals (None: nothing to divide)."""

    class_accuracy: float | None
    instance_accuracy: float | None
    pose_score: float | None


def totals(class_ok: np.ndarray, instance_ok: np.ndarray, pose_score: F64, divisor: int) -> Totals:
    """``positives / divisor`` and ``sum(pose_score) / divisor`` (l. 311-313): the arrays hold
    the goals whose results entered the sums (completed goals; a pose score of a goal without
    one is not in ``pose_score``)."""
    if divisor <= 0:
        return Totals(None, None, None)
    classes = float(np.count_nonzero(class_ok))
    instances = float(np.count_nonzero(instance_ok))
    return Totals(classes / divisor, instances / divisor, running_sum(pose_score) / divisor)
