"""Calibration of the FBM1 intervals: one simulated FBM1@Home execution per trial.

The simulator (:func:`ertools.benchmarks.fbm1.sample.simulate`) draws the table, ten board
placements, the items' transforms, the robot's answers and the mocap noise of both marker sets
from the seed, and computes each run's true ground truth and score from the noiseless poses
with 4x4 matrices (``expected``). The item list the scorer is given is the one an acquisition would
have written (``ertools acquire items``): each item's transform measured as the mean of
``ACQUIRE_SAMPLES`` noisy samples, with their spread, so the transform source is exercised as
in real use. The noisy log is scored by the pure scorer :func:`~ertools.benchmarks.fbm1.
benchmark.score_fbm1` (what ``ertools score fbm1h`` calls), intervals included.

Returned per trial: every ground-truth-derived number of every scored run (ground truth x, y,
theta; errors x, y, translation, theta; pose score) and the pose score total.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from calibration import Row

ACQUIRE_SAMPLES = 240  # 2 s at 120 Hz, as ertools acquire items averages a still window
ACQUIRE_SIGMA_M = 3.0e-4  # per axis, per sample: the board relative to the origin
ACQUIRE_SIGMA_RAD = 7.0e-4


def _acquired(items: list[dict[str, Any]], rng: np.random.Generator) -> Any:
    """The item list an acquisition would write: transforms with their measurement error."""
    # lazy: the calibration imports fast; the simulator and scipy on demand
    from scipy.spatial.transform import Rotation

    from ertools.configs.items import Item, ItemList, ItemSpread

    out = []
    for it in items:
        pos = rng.normal(0.0, ACQUIRE_SIGMA_M, (ACQUIRE_SAMPLES, 3))
        rot = rng.normal(0.0, ACQUIRE_SIGMA_RAD, (ACQUIRE_SAMPLES, 3))
        mp, mr = pos.mean(axis=0), rot.mean(axis=0)
        spread = ItemSpread(
            position_m=float(np.sqrt(np.mean(np.sum((pos - mp) ** 2, axis=1)))),
            angle_deg=math.degrees(float(np.sqrt(np.mean(np.sum((rot - mr) ** 2, axis=1))))),
            samples=ACQUIRE_SAMPLES,
            start_s=0.0,
            end_s=2.0,
        )
        q = (Rotation.from_quat(it["rot"]) * Rotation.from_rotvec(mr)).as_quat()
        trans = np.asarray(it["trans"], dtype=np.float64) + mp
        out.append(
            Item(
                int(it["id"]),
                str(it["class"]),
                str(it["instance"]),
                (float(trans[0]), float(trans[1]), float(trans[2])),
                (float(q[0]), float(q[1]), float(q[2]), float(q[3])),
                spread,
            )
        )
    return ItemList(tuple(out), "acquired items (simulated)")


def score(seed: int, draws: int) -> tuple[Any, Any]:
    """(the simulated execution, its score with intervals)."""
    from ertools.benchmarks.common.inputs import IntervalSettings
    from ertools.benchmarks.fbm1.config import Fbm1Options
    from ertools.benchmarks.fbm1.pipeline import score_fbm1
    from ertools.benchmarks.fbm1.runs import runs_from_states
    from ertools.benchmarks.fbm1.sample import item_list, simulate
    from ertools.simulator.statemachine import state_messages
    from ertools.states import Machine
    from ertools.streams import PoseStream, StateStream

    rng = np.random.default_rng([seed, 1])
    items = item_list(np.random.default_rng([seed, 2]))
    sim = simulate(seed, items=items)
    streams = {}
    for body, pub in sim.bodies.items():
        streams[body] = PoseStream(pub.t_header_ns, pub.xyz, pub.quat_xyzw, "world", body)
    msgs = state_messages(sim.transitions, end_ns=sim.state_end_ns)
    states = {m: StateStream(m, s.t_ns, s.state, s.payload) for m, s in msgs.items()}
    found = runs_from_states(
        states[Machine.BMBOX],
        states.get(Machine.REFBOX),
        states.get(Machine.CLIENT),
        benchmark="fbm1h",
    )
    options = Fbm1Options("fbm1h", intervals=IntervalSettings(draws=draws, seed=seed))
    result = score_fbm1(
        streams["origin"],
        streams["ref_board"],
        found,
        _acquired(items, rng),
        options,
        t0_ns=sim.start_ns,
    )
    return sim, result


TRUE_KEYS = (
    ("ground_truth.x", "gt_x"),
    ("ground_truth.y", "gt_y"),
    ("ground_truth.theta", "gt_theta_deg"),
    ("error.x", "error_x"),
    ("error.y", "error_y"),
    ("error.translation", "error_translation"),
    ("error.theta", "error_theta_deg"),
    ("pose_score", "pose_score"),
)


def trial(seed: int, draws: int) -> list[Row]:
    sim, result = score(seed, draws)
    rows: list[Row] = []
    for exp in sim.expected["runs"]:
        if exp["status"] != "scored":
            continue
        for key, true_key in TRUE_KEYS:
            iv = result.intervals.get(f"runs.{exp['run']}.{key}")
            if iv is not None:
                rows.append((f"runs.{exp['run']}.{key}", float(exp[true_key]), iv.low, iv.high))
    iv = result.intervals.get("pose_score")
    if iv is not None:
        rows.append(("pose_score", float(sim.expected["totals"]["pose_score"]), iv.low, iv.high))
    return rows
