"""Scenario ``robotlog``: a robot's own pose log and the GT logger's split files around it.

What ``rockin_offline_trajectory_benchmark`` was run on in 2015: the robot logged its estimate of
its marker set's pose on ``/rockin/<team>/marker_pose`` (PoseStamped, 10 Hz) in its own bag,
stamped with its own clock; the GT logger recorded the mocap pose of the same marker set
(``/fbm2h/robot_at_home/pose``, 120 Hz) into hourly split files ``log_..._0.bag``,
``log_..._1.bag``. Here, kept short:

- the robot drives an ellipse (about 20 s per lap, 0.3 to 0.5 m/s), heading along the path, so
  its yaw crosses +-pi every lap;
- the robot's estimate = truth + a known error: a constant bias, a slow sinusoidal drift and
  white noise on the position, a small yaw error;
- the robot's clock runs :data:`ROBOT_CLOCK_AHEAD_S` ahead of the GT clock (its stamps and
  its bag's record times are both on its clock): the offset to add to the robot stamps is
  ``-ROBOT_CLOCK_AHEAD_S``;
- GT file 0 covers the first part, file 1 starts :data:`SPLIT_GAP_S` after file 0 ends (the
  logger lost that stretch: a gap), and a tracking loss (Motive repeats the last pose for
  0.4 s) lies in file 0, another (repeats, then 0.3 s of nothing) in file 1.

Answers (``expected``), for ``max_gap`` 0.1 s and each association (``hold``, ``nearest``,
``linear``), with no offset (``offset_0``) and with the true offset applied (``offset_true``):
the counts of compared / gap / tracking-lost / uncovered poses and the position and orientation
errors. They are computed by :func:`expected_scores`, a plain per-pose loop over the published
arrays (bisect, hand-written lerp and SLERP), independent of ``ertools.benchmarks`` and of
``ertools.geometry``'s interpolation. ``truth.offset_s`` is what ``--offset auto`` must find.
"""

from __future__ import annotations

import bisect
import math
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from ertools.arrays import F64, I64
from ertools.geometry import quat_from_yaw
from ertools.simulator.answers import EPOCH_2015, log_name, tol, window, write_answers
from ertools.simulator.mocap import (
    MocapNoise,
    MocapPublished,
    TrackingLoss,
    frame_times,
    pose_topic,
    publish_environment,
    publish_mocap,
    simulate_mocap,
)
from ertools.simulator.writer import BagWriter

NS = 1_000_000_000
TEAM = "homer"
# The 2015 GT logger recorded FBM2@Home's marker set (/fbm2h/...): data; the trajectory
# benchmark is independent of fbm2h's package.
NAMESPACE = "fbm2h"
BODY = "robot_at_home"
ROBOT_TOPIC = f"/rockin/{TEAM}/marker_pose"
GT_TOPIC = pose_topic(NAMESPACE, BODY)

START_NS = EPOCH_2015 + 2 * 3600 * NS  # 12:00 UTC on the competition day
FILE_S = (22.0, 20.0)  # durations of GT files 0 and 1
SPLIT_GAP_S = 1.0  # GT file 1 starts this long after file 0 ends
ROBOT_FROM_S, ROBOT_TO_S = 2.0, 40.0  # robot log span, seconds after START on the GT clock
ROBOT_RATE_HZ = 10.0
ROBOT_CLOCK_AHEAD_S = 0.35
LOSSES_S = ((9.0, 48, 0), (30.0, 3, 36))  # (s after start, repeated frames, dropped frames)
MAX_GAP_S = 0.1

# The robot's estimation error (metres, radians).
BIAS_XYZ = (0.012, -0.008, 0.003)
DRIFT_AMPLITUDE = 0.01
DRIFT_PERIOD_S = 13.0
NOISE_SIGMA = 0.003
YAW_BIAS = 0.015
YAW_NOISE = 0.01

ASSOCIATIONS = ("hold", "nearest", "linear")


def truth_at(t_ns: I64) -> tuple[F64, F64]:
    """True marker position (N,3) and yaw (N,) at times ``t_ns`` (GT clock)."""
    s = (np.asarray(t_ns, dtype=np.int64) - START_NS) / NS
    w = 2.0 * math.pi / 20.0
    x = 1.6 * np.cos(w * s) + 0.2
    y = 1.0 * np.sin(w * s) - 0.1
    z = 0.45 + 0.002 * np.sin(0.5 * s)
    dx = -1.6 * w * np.sin(w * s)
    dy = 1.0 * w * np.cos(w * s)
    return np.column_stack([x, y, z]), np.arctan2(dy, dx)


def _gt_file(
    path: Path,
    t_start_ns: int,
    duration_s: float,
    losses: Sequence[tuple[float, int, int]],
    rng: np.random.Generator,
) -> MocapPublished:
    t = frame_times(t_start_ns, duration_s)
    xyz, yaw = truth_at(t)
    loss_list = [TrackingLoss(START_NS + round(s * NS), r, g) for s, r, g in losses]
    pub = simulate_mocap(t, xyz, quat_from_yaw(yaw), rng=rng, noise=MocapNoise(), losses=loss_list)
    rec_start = t_start_ns - 400_000_000
    with BagWriter(path, "ros1", compression="bz2") as bag:
        publish_mocap(bag, NAMESPACE, BODY, pub, pose2d=False)
        publish_environment(
            bag, NAMESPACE, rec_start, int(pub.t_record_ns[-1]), bag_name=path.name, bodies=[BODY]
        )
    return pub


