"""FBM2@Home calibration trial: the simulator's five-waypoint execution
(ertools.benchmarks.fbm2h.sample: 120 Hz mocap, 0.2 mm and 0.5 mrad of noise, one tracking
loss while driving, a tilted marker set), its noisy marker stream scored as ``ertools score
fbm2h`` scores it (``compute`` then ``with_intervals``, the pure stages of ``score_runs``; the
reached moments are the logged ones: EXECUTING_GOAL to the Client's COMPLETED_GOAL), against
the simulator's noiseless truth (``expected``: the stop poses against the waypoints, with the
seed's formulas).

The transform is acquired as the 2015 node did, from one mocap sample with the robot on the
origin: the simulator's exact transform turned and shifted by one measurement's noise (the
error the scorer's stated default assumes), while the truth uses the exact one.
"""

from __future__ import annotations

import numpy as np
import yaml
from scipy.spatial.transform import Rotation

from ertools.benchmarks.fbm2h import sample as sim_fbm2h
from ertools.benchmarks.fbm2h.config import Fbm2hOptions
from ertools.benchmarks.fbm2h.goal import parse_goal
from ertools.benchmarks.fbm2h.intervals import with_intervals
from ertools.benchmarks.fbm2h.pipeline import compute
from ertools.benchmarks.fbm2h.runs import ReachedMoments
from ertools.configs.transform import MarkerTransform, parse_transform
from ertools.streams import PoseStream


def acquired(exact: MarkerTransform, rng: np.random.Generator) -> MarkerTransform:
    """``exact`` as one noisy mocap sample would give it: E^-1 T (E the marker's error)."""
    turn = Rotation.from_rotvec(rng.normal(0.0, sim_fbm2h.SIGMA_RAD, 3))
    t = turn.apply(np.asarray(exact.translation)) + np.append(
        rng.normal(0.0, sim_fbm2h.SIGMA_M, 2), 0.0
    )
    q = (turn * Rotation.from_quat(exact.quat_xyzw)).as_quat()
    return MarkerTransform(
        exact.robot_info,
        exact.timestamp,
        (float(t[0]), float(t[1]), float(t[2])),
        (float(q[0]), float(q[1]), float(q[2]), float(q[3])),
        source="acquired from one simulated sample",
    )


def trial(seed: int, draws: int) -> list[tuple[str, float, float, float]]:
    sim = sim_fbm2h.simulate(seed)
    pub = sim.bodies[sim_fbm2h.BODY]
    marker = PoseStream(
        t_ns=np.asarray(pub.t_header_ns, dtype=np.int64),
        xyz=pub.xyz,
        quat_xyzw=pub.quat_xyzw,
        source="simulated:/fbm2h/robot_at_home/pose",
    )
    goal = parse_goal(yaml.safe_load(sim.configs["fbm2h_goal.yaml"]), "fbm2h_goal.yaml")
    name = f"transform-{sim_fbm2h.TEAM}.yaml"
    exact = parse_transform(yaml.safe_load(sim.configs[name]), name)
    transform = acquired(exact, np.random.default_rng([seed, 28]))
    segments = sim.truth["segments"]
    moments = ReachedMoments(
        method="states",
        start_ns=np.array([s["start_ns"] for s in segments], dtype=np.int64),
        end_ns=np.array([s["end_ns"] for s in segments], dtype=np.int64),
        payloads=tuple("" for _ in segments),
    )
    options = Fbm2hOptions(draws=draws, seed=seed)
    result = compute(goal, transform, marker, moments, max_gap_s=options.max_gap_s)
    result = with_intervals(result, marker, transform, moments, options)
    iv = result.intervals
    if iv is None:
        return []
    expected = sim.expected
    rows: list[tuple[str, float, float, float]] = []
    for key, found in (
        ("position_accuracy", iv.position),
        ("orientation_accuracy", iv.orientation),
    ):
        if found is not None:
            rows.append((key, float(expected[key]), found.low, found.high))
    for k, seg in enumerate(expected["segments"]):
        for key, table, true_key in (
            ("distance_error", iv.distance, "distance_error"),
            ("orientation_error", iv.angle, "orientation_error"),
        ):
            found = table.get(k)
            if found is not None:
                rows.append((f"segments.{k}.{key}", float(seg[true_key]), found.low, found.high))
    return rows
