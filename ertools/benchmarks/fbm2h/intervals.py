"""Confidence intervals of FBM2@Home's scores (issue 28): every segment's distance and
orientation errors and the two accuracies, re-computed from perturbed robot poses, all
Monte Carlo draws at once ((draws, segments) arrays). No IO here.

The robot pose at a reached moment is the marker pose there (interpolated between the two
GT samples around it) composed with the marker-to-robot transform. Sources
(:mod:`ertools.benchmarks.common.uncertainty`):

- ``mocap_noise``: the marker's position (normal, sigma per axis) and orientation (a small
  rotation: sigma_tilt about the two horizontal axes, sigma_yaw about the vertical) at the
  moment; sigma = epsilon / sqrt(pi) from the log's own stationary phases (as ``ertools
  noise --stationary auto``), the rotation sigmas = 1.4826 MAD / sqrt(2) of the relative
  rotations of consecutive still samples, per axis of the marker frame (a robust spread: a
  turn starting inside a phase does not count). The rotation swings the marker-to-robot lever
  arm: a marker set 0.85 m above the robot turns 0.5 mrad of tilt noise into 0.4 mm at the
  robot, twice the position noise itself. Interpolating between two samples with weights w,
  1 - w averages their noise: sigma times sqrt(w^2 + (1 - w)^2).
  Without a still phase: the 2015 FBM2 log's values (``transform.py``: ~0.8 mm per still
  step, 13 mrad RMS), stated as defaults.
- ``time_association``: where the pose was taken is as uncertain as the moment is on the GT
  clock: the GT stamps a frame anywhere inside its period, so the moment is off by up to half
  a period (uniform, the median frame period measured from the GT); the robot's velocity there
  (from the GT around the moment) turns that into a pose error. No clock audit exists between
  the state messages and the GT (both are stamped by the logging machine): no further offset.
- ``transform``: the marker-to-robot transform's error, common to every segment. A file
  written by ``ertools acquire transform`` carries the spread of the poses it averaged
  (``acquisition_spread``: per axis of the marker frame, and the number of independent poses
  they are worth): the error is that spread over the square root of the count, per axis
  (offset x, y; tilt x, y; yaw), measured. A file without it (older acquisitions,
  hand-written, the 2015 files) is taken as the 2015 node acquired it, a single tf sample with
  the robot on the origin: one mocap measurement's error (sigma per axis, the rotation
  sigmas, turning the lever arm as above), stated as a default.

Scores near zero are biased by noise (a distance cannot be negative); the basic interval
removes the bias the draws show.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import replace

import numpy as np

from ertools.arrays import F64
from ertools.benchmarks.common.epsilon import noise_from_stream
from ertools.benchmarks.common.hygiene import drop_invalid
from ertools.benchmarks.common.phases import phase_pairs, stationary_phases
from ertools.benchmarks.common.uncertainty import (
    MOCAP_NOISE,
    TIME_ASSOCIATION,
    TRANSFORM,
    Source,
    Uncertainty,
    monte_carlo,
    sigma_from_epsilon,
)
from ertools.benchmarks.fbm2h.config import Fbm2hOptions
from ertools.benchmarks.fbm2h.formula import robot_poses_at
from ertools.benchmarks.fbm2h.result import Fbm2hIntervals, Fbm2hResult
from ertools.benchmarks.fbm2h.runs import ReachedMoments
from ertools.configs.transform import MarkerTransform, TransformSpread
from ertools.errors import ScoringError
from ertools.frozen_dataclass import frozen_dataclass
from ertools.geometry import quat_conjugate, quat_multiply, rotate, wrap_angle
from ertools.streams import PoseStream
from ertools.timeutil import s_to_ns

METHOD = "Monte Carlo (parametric bootstrap, basic interval)"
# The 2015 FBM2 log's still marker set (ertools/benchmarks/fbm2h/acquire.py): ~0.8 mm per
# consecutive still pair (epsilon) and ~13 mrad RMS yaw.
DEFAULT_EPSILON_M = 0.0008
DEFAULT_SIGMA_YAW = 0.013
MAD_TO_SIGMA = 1.4826
MIN_PAIRS = 10


@frozen_dataclass(eq=False)
class Moments:
    """What the perturbed scorer needs of the K scored segments.

    Attributes:
        robot: (K, 3) robot x, y, yaw as scored.
        target: (K, 3) the waypoints.
        lever: (K, 3) the marker-to-robot offset in the world at the moment.
        heading: (K,) the marker's yaw at the moment (turns a transform error into the world).
        averaging: (K,) sqrt(w^2 + (1 - w)^2) of the interpolation (1: one sample).
        velocity: (K, 3) robot vx, vy, yaw rate at the moment (per second).
    """

    robot: F64
    target: F64
    lever: F64
    heading: F64
    averaging: F64
    velocity: F64


@frozen_dataclass
class Model:
    """The sources' sizes. ``transform_sd``: the transform's standard errors (offset x, y;
    tilt x, y; yaw) in the marker frame; None: one mocap measurement's (``sigma``,
    ``sigma_tilt``, ``sigma_yaw``)."""

    sigma: float
    sigma_tilt: float
    sigma_yaw: float
    half_period_s: float
    sources: tuple[Source, ...]
    transform_sd: tuple[float, float, float, float, float] | None = None

    def transform_errors(self) -> tuple[F64, F64, float]:
        """(offset (2,), tilt (2,), yaw) standard deviations of the transform's error."""
        if self.transform_sd is None:
            pair = np.array([self.sigma, self.sigma])
            return pair, np.array([self.sigma_tilt, self.sigma_tilt]), self.sigma_yaw
        x, y, tx, ty, yaw = self.transform_sd
        return np.array([x, y]), np.array([tx, ty]), yaw