def robot_estimate(rng: np.random.Generator) -> tuple[I64, F64, F64, F64, F64]:
    """(true times, estimated xyz, estimated yaw, true xyz, true yaw) of the robot's poses."""
    n = int((ROBOT_TO_S - ROBOT_FROM_S) * ROBOT_RATE_HZ) + 1
    period = round(NS / ROBOT_RATE_HZ)
    jitter = rng.integers(0, 2_000_000, size=n)  # the robot's loop is not exact
    tau = START_NS + round(ROBOT_FROM_S * NS) + np.arange(n, dtype=np.int64) * period + jitter
    xyz, yaw = truth_at(tau)
    s = (tau - START_NS) / NS
    drift = DRIFT_AMPLITUDE * np.column_stack(
        [np.sin(2 * math.pi * s / DRIFT_PERIOD_S), np.cos(2 * math.pi * s / DRIFT_PERIOD_S), 0 * s]
    )
    est_xyz = xyz + np.asarray(BIAS_XYZ) + drift + rng.normal(0.0, NOISE_SIGMA, size=(n, 3))
    est_yaw = yaw + YAW_BIAS + rng.normal(0.0, YAW_NOISE, size=n)
    est_yaw = (est_yaw + math.pi) % (2 * math.pi) - math.pi
    return tau, est_xyz, est_yaw, xyz, yaw


# --- the independent expected scores ----------------------------------------------------------


def _yaw_of(q: Sequence[float]) -> float:
    x, y, z, w = q
    return math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))


def _slerp(q0: Sequence[float], q1: Sequence[float], a: float) -> list[float]:
    dot = sum(u * v for u, v in zip(q0, q1, strict=True))
    if dot < 0.0:  # the shorter way round
        q1 = [-v for v in q1]
        dot = -dot
    if dot > 0.9999999:
        out = [u + a * (v - u) for u, v in zip(q0, q1, strict=True)]
    else:
        theta = math.acos(min(1.0, dot))
        s0 = math.sin((1.0 - a) * theta) / math.sin(theta)
        s1 = math.sin(a * theta) / math.sin(theta)
        out = [s0 * u + s1 * v for u, v in zip(q0, q1, strict=True)]
    norm = math.sqrt(sum(v * v for v in out))
    return [v / norm for v in out]


