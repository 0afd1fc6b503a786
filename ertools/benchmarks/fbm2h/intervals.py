"""Confidence intervals of FBM2@Home's scores (issue 28): every segment's distance and
orientation errors and the two accuracies, re-computed from perturbed robot poses, all
Monte Carlo draws at once ((draws, segments) arrays). No IO here.

The robot pose at a reached moment is the marker pose there (interpolated between the two
GT samples around it) composed with the marker-to-robot transform. Sources
(:mod:`ertools.benchmarks.common.uncertainty`):

- ``mocap_noise``: the marker's position (normal, sigma per axis) and yaw (sigma_yaw) at the
  moment; sigma = epsilon / sqrt(pi) from the log's own stationary phases (as ``ertools
  noise --stationary auto``), sigma_yaw = 1.4826 MAD / sqrt(2) of the yaw differences of
  consecutive still samples (a robust spread: a turn starting inside a phase does not count).
  Interpolating between two samples with weights w, 1 - w averages their noise: sigma times
  sqrt(w^2 + (1 - w)^2). The marker's yaw noise also swings the marker-to-robot lever arm.
  Without a still phase: the 2015 FBM2 log's values (``transform.py``: ~0.8 mm per still
  step, 13 mrad RMS), stated as defaults.
- ``time_association``: where the pose was taken is as uncertain as the moment is on the GT
  clock: the GT stamps a frame anywhere inside its period, so the moment is off by up to half
  a period (uniform, the median frame period measured from the GT); the robot's velocity there
  (from the GT around the moment) turns that into a pose error. No clock audit exists between
  the state messages and the GT (both are stamped by the logging machine): no further offset.
- ``transform``: the marker-to-robot transform's error, common to every segment. A transform
  file does not carry how it was acquired: the 2015 node read a single tf sample with the
  robot on the origin, so its error is one mocap measurement's (sigma per axis, sigma_yaw),
  stated as a default.

Scores near zero are biased by noise (a distance cannot be negative); the basic interval
removes the bias the draws show.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ertools.arrays import F64
from ertools.benchmarks.common.phases import phase_pairs, stationary_phases
from ertools.benchmarks.common.uncertainty import (
    MOCAP_NOISE,
    TIME_ASSOCIATION,
    TRANSFORM,
    Interval,
    Source,
    Uncertainty,
    monte_carlo,
    sigma_from_epsilon,
)
from ertools.benchmarks.noise.benchmark import noise_from_stream
from ertools.errors import ScoringError
from ertools.geometry import wrap_angle, yaw_from_quat
from ertools.streams import PoseStream

METHOD = "Monte Carlo (parametric bootstrap, basic interval)"
# The 2015 FBM2 log's still marker set (ertools/benchmarks/fbm2h/transform.py): ~0.8 mm per
# consecutive still pair (epsilon) and ~13 mrad RMS yaw.
DEFAULT_EPSILON_M = 0.0008
DEFAULT_SIGMA_YAW = 0.013
MAD_TO_SIGMA = 1.4826
MIN_YAW_PAIRS = 10


@dataclass(frozen=True, eq=False)
class Moments:
    """What the perturbed scorer needs of the K scored segments.

    Attributes:
        robot: (K, 3) robot x, y, yaw as scored.
        target: (K, 3) the waypoints.
        lever: (K, 2) the marker-to-robot offset in the world plane at the moment.
        averaging: (K,) sqrt(w^2 + (1 - w)^2) of the interpolation (1: one sample).
        velocity: (K, 3) robot vx, vy, yaw rate at the moment (per second).
    """

    robot: F64
    target: F64
    lever: F64
    averaging: F64
    velocity: F64


@dataclass(frozen=True)
class Model:
    """The sources' sizes."""

    sigma: float
    sigma_yaw: float
    half_period_s: float
    transform_sigma: float
    transform_sigma_yaw: float
    sources: tuple[Source, ...]


