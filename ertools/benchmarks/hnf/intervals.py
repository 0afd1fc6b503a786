"""Confidence intervals of HNF's accuracies: the measured poses re-computed from perturbed
mocap samples, all Monte Carlo draws at once ((draws, segments) arrays). No IO.

The lookup's moment is logged exactly (the script's broadcast), so the only source is the
mocap's own noise (``mocap_noise``), measured from the marker set's track
(:mod:`ertools.rsbb.jitter`): the marker's position (normal, sigma per axis) and yaw; the yaw
swings the team transform's lever arm. Interpolating between two samples with weights w and
1 - w averages their noise: sigma times sqrt(w^2 + (1 - w)^2).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ertools.arrays import F64, Bool
from ertools.benchmarks.common.uncertainty import (
    MOCAP_NOISE,
    Interval,
    Source,
    Uncertainty,
    monte_carlo,
)
from ertools.benchmarks.hnf.config import HnfOptions
from ertools.benchmarks.hnf.logs import HnfLogs
from ertools.benchmarks.hnf.result import ORIENTATION_KEY, POSITION_KEY, HnfSegment
from ertools.geometry import wrap_angle
from ertools.rsbb.jitter import mocap_noise
from ertools.rsbb.tf import TfTrack, duration_sec, link_at

METHOD = "Monte Carlo (parametric bootstrap, basic interval)"


def averaging(track: TfTrack, t_ns: np.ndarray) -> F64:
    """sqrt(w^2 + (1 - w)^2) of the interpolation weights at ``t_ns`` (1 on a sample)."""
    t = track.t_ns
    right = np.clip(np.searchsorted(t, t_ns, side="right"), 1, len(t) - 1)
    span = duration_sec(t[right] - t[right - 1])
    w = np.where(span > 0, duration_sec(t_ns - t[right - 1]) / np.where(span > 0, span, 1.0), 0.0)
    w = np.clip(w, 0.0, 1.0)
    return np.asarray(np.sqrt(w**2 + (1.0 - w) ** 2))


def hnf_intervals(
    logs: HnfLogs,
    segments: Sequence[HnfSegment],
    summed: Bool,
    divisor: int,
    options: HnfOptions,
) -> tuple[dict[str, Interval | None], Uncertainty | None]:
    """The accuracies' intervals (empty without draws or without an accuracy)."""
    measured = [s for s in segments if s.measured and s.robot is not None]
    if options.draws <= 0 or divisor <= 0 or not measured:
        return {}, None
    keep = np.array([bool(summed[s.index]) for s in measured])
    t = np.array([s.flow.lookup_ns for s in measured], dtype=np.int64)
    robot = np.array([s.robot for s in measured], dtype=np.float64)
    target = np.array([[float(v) for v in s.waypoint] for s in measured])
    marker = link_at(logs.body, t).xyz[:, :2]
    lever = robot[:, :2] - marker
    factor = averaging(logs.body, t)
    noise = mocap_noise(logs.body)
    wrap = not options.orientation_2019
    fabs = options.script != "069fd1d"

    def scores(x: F64, y: F64, theta: F64) -> F64:
        d = np.hypot(x - target[:, 0], y - target[:, 1])
        dth = theta - target[:, 2]
        if wrap:
            dth = wrap_angle(dth)
        s, c = np.sin(np.abs(dth)), np.cos(np.abs(dth))
        sum_s = np.sum(s * keep, axis=-1)
        position = np.sum(d * keep, axis=-1) / divisor
        orientation = np.arctan2(np.abs(sum_s) if fabs else sum_s, np.sum(c * keep, axis=-1))
        return np.stack([position, orientation], axis=-1)

    def perturbed(rng: np.random.Generator, sources: frozenset[str], n: int) -> F64:
        del sources  # one source
        dxy = rng.normal(0.0, noise.sigma_m, (n, len(t), 2)) * factor[None, :, None]
        dpsi = rng.normal(0.0, noise.sigma_rad, (n, len(t))) * factor[None, :]
        cos, sin = np.cos(dpsi), np.sin(dpsi)
        lx = cos * lever[:, 0] - sin * lever[:, 1]
        ly = sin * lever[:, 0] + cos * lever[:, 1]
        x = marker[:, 0] + lx + dxy[..., 0]
        y = marker[:, 1] + ly + dxy[..., 1]
        return scores(x, y, robot[:, 2] + dpsi)

    estimate = scores(robot[:, 0], robot[:, 1], robot[:, 2])
    ivs = monte_carlo(
        estimate,
        perturbed,
        (MOCAP_NOISE,),
        draws=options.draws,
        seed=options.seed,
        confidence=options.confidence,
    )
    source = Source(MOCAP_NOISE, noise.sigma_m, "m", noise.measured, noise.note)
    keys = (POSITION_KEY, ORIENTATION_KEY)
    shares = {k: {MOCAP_NOISE: 1.0} for k, iv in zip(keys, ivs, strict=True) if iv is not None}
    block = Uncertainty(options.confidence, METHOD, options.draws, options.seed, (source,), shares)
    return dict(zip(keys, ivs, strict=True)), block
