"""Scenario ``stationary``: the FBM3@Work marker set lying still, for noise statistics.

What ``mocap_noise_statistics`` (seed 7.3.13) was run on: 50 s of ``/fbm3w/robot_at_work/pose``
at 120 Hz with a known isotropic position noise and three tracking losses with known numbers
of repeated frames and dropped frames; plus the usual static ``world -> map``, map topics and
``/rosout``.

Answers (``expected``):

- ``samples``: pose messages in the bag; ``repeats``: messages that repeat the previous
  measurement (tracking loss); ``dropped``: frames with no message.
- ``epsilon_formula``: the mean distance between consecutive measurements for isotropic
  Gaussian noise of per-axis sd ``sigma``: the difference of two independent samples has
  per-axis sd ``sigma*sqrt(2)``, and the mean of a chi distribution with 3 degrees of freedom
  is ``2*sqrt(2/pi)``, so ``E|d| = sigma*sqrt(2)*2*sqrt(2/pi) = 4*sigma/sqrt(pi)``.
- ``epsilon``: the same mean measured on the simulated noise, over consecutive pairs of
  messages whose positions differ (repeats excluded; pairs across a gap count, the body is
  still). A scorer reading the bag must find this value up to float rounding.
- ``epsilon_xy`` / ``epsilon_xy_formula``: the same in the (x, y) plane, the distance the
  2015 ``mocap_noise_statistics`` tool histogrammed: chi with 2 degrees of freedom has mean
  ``sqrt(pi/2)``, so ``E|d_xy| = sigma*sqrt(2)*sqrt(pi/2) = sigma*sqrt(pi)``.
- ``pairs``: consecutive message pairs (``samples - 1``); ``lost``: pairs with identical poses
  (= ``repeats``, what the 2015 tool counted as lost).
- ``sigma_xyz``: the sample standard deviation of the published positions per axis.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from ertools.geometry import quat_from_yaw
from ertools.simulator.answers import EPOCH_2015, log_name, tol, window, write_answers
from ertools.simulator.mocap import (
    MocapNoise,
    TrackingLoss,
    frame_times,
    pose_topic,
    publish_environment,
    publish_mocap,
    quat_multiply,
    simulate_mocap,
    small_rotation,
)
from ertools.simulator.writer import BagWriter

# The 2015 noise recording was made on FBM3@Work's marker set and topics: data, and noise
# sits below fbm3w (fbm3w suggests d_min from it), so it does not import fbm3w's constant.
NAMESPACE = "fbm3w"
BODY = "robot_at_work"
DURATION_S = 50.0
SIGMA_M = 2.0e-4
SIGMA_RAD = 5.0e-4
POSITION = (1.234, -0.567, 0.912)
RPY = (0.02, -0.03, 0.7)
# (seconds after start, repeated frames, dropped frames)
LOSSES = ((11.0, 3, 0), (23.5, 5, 12), (37.25, 4, 30))


def generate(outdir: Path, *, seed: int) -> list[Path]:
    """Write the stationary log and its answers into ``outdir``."""
    rng = np.random.default_rng(seed)
    start = EPOCH_2015 - 3600 * 1_000_000_000  # an hour before the benchmarks
    t0 = start + 1_000_000_000  # the mocap stream starts a second after the recorder
    t = frame_times(t0, DURATION_S)
    n = t.size
    xyz = np.tile(np.asarray(POSITION), (n, 1))
    q0 = quat_multiply(quat_from_yaw(RPY[2]), small_rotation(np.array([RPY[0], RPY[1], 0.0])))
    quat = np.tile(q0, (n, 1))
    losses = [TrackingLoss(t0 + round(s * 1e9), r, g) for s, r, g in LOSSES]
    noise = MocapNoise(sigma_m=SIGMA_M, sigma_rad=SIGMA_RAD)
    pub = simulate_mocap(t, xyz, quat, rng=rng, noise=noise, losses=losses)

    bag_path = outdir / log_name(f"{NAMESPACE}_noise", start)
    end = int(pub.t_record_ns[-1]) + 50_000_000
    with BagWriter(bag_path, "ros1") as bag:
        publish_mocap(bag, NAMESPACE, BODY, pub)
        publish_environment(bag, NAMESPACE, start, end, bag_name=bag_path.name, bodies=[BODY])

    # Expected values from the simulation arrays (not from reading the bag back).
    diffs = np.diff(pub.xyz, axis=0)
    moved = np.any(diffs != 0.0, axis=1)
    dist = np.linalg.norm(diffs[moved], axis=1)
    epsilon = float(dist.mean())
    epsilon_formula = SIGMA_M * math.sqrt(2.0) * 2.0 * math.sqrt(2.0 / math.pi)
    dist_xy = np.hypot(diffs[moved, 0], diffs[moved, 1])
    epsilon_xy_formula = SIGMA_M * math.sqrt(2.0) * math.sqrt(math.pi / 2.0)
    # Standard error of the mean distance: sd of |d| is s*sqrt(k - mean_chi_k^2) with
    # s = sigma*sqrt(2) (k = 3: 3 - 8/pi; k = 2: 2 - pi/2); consecutive differences share a
    # sample (correlated), so allow 6 standard errors.
    s_diff = SIGMA_M * math.sqrt(2.0)
    stderr = s_diff * math.sqrt(3.0 - 8.0 / math.pi) / math.sqrt(dist.size)
    stderr_xy = s_diff * math.sqrt(2.0 - math.pi / 2.0) / math.sqrt(dist.size)
    sigma_xyz = pub.xyz.std(axis=0, ddof=1)

    answers = write_answers(
        bag_path,
        benchmark="stationary",
        scenario="stationary",
        seed=seed,
        parameters={
            "namespace": NAMESPACE,
            "body": BODY,
            "topic": pose_topic(NAMESPACE, BODY),
            "rate_hz": 120.0,
            "duration_s": DURATION_S,
            "sigma_m": SIGMA_M,
            "sigma_rad": SIGMA_RAD,
            "latency_ns": noise.latency_ns,
            "header_jitter_ns": noise.header_jitter_ns,
            "losses": [{"at_s": s, "repeat_frames": r, "gap_frames": g} for s, r, g in LOSSES],
        },
        truth={
            "window": window(int(pub.t_header_ns[0]), int(pub.t_header_ns[-1])),
            "position": list(POSITION),
            "quat_xyzw": q0,
            "frames": int(n),
        },
        expected={
            "samples": len(pub),
            "pairs": len(pub) - 1,
            "lost": int((~moved).sum()),
            "repeats": int(pub.repeated.sum()),
            "dropped": pub.dropped,
            "moving_pairs": int(dist.size),
            "epsilon": epsilon,
            "epsilon_formula": epsilon_formula,
            "epsilon_xy": float(dist_xy.mean()),
            "epsilon_xy_formula": epsilon_xy_formula,
            "sigma_xyz": sigma_xyz,
            "mean_position": pub.xyz.mean(axis=0),
        },
        tolerance={
            "samples": tol(0, "counts are exact"),
            "epsilon": tol(1e-12, "same samples as the bag; only float summation order differs"),
            "epsilon_formula": tol(
                6 * stderr,
                f"sampling error of a mean over {dist.size} pairs: 6 standard errors "
                "(consecutive differences are correlated)",
            ),
            "epsilon_xy": tol(1e-12, "same samples as the bag"),
            "epsilon_xy_formula": tol(
                6 * stderr_xy, f"sampling error of a mean over {dist.size} pairs: 6 standard errors"
            ),
            "sigma_xyz": tol(1e-12, "same samples as the bag"),
            "mean_position": tol(1e-12, "same samples as the bag"),
            "mean_position_vs_truth": tol(
                4 * SIGMA_M / math.sqrt(len(pub)),
                "mean of the noisy samples vs truth.position: 4 standard errors",
            ),
        },
    )
    return [bag_path, answers]