def expected_scores(
    robot_t: Sequence[int],
    robot_xyz: Sequence[Sequence[float]],
    robot_yaw: Sequence[float],
    gt_t: Sequence[int],
    gt_xyz: Sequence[Sequence[float]],
    gt_quat: Sequence[Sequence[float]],
    association: str,
    offset_ns: int,
    max_gap_ns: int,
) -> dict[str, Any]:
    """The trajectory scores by a plain loop over the robot poses (the rules of issue 7)."""
    counts = {"compared": 0, "gaps": 0, "tracking_lost": 0, "uncovered": 0}
    dists: list[float] = []
    dyaws: list[float] = []
    for t, p, ryaw in zip(robot_t, robot_xyz, robot_yaw, strict=True):
        q = t + offset_ns
        if q < gt_t[0] or q > gt_t[-1]:
            counts["uncovered"] += 1
            continue
        hi = bisect.bisect_left(gt_t, q)  # first GT at or after
        lo = bisect.bisect_right(gt_t, q) - 1  # last GT at or before
        if gt_t[hi] - gt_t[lo] > max_gap_ns:
            counts["gaps"] += 1
            continue
        if hi >= 1 and list(gt_xyz[hi - 1]) == list(gt_xyz[hi]):
            counts["tracking_lost"] += 1
            continue
        if association == "hold":
            g, gq = list(gt_xyz[lo]), list(gt_quat[lo])
        elif association == "nearest":
            k = lo if q - gt_t[lo] <= gt_t[hi] - q else hi
            g, gq = list(gt_xyz[k]), list(gt_quat[k])
        else:
            a = 0.0 if hi == lo else (q - gt_t[lo]) / (gt_t[hi] - gt_t[lo])
            g = [u + a * (v - u) for u, v in zip(gt_xyz[lo], gt_xyz[hi], strict=True)]
            gq = _slerp(gt_quat[lo], gt_quat[hi], a)
        counts["compared"] += 1
        dists.append(math.sqrt(sum((u - v) ** 2 for u, v in zip(p, g, strict=True))))
        d = ryaw - _yaw_of(gq)
        dyaws.append(abs(math.atan2(math.sin(d), math.cos(d))))
    out: dict[str, Any] = dict(counts)
    if dists:
        k = len(dists)
        out["position_error"] = sum(dists) / k
        out["rmse"] = math.sqrt(sum(d * d for d in dists) / k)
        ordered = sorted(dists)
        out["median"] = (ordered[(k - 1) // 2] + ordered[k // 2]) / 2
        out["max"] = ordered[-1]
        out["orientation_error"] = math.atan2(
            sum(math.sin(v) for v in dyaws), sum(math.cos(v) for v in dyaws)
        )
    return out


# --- the scenario -----------------------------------------------------------------------------


def generate(outdir: Path, *, seed: int) -> list[Path]:
    """Write the robot log, the two GT split files and the answers into ``outdir``."""
    rng = np.random.default_rng(seed)
    t0 = START_NS
    t1 = START_NS + round((FILE_S[0] + SPLIT_GAP_S) * NS)
    gt_paths = [
        outdir / log_name(f"{NAMESPACE}_mocap", START_NS - 400_000_000, index=i) for i in (0, 1)
    ]
    losses0 = [x for x in LOSSES_S if x[0] < FILE_S[0]]
    losses1 = [x for x in LOSSES_S if x[0] >= FILE_S[0]]
    pub0 = _gt_file(gt_paths[0], t0, FILE_S[0], losses0, rng)
    pub1 = _gt_file(gt_paths[1], t1, FILE_S[1], losses1, rng)

    tau, est_xyz, est_yaw, true_xyz, _true_yaw = robot_estimate(rng)
    ahead = round(ROBOT_CLOCK_AHEAD_S * NS)
    stamps = tau + ahead
    robot_path = outdir / f"FBM2H_201511201200_{TEAM}.bag"
    with BagWriter(robot_path, "ros1") as bag:
        # The robot's own recorder: record time = its stamp + 2 ms, on the robot's clock.
        bag.write_pose_stamped(
            ROBOT_TOPIC,
            stamps + 2_000_000,
            stamps,
            "world",
            est_xyz,
            quat_from_yaw(est_yaw),
            callerid=f"/rockin/{TEAM}/logger",
        )
        bag.write_string(
            f"/rockin/{TEAM}/command",
            np.array([stamps[0] - 500_000_000]),
            ["start"],
            callerid=f"/rockin/{TEAM}/logger",
        )

    gt_t = np.concatenate([pub0.t_header_ns, pub1.t_header_ns])
    gt_xyz = np.concatenate([pub0.xyz, pub1.xyz])
    gt_quat = np.concatenate([pub0.quat_xyzw, pub1.quat_xyzw])
    args = (stamps.tolist(), est_xyz.tolist(), est_yaw.tolist(), gt_t.tolist(), gt_xyz.tolist())
    max_gap = round(MAX_GAP_S * NS)
    expected: dict[str, Any] = {}
    for label, off in (("offset_0", 0), ("offset_true", -ahead)):
        expected[label] = {
            a: expected_scores(*args, gt_quat.tolist(), a, off, max_gap) for a in ASSOCIATIONS
        }
    # The robot's own error against the noiseless truth: what a perfect GT would show.
    true_err = float(np.mean(np.linalg.norm(est_xyz - true_xyz, axis=1)))

    answers = write_answers(
        [robot_path, *gt_paths],
        benchmark="robotlog",
        scenario="robotlog",
        seed=seed,
        parameters={
            "team": TEAM,
            "robot_topic": ROBOT_TOPIC,
            "gt_topic": GT_TOPIC,
            "robot_rate_hz": ROBOT_RATE_HZ,
            "robot_clock_ahead_s": ROBOT_CLOCK_AHEAD_S,
            "gt_files_s": list(FILE_S),
            "split_gap_s": SPLIT_GAP_S,
            "losses": [{"at_s": s, "repeat_frames": r, "gap_frames": g} for s, r, g in LOSSES_S],
            "max_gap_s": MAX_GAP_S,
            "error": {
                "bias_xyz": list(BIAS_XYZ),
                "drift_amplitude": DRIFT_AMPLITUDE,
                "drift_period_s": DRIFT_PERIOD_S,
                "noise_sigma": NOISE_SIGMA,
                "yaw_bias": YAW_BIAS,
                "yaw_noise": YAW_NOISE,
            },
        },
        truth={
            "offset_s": -ROBOT_CLOCK_AHEAD_S,
            "offset_ns": -ahead,
            "robot_window_gt_clock": window(int(tau[0]), int(tau[-1])),
            "robot_window_robot_clock": window(int(stamps[0]), int(stamps[-1])),
            "gt_files": [
                {"file": p.name, **window(int(pub.t_header_ns[0]), int(pub.t_header_ns[-1]))}
                for p, pub in zip(gt_paths, (pub0, pub1), strict=True)
            ],
            "robot_poses": len(stamps),
            "mean_error_vs_truth": true_err,
        },
        expected=expected,
        tolerance={
            "counts": tol(0, "counts are exact"),
            "errors": tol(
                1e-9, "same arrays as the bags; only summation order and SLERP form differ"
            ),
            "offset_s": tol(
                0.01,
                "10 ms: the robot's error (3 mm noise, 1 cm drift) at ~0.4 m/s limits the "
                "estimate to a few ms; 10 ms is 4 mm of travel, below the robot's error",
            ),
        },
    )
    return [robot_path, *gt_paths, answers]
