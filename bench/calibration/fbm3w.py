"""FBM3@Work calibration trial: the simulator's five-run execution
(ertools.benchmarks.fbm3w.sample: 120 Hz mocap, 0.05 mm of noise per axis, one tracking loss,
run 4 timed out), its noisy Pose2D stream scored as ``ertools score fbm3w`` scores it
(``score_paths``, the noise measured from the stream's own stationary phases), against the
noiseless truth the simulator computes with its own Eq. (1) loop
(:func:`ertools.benchmarks.fbm3w.sample.eq1`, not the scorer's code) on the same published
frames without their noise: the poses a noiseless mocap would have sent, the tracking loss of
run 1 included (a lost frame is a validity question, item 2, not noise), in the same windows."""

from __future__ import annotations

import numpy as np

from ertools.benchmarks.fbm3w import sample as sim_fbm3w
from ertools.benchmarks.fbm3w.config import Fbm3wOptions
from ertools.benchmarks.fbm3w.pipeline import score_paths
from ertools.benchmarks.fbm3w.runs import RunWindow
from ertools.benchmarks.fbm3w.settings import Fbm3wConfig
from ertools.streams import PoseStream

POSE2D_AFTER_NS = 20_000  # the simulator records pose2d 20 us after the pose


def trial(seed: int, draws: int) -> list[tuple[str, float, float, float]]:
    sim = sim_fbm3w.simulate(seed)
    pub = sim.bodies[sim_fbm3w.BODY]
    poses = PoseStream(
        t_ns=np.asarray(pub.t_record_ns + POSE2D_AFTER_NS, dtype=np.int64),
        xyz=pub.xyz,
        quat_xyzw=pub.quat_xyzw,
        source="simulated:/fbm3w/robot_at_work/pose2d",
    )
    windows = [
        RunWindow(
            k,
            run["spec"],
            run["reference_ns"],
            run["start_ns"],
            run["end_ns"],
            run["status"],
            "windows",
        )
        for k, run in enumerate(sim.truth["runs"])
    ]
    result = score_paths(
        poses,
        windows,
        Fbm3wConfig(),
        options=Fbm3wOptions(draws=draws, seed=seed),
        bag_start_ns=sim.start_ns,
    )
    noiseless = (pub.xyz - pub.noise_xyz)[:, :2]
    t = poses.t_ns
    truth: dict[int, float] = {}
    for k, run in enumerate(sim.truth["runs"]):
        if run["status"] != "completed":
            continue
        m = (t >= run["start_ns"]) & (t <= run["end_ns"])
        ref_i = int(np.searchsorted(t, run["reference_ns"], side="right")) - 1
        truth[k] = sim_fbm3w.eq1(noiseless[ref_i], noiseless[m], run["spec"], sim_fbm3w.D_MIN)[0]
    rows: list[tuple[str, float, float, float]] = []
    for run in result.runs:
        if run.interval is None or run.index not in truth:
            continue
        key = f"runs_details.{run.index}.distance_error"
        rows.append((key, truth[run.index], run.interval.low, run.interval.high))
    if result.best_interval is not None and truth:
        best = result.best_interval
        rows.append(("best_distance_error", min(truth.values()), best.low, best.high))
    return rows