def measure_model(marker: PoseStream) -> Model:
    """The sources' sizes from the marker stream (still phases, frame period)."""
    sigma, sigma_yaw, measured, note = (
        DEFAULT_EPSILON_M / math.sqrt(math.pi),
        DEFAULT_SIGMA_YAW,
        False,
        "",
    )
    try:
        noise = noise_from_stream(marker, stationary=True)
    except ScoringError:
        noise = None
    if noise is not None and noise.distances.size >= 2 and noise.epsilon > 0:
        sigma = sigma_from_epsilon(noise.epsilon)
        measured = True
        note = (
            f"sigma = epsilon / sqrt(pi), epsilon {noise.epsilon * 1000:.4g} mm from "
            f"{noise.distances.size} pairs over {noise.duration_s:.1f} s of stationary phases"
        )
        yaw = _yaw_sigma(marker)
        if yaw is not None:
            sigma_yaw = yaw
            note += f"; yaw sigma {yaw * 1000:.3g} mrad (1.4826 MAD / sqrt 2 of still yaw steps)"
        else:
            note += f"; yaw sigma default {DEFAULT_SIGMA_YAW * 1000:g} mrad (too few still pairs)"
    else:
        note = (
            "default: no stationary phase in the GT; epsilon 0.8 mm and yaw sigma 13 mrad, "
            "the 2015 FBM2 log's still marker set"
        )
    dt = np.diff(marker.t_ns)
    dt = dt[dt > 0]
    half = float(np.median(dt)) / 2e9 if dt.size else 0.0
    mocap = Source(MOCAP_NOISE, sigma, "m", measured, note)
    timing = Source(
        TIME_ASSOCIATION,
        half,
        "s",
        bool(dt.size),
        f"uniform within half the median GT frame period ({half * 2e3:.3g} ms), times the "
        "robot's velocity at the moment; no clock offset between states and GT (same machine)",
    )
    transform = Source(
        TRANSFORM,
        sigma,
        "m",
        False,
        f"default: the transform file carries no acquisition spread; as the 2015 node read a "
        f"single tf sample, one mocap measurement's error (sigma per axis, yaw "
        f"{sigma_yaw * 1000:.3g} mrad), common to every segment",
    )
    return Model(sigma, sigma_yaw, half, sigma, sigma_yaw, (mocap, timing, transform))


def _yaw_sigma(marker: PoseStream) -> float | None:
    xy = marker.xyz[:, :2]
    phases = stationary_phases(marker.t_ns, xy)
    pairs = phase_pairs(phases, len(marker))
    if not pairs.any():
        return None
    yaw = yaw_from_quat(marker.quat_xyzw)
    d = wrap_angle(np.diff(yaw))[pairs]
    d = d[np.isfinite(d) & (d != 0.0)]  # a repeated pose is a lost frame, not noise
    if d.size < MIN_YAW_PAIRS:
        return None
    mad = float(np.median(np.abs(d - np.median(d))))
    return MAD_TO_SIGMA * mad / math.sqrt(2.0)