def measure_model(marker: PoseStream, spread: TransformSpread | None = None) -> Model:
    """The sources' sizes from the marker stream (still phases, frame period) and the
    transform file's acquisition ``spread`` (None: the stated default)."""
    sigma = DEFAULT_EPSILON_M / math.sqrt(math.pi)
    sigma_tilt = sigma_yaw = DEFAULT_SIGMA_YAW
    measured = False
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
        rot = _rotation_sigmas(marker)
        if rot is not None:
            sigma_tilt, sigma_yaw = rot
            note += (
                f"; rotation sigma {sigma_tilt * 1000:.3g} mrad (tilt), {sigma_yaw * 1000:.3g} "
                "mrad (yaw): 1.4826 MAD / sqrt 2 of the still samples' relative rotations"
            )
        else:
            note += (
                f"; rotation sigma default {DEFAULT_SIGMA_YAW * 1000:g} mrad per axis (too few "
                "still pairs)"
            )
    else:
        note = (
            "default: no stationary phase in the GT; epsilon 0.8 mm and 13 mrad per rotation "
            "axis, the 2015 FBM2 log's still marker set"
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
    if spread is None:
        transform = Source(
            TRANSFORM,
            sigma,
            "m",
            False,
            f"default: the transform file carries no acquisition spread; as the 2015 node read "
            f"a single tf sample, one mocap measurement's error (sigma per axis, rotation "
            f"{sigma_tilt * 1000:.3g}/{sigma_yaw * 1000:.3g} mrad tilt/yaw), common to every "
            "segment",
        )
        return Model(sigma, sigma_tilt, sigma_yaw, half, (mocap, timing, transform))
    (px, py, _), (rx, ry, rz) = spread.standard_errors()
    mm = ", ".join(f"{v * 1000:.3g}" for v in spread.position_std)
    mrad = ", ".join(f"{v * 1000:.3g}" for v in spread.rotation_std)
    transform = Source(
        TRANSFORM,
        math.hypot(px, py) / math.sqrt(2.0),
        "m",
        True,
        f"the acquisition's spread: position {mm} mm, rotation {mrad} mrad (marker x, y, z) over "
        f"{spread.samples} poses worth {spread.effective_samples} independent ones; the "
        "error is spread / sqrt(that), per axis, common to every segment",
    )
    return Model(
        sigma, sigma_tilt, sigma_yaw, half, (mocap, timing, transform), (px, py, rx, ry, rz)
    )


def _rotation_sigmas(marker: PoseStream) -> tuple[float, float] | None:
    """(tilt, yaw) rotation noise sigmas from consecutive still samples, None if too few."""
    phases = stationary_phases(marker.t_ns, marker.xyz[:, :2])
    pairs = phase_pairs(phases, len(marker))
    if not pairs.any():
        return None
    q = marker.quat_xyzw
    rel = quat_multiply(quat_conjugate(q[:-1]), q[1:])[pairs]
    rel = rel * np.where(rel[:, 3:] < 0, -1.0, 1.0)  # the short way round
    rotvec = 2.0 * rel[:, :3]  # small angles: the vector part is half the rotation vector
    moved = np.isfinite(rotvec).all(axis=1) & np.any(rotvec != 0.0, axis=1)
    rotvec = rotvec[moved]  # a repeated pose is a lost frame, not noise
    if len(rotvec) < MIN_PAIRS:
        return None
    mad = np.median(np.abs(rotvec - np.median(rotvec, axis=0)), axis=0)
    sig = MAD_TO_SIGMA * mad / math.sqrt(2.0)
    return float(math.sqrt((sig[0] ** 2 + sig[1] ** 2) / 2.0)), float(sig[2])


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

    lx, ly, lz = m.lever[:, 0], m.lever[:, 1], m.lever[:, 2]

    def swing(rx: F64, ry: F64, rz: F64) -> tuple[F64, F64]:
        """The planar change of the lever turned by the small rotation (rx, ry, rz)."""
        return ry * lz - rz * ly, rz * lx - rx * lz

    if MOCAP_NOISE in sources:
        a = m.averaging
        x += rng.standard_normal((n, k)) * model.sigma * a
        y += rng.standard_normal((n, k)) * model.sigma * a
        rx = rng.standard_normal((n, k)) * model.sigma_tilt * a
        ry = rng.standard_normal((n, k)) * model.sigma_tilt * a
        rz = rng.standard_normal((n, k)) * model.sigma_yaw * a
        dx, dy = swing(rx, ry, rz)
        x, y, yaw = x + dx, y + dy, yaw + rz
    if TIME_ASSOCIATION in sources and model.half_period_s > 0:
        dt = rng.uniform(-model.half_period_s, model.half_period_s, size=(n, k))
        x += dt * m.velocity[:, 0]
        y += dt * m.velocity[:, 1]
        yaw += dt * m.velocity[:, 2]
    if TRANSFORM in sources:
        # one transform error for every segment of a draw, in the marker frame (turned into
        # the world with each segment's heading): an offset and a small rotation of the lever
        sd_offset, sd_tilt, sd_yaw = model.transform_errors()
        e = rng.standard_normal((n, 2)) * sd_offset
        tilt = rng.standard_normal((n, 2)) * sd_tilt
        t_yaw = rng.standard_normal((n, 1)) * sd_yaw
        c, s = np.cos(m.heading)[None, :], np.sin(m.heading)[None, :]
        x += c * e[:, :1] - s * e[:, 1:]
        y += s * e[:, :1] + c * e[:, 1:]
        rx = c * tilt[:, :1] - s * tilt[:, 1:]
        ry = s * tilt[:, :1] + c * tilt[:, 1:]
        dx, dy = swing(rx, ry, np.broadcast_to(t_yaw, (n, k)))
        x, y, yaw = x + dx, y + dy, yaw + t_yaw
    distance = np.hypot(x - m.target[:, 0], y - m.target[:, 1])
    dtheta = yaw - m.target[:, 2]
    angle = np.abs(dtheta) if orientation_2015 else np.abs(wrap_angle(dtheta))
    s, c = np.sin(angle), np.cos(angle)
    orientation = np.arctan2(s, c)
    position = distance.sum(axis=1) / divide_by
    accuracy = np.arctan2(s.sum(axis=1), c.sum(axis=1))
    return np.column_stack([position, accuracy, distance, orientation])


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


VELOCITY_FRAMES = 5


def with_intervals(
    result: Fbm2hResult,
    marker: PoseStream,
    transform: MarkerTransform,
    moments: ReachedMoments,
    options: Fbm2hOptions,
) -> Fbm2hResult:
    """``result`` with the intervals of its scores (:mod:`ertools.benchmarks.fbm2h.intervals`);
    unchanged with ``--draws 0`` or nothing scored."""
    ok = [s for s in result.segments if s.status == "ok" and s.robot is not None]
    if options.draws <= 0 or not ok:
        return result
    marker, _ = drop_invalid(marker)
    q = np.array([s.end_ns for s in ok], dtype=np.int64)
    gap = s_to_ns(options.max_gap_s)
    t_mr = transform.arrays()
    identity = (np.zeros(3), np.array([0.0, 0.0, 0.0, 1.0]))
    at_marker = robot_poses_at(marker, identity, q, gap)
    robot = np.array([s.robot for s in ok], dtype=np.float64)
    t = marker.t_ns
    nearest = np.clip(np.searchsorted(t, q), 0, len(t) - 1)
    lever = rotate(marker.quat_xyzw[nearest], np.broadcast_to(t_mr[0], (len(q), 3)).copy())
    lo = np.clip(np.searchsorted(t, q, side="right") - 1, 0, len(t) - 1)
    hi = np.clip(lo + 1, 0, len(t) - 1)
    span = (t[hi] - t[lo]).astype(np.float64)
    with np.errstate(invalid="ignore", divide="ignore"):
        w = np.where(span > 0, (q - t[lo]) / span, 0.0)
    interpolated = robot_poses_at(marker, t_mr, q, gap).interpolated
    averaging = np.where(interpolated, np.sqrt(w**2 + (1.0 - w) ** 2), 1.0)
    dts = np.diff(t)
    period = int(np.median(dts[dts > 0])) if np.any(dts > 0) else 0
    velocity = np.zeros((len(q), 3))
    if period > 0:
        # over 5 frames each side: one frame's difference would read the noise as motion
        base = VELOCITY_FRAMES * period
        after = robot_poses_at(marker, t_mr, q + base, gap).xyyaw
        before = robot_poses_at(marker, t_mr, q - base, gap).xyyaw
        step = after - before
        step[:, 2] = wrap_angle(step[:, 2])
        velocity = np.nan_to_num(step / (2 * base / 1e9))
    m = Moments(
        robot=robot,
        target=np.array([s.target for s in ok], dtype=np.float64),
        lever=np.nan_to_num(lever),
        heading=np.nan_to_num(at_marker.xyyaw[:, 2]),
        averaging=averaging,
        velocity=velocity,
    )
    indices = [s.index for s in ok]
    estimates = [
        result.position_accuracy,
        result.orientation_accuracy,
        *[s.distance_error for s in ok],
        *[s.orientation_error for s in ok],
    ]
    found = intervals(
        m,
        indices,
        estimates,
        measure_model(marker, transform.spread),
        orientation_2015=result.orientation_2015,
        divide_by=len(result.segments) if result.unscored_2015 else len(ok),
        draws=options.draws,
        seed=options.seed,
        confidence=options.confidence,
    )
    return replace(result, intervals=found)