def perturbed_scores(
    m: Moments,
    model: Model,
    rng: np.random.Generator,
    sources: frozenset[str],
    n: int,
    *,
    orientation_2015: bool,
    divide_by: int,
) -> F64:
    """(n, 2 + 2K) draws of [position_accuracy, orientation_accuracy, distance errors...,
    orientation errors...]."""
    k = len(m.robot)
    x = np.broadcast_to(m.robot[:, 0], (n, k)).copy()
    y = np.broadcast_to(m.robot[:, 1], (n, k)).copy()
    yaw = np.broadcast_to(m.robot[:, 2], (n, k)).copy()

    def swing(angle: F64, lever: F64) -> tuple[F64, F64]:
        """The change of a lever (K, 2) turned by ``angle`` (n, K)."""
        c, s = np.cos(angle) - 1.0, np.sin(angle)
        return c * lever[:, 0] - s * lever[:, 1], s * lever[:, 0] + c * lever[:, 1]

    if MOCAP_NOISE in sources:
        a = m.averaging
        x += rng.standard_normal((n, k)) * model.sigma * a
        y += rng.standard_normal((n, k)) * model.sigma * a
        dyaw = rng.standard_normal((n, k)) * model.sigma_yaw * a
        dx, dy = swing(dyaw, m.lever)
        x, y, yaw = x + dx, y + dy, yaw + dyaw
    if TIME_ASSOCIATION in sources and model.half_period_s > 0:
        dt = rng.uniform(-model.half_period_s, model.half_period_s, size=(n, k))
        x += dt * m.velocity[:, 0]
        y += dt * m.velocity[:, 1]
        yaw += dt * m.velocity[:, 2]
    if TRANSFORM in sources:
        # one transform error for every segment of a draw: lever offset in the marker frame
        # (turned into the world with each segment's heading) and a yaw offset
        t_lever = rng.standard_normal((n, 2)) * model.transform_sigma
        t_yaw = rng.standard_normal((n, 1)) * model.transform_sigma_yaw
        heading = m.robot[:, 2][None, :]
        c, s = np.cos(heading), np.sin(heading)
        x += c * t_lever[:, :1] - s * t_lever[:, 1:]
        y += s * t_lever[:, :1] + c * t_lever[:, 1:]
        dx, dy = swing(np.broadcast_to(t_yaw, (n, k)), m.lever)
        x, y, yaw = x + dx, y + dy, yaw + t_yaw
    distance = np.hypot(x - m.target[:, 0], y - m.target[:, 1])
    dtheta = yaw - m.target[:, 2]
    angle = np.abs(dtheta) if orientation_2015 else np.abs(wrap_angle(dtheta))
    s, c = np.sin(angle), np.cos(angle)
    orientation = np.arctan2(s, c)
    position = distance.sum(axis=1) / divide_by
    accuracy = np.arctan2(s.sum(axis=1), c.sum(axis=1))
    return np.column_stack([position, accuracy, distance, orientation])


@dataclass(frozen=True)
class Fbm2hIntervals:
    """The intervals of one result: accuracies, then per scored segment index."""

    position: Interval | None
    orientation: Interval | None
    distance: dict[int, Interval | None]
    angle: dict[int, Interval | None]
    uncertainty: Uncertainty


def intervals(
    m: Moments,
    indices: Sequence[int],
    estimates: Sequence[float | None],
    model: Model,
    *,
    orientation_2015: bool,
    divide_by: int,
    draws: int,
    seed: int,
    confidence: float,
) -> Fbm2hIntervals:
    """Intervals of ``estimates`` = [position_accuracy, orientation_accuracy, the K distance
    errors, the K orientation errors] (None for an accuracy that is null)."""
    est = np.array([math.nan if v is None else v for v in estimates], dtype=np.float64)

    def perturbed(rng: np.random.Generator, sources: frozenset[str], n: int) -> F64:
        return perturbed_scores(
            m, model, rng, sources, n, orientation_2015=orientation_2015, divide_by=divide_by
        )

    names = tuple(s.name for s in model.sources)
    ivs = monte_carlo(
        est,
        perturbed,
        names,
        draws=draws,
        seed=seed,
        confidence=confidence,
        nonnegative=not orientation_2015,
    )
    k = len(indices)
    distance = {i: ivs[2 + j] for j, i in enumerate(indices)}
    angle = {i: ivs[2 + k + j] for j, i in enumerate(indices)}
    shares: dict[str, dict[str, float]] = {}
    for key, iv in (("position_accuracy", ivs[0]), ("orientation_accuracy", ivs[1])):
        if iv is not None:
            shares[key] = iv.share_dict()
    for i in indices:
        for key, table in (("dinstance_error", distance), ("orientation_error", angle)):
            iv = table[i]
            if iv is not None:
                shares[f"details.segments_details.{i}.{key}"] = iv.share_dict()
    block = Uncertainty(confidence, METHOD, draws, seed, model.sources, shares)
    return Fbm2hIntervals(ivs[0], ivs[1], distance, angle, block)
