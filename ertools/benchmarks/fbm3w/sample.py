"""Scenario ``fbm3w``: an FBM3@Work benchmark of five runs, the last one ended by a timeout.

Runs follow seed Listing 14 (line, spline, line, spline, line) with the Listing 15 shapes
(``line`` = line_path, ``spline`` = sine). For run k the printed path lies at a known place and
angle on the table; the end effector (marker set ``robot_at_work``, 120 Hz mocap, 0.05 mm of
noise per axis) does, per run::

    stationary at the reference position (manual operation; COMPLETED_MANUAL_OPERATION = the
      reference time), straight 8 cm approach to the starting position (TRANSMITTING_GOAL),
    stationary at the start (EXECUTING_GOAL, WAITING_RESULT: the path window opens),
    the path: target + a known smooth deviation of a few mm (minimum-jerk timing),
    stationary at the end (Client COMPLETED_GOAL, BmBox READY: the path window closes),
    a return move to the next reference position.

Run 4 is slow: 5 s into its path the RefBox ends the benchmark with payload ``timeout``; the
BmBox returns to READY, transmits the score and ends. One tracking loss (3 repeated frames, 6
dropped) happens during run 1's path.

Written as a ROS1 bag and, with the same messages, as a rosbag2 directory with MCAP storage;
one answers file lists both. ``fbm3w.yaml`` beside them is the config (Listing 14, d_min).

Answers (``expected``), from the noiseless truth at the 120 Hz frames, with the seed's
formulas (7.3.1-7.3.2) written out in :func:`eq1` as a plain loop (no ertools scorer code):
per run ``distance_error`` with ``D_MIN`` = 0.00033 m, ``execution_time`` = BmBox leaving
WAITING_RESULT - entering EXECUTING_GOAL, ``status``; ``best_run``, ``best_distance_error``,
``execution_time`` (sum over every run, the timed-out one included); ``noise`` for the
stationary phases (epsilon = sigma*sqrt(pi) in the plane). ``expected.published`` is what the
live node computed from the noisy Pose2D messages it received (the same loop on the published
arrays), also the BmBox score payload; a ``states`` scorer must match it to float rounding.
``truth.runs`` has the windows (ns and seconds from the bag's first message) and
``truth.phases`` the stationary phases.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt
import yaml

from ertools.arrays import F64
from ertools.geometry import quat_from_yaw
from ertools.simulator.answers import (
    EPOCH_2015,
    given_tol,
    log_name,
    tol,
    window,
    write_answers,
)
from ertools.simulator.mocap import (
    MocapNoise,
    TrackingLoss,
    frame_times,
    publish_environment,
    publish_mocap,
    simulate_mocap,
)
from ertools.simulator.simulated import SimulatedRun
from ertools.simulator.statemachine import Transition, publish_states
from ertools.simulator.writer import BagWriter
from ertools.states import BmBoxState, ClientState, Machine, RefBoxState

Motion = Callable[[F64], F64]  # time (s from the mocap start) -> (N, 2) world positions
S = 1_000_000_000

NAMESPACE = "fbm3w"
CONFIG_FILE = "fbm3w.yaml"
NOON_NS = EPOCH_2015 + 2 * 3600 * S
BODY = "robot_at_work"
SIGMA_M = 5.0e-5
D_MIN = 0.00033  # the 2015 script's D_MIN
SPECS = ("line", "spline", "line", "spline", "line")
# Deviation amplitude of each run (m): run 2 is the most accurate.
AMPLITUDE = (0.0020, 0.0030, 0.0008, 0.0040, 0.0025)
PATH_S = {"line": 3.0, "spline": 4.5}
TIMEOUT_RUN = 4
TIMEOUT_PATH_S = 8.0  # run 4 moves slowly ...
TIMEOUT_AFTER_S = 5.0  # ... and the RefBox gives up 5 s into its path
BASELINE_M = 0.08  # reference -> start
Z_M = 0.78
# Phase durations (s) within a run, from the robot's arrival at the reference position.
CMO_AT = 0.8  # COMPLETED_MANUAL_OPERATION
TG_AT = 0.9  # TRANSMITTING_GOAL
APPROACH = (1.0, 0.6)  # start, duration
EG_AT = 2.0  # EXECUTING_GOAL (WAITING_RESULT 10 ms later)
PATH_AT = 2.5
DONE_AFTER = 0.5  # BmBox leaves WAITING_RESULT this long after the robot stops
RETURN_AFTER = 0.9
RETURN_S = 1.0
LOSS = (1, 2.0, 3, 6)  # run, seconds into its path, repeated frames, dropped frames


def target(spec: str, l_norm: F64) -> F64:
    """Seed Listing 15, written out again: line_path and sine (= spline_path)."""
    ll = np.asarray(l_norm, dtype=np.float64)
    if spec == "line":
        return np.column_stack([0.15 * ll, 0.045 * ll])
    return np.column_stack([0.15 * ll, 0.075 * np.sin(12.5 * math.pi * 0.15 * ll)])


def deviation(k: int, u: F64, amplitude: tuple[float, ...] = AMPLITUDE) -> F64:
    """The robot's smooth deviation from the target in run k's frame (0 at the start)."""
    a = amplitude[k]
    return a * np.column_stack(
        [0.3 * np.sin(2 * math.pi * u), np.sin(math.pi * u / 2) + 0.2 * np.sin(3 * math.pi * u)]
    )


def min_jerk(s: F64) -> F64:
    """0 -> 1 with zero speed and acceleration at both ends."""
    s = np.clip(s, 0.0, 1.0)
    return np.asarray(s**3 * (10 - 15 * s + 6 * s**2))


def run_placement(k: int) -> tuple[F64, float]:
    """(starting position in world, frame angle) of run k: the sheet moves a little per run."""
    start = np.array([1.50 + 0.012 * k, 0.90 - 0.007 * k])
    theta = 0.35 + 0.03 * k * (-1) ** k
    return start, theta


def to_world(k: int, xy_frame: F64) -> F64:
    start, theta = run_placement(k)
    c, s = math.cos(theta), math.sin(theta)
    return np.column_stack(
        [
            start[0] + c * xy_frame[:, 0] - s * xy_frame[:, 1],
            start[1] + s * xy_frame[:, 0] + c * xy_frame[:, 1],
        ]
    )


def reference_of(k: int) -> F64:
    start, theta = run_placement(k)
    return start - BASELINE_M * np.array([math.cos(theta), math.sin(theta)])


def eq1(reference: F64, positions: F64, spec: str, d_min: float) -> tuple[float, int, float]:
    """Seed Eq. (1) with the 7.3.2 subsampling, as a plain loop: (error, kept, L)."""
    kept = [positions[0]]
    for p in positions[1:]:
        if math.hypot(p[0] - kept[-1][0], p[1] - kept[-1][1]) >= d_min:
            kept.append(p)
    start = kept[0]
    yaw = math.atan2(start[1] - reference[1], start[0] - reference[0])
    c, s = math.cos(yaw), math.sin(yaw)
    total = sum(math.hypot(b[0] - a[0], b[1] - a[1]) for a, b in itertools.pairwise(kept))
    length = 0.0
    error_sum = 0.0
    for a, b in itertools.pairwise(kept):
        length += math.hypot(b[0] - a[0], b[1] - a[1])
        dx, dy = b[0] - start[0], b[1] - start[1]
        fx, fy = c * dx + s * dy, -s * dx + c * dy
        tx, ty = target(spec, np.array([length / total]))[0]
        error_sum += math.hypot(fx - tx, fy - ty)
    return error_sum / len(kept), len(kept), total


def simulate(
    seed: int, *, start_ns: int = NOON_NS, amplitude: tuple[float, ...] = AMPLITUDE
) -> SimulatedRun:
    """One FBM3@Work execution whose recorder starts at ``start_ns`` (module docstring);
    ``amplitude`` (m, one per run) is how far the robot strays from each path."""
    rng = np.random.default_rng(seed)
    start = start_ns
    t0 = start + S // 2  # mocap starts half a second after the recorder
    tr: list[Transition] = []

    def add(t_s: float, machine: Machine, state: int, payload: str = "") -> int:
        t_ns = t0 + round(t_s * S)
        tr.append(Transition(t_ns, machine, state, payload))
        return t_ns

    add(0.05, Machine.REFBOX, RefBoxState.START)
    add(0.10, Machine.BMBOX, BmBoxState.START)
    add(0.10, Machine.CLIENT, ClientState.START)
    add(0.15, Machine.REFBOX, RefBoxState.WAITING_CLIENT)
    add(0.20, Machine.BMBOX, BmBoxState.WAITING_CLIENT)
    add(0.20, Machine.CLIENT, ClientState.CONNECTING)
    add(0.40, Machine.CLIENT, ClientState.READY)
    add(0.45, Machine.REFBOX, RefBoxState.READY)
    add(0.50, Machine.BMBOX, BmBoxState.READY)
    add(0.50, Machine.CLIENT, ClientState.WAITING_GOAL)

    # Piecewise motion, as (t_from, t_to, function of time in seconds -> (N, 2) world xy).
    pieces: list[tuple[float, float, Motion]] = []
    runs_truth: list[dict[str, Any]] = []
    tau = 0.6
    end_s = 0.0
    for k, spec in enumerate(SPECS):
        ref, start_xy, (_, theta) = reference_of(k), run_placement(k)[0], run_placement(k)
        timeout = k == TIMEOUT_RUN
        path_s = TIMEOUT_PATH_S if timeout else PATH_S[spec]
        a0, ad = APPROACH
        add(tau + 0.05, Machine.BMBOX, BmBoxState.WAITING_MANUAL_OPERATION)
        add(
            tau + 0.06,
            Machine.REFBOX,
            RefBoxState.EXECUTING_MANUAL_OPERATION,
            f"Place the end effector at the reference position of run {k}",
        )
        ref_ns = add(tau + CMO_AT, Machine.BMBOX, BmBoxState.COMPLETED_MANUAL_OPERATION)
        add(tau + CMO_AT + 0.01, Machine.REFBOX, RefBoxState.READY)
        add(tau + TG_AT, Machine.BMBOX, BmBoxState.TRANSMITTING_GOAL, spec)
        add(tau + TG_AT + 0.01, Machine.REFBOX, RefBoxState.EXECUTING_GOAL)
        add(tau + TG_AT + 0.05, Machine.CLIENT, ClientState.EXECUTING_GOAL)
        eg_ns = add(tau + EG_AT, Machine.BMBOX, BmBoxState.EXECUTING_GOAL)
        add(tau + EG_AT + 0.01, Machine.BMBOX, BmBoxState.WAITING_RESULT)
        p0 = tau + PATH_AT

        def still(p: F64) -> Motion:
            return lambda t: np.tile(p, (len(t), 1))

        def move(a: F64, b: F64, t_a: float, dur: float) -> Motion:
            return lambda t: a + np.outer(min_jerk((t - t_a) / dur), b - a)

        def path(k: int = k, spec: str = spec, t_a: float = p0, dur: float = path_s) -> Motion:
            def f(t: F64) -> F64:
                u = min_jerk((t - t_a) / dur)
                return to_world(k, target(spec, u) + deviation(k, u, amplitude))

            return f

        pieces.append((0.0 if k == 0 else tau, tau + a0, still(ref)))
        pieces.append((tau + a0, tau + a0 + ad, move(ref, start_xy, tau + a0, ad)))
        pieces.append((tau + a0 + ad, p0, still(start_xy)))
        if timeout:
            t_out = p0 + TIMEOUT_AFTER_S
            pieces.append((p0, t_out + 2.0, path()))
            add(t_out, Machine.REFBOX, RefBoxState.END, "timeout")
            add(t_out + 0.02, Machine.CLIENT, ClientState.END)
            done_ns = add(t_out + 0.05, Machine.BMBOX, BmBoxState.READY)
            end_s = t_out + 1.5
            status = "timeout"
        else:
            stop = p0 + path_s
            end_xy = to_world(k, target(spec, np.ones(1)) + deviation(k, np.ones(1), amplitude))[0]
            add(stop + 0.4, Machine.CLIENT, ClientState.COMPLETED_GOAL, "path following completed")
            add(stop + 0.45, Machine.REFBOX, RefBoxState.READY)
            done_ns = add(stop + DONE_AFTER, Machine.BMBOX, BmBoxState.READY)
            add(stop + DONE_AFTER + 0.05, Machine.CLIENT, ClientState.WAITING_GOAL)
            nxt = reference_of(k + 1) if k + 1 < len(SPECS) else end_xy
            back = stop + RETURN_AFTER
            pieces.append((p0, stop, path()))
            pieces.append((stop, back, still(end_xy)))
            pieces.append((back, back + RETURN_S, move(end_xy, nxt, back, RETURN_S)))
            status = "completed"
        runs_truth.append(
            {
                "spec": spec,
                "status": status,
                "reference_ns": ref_ns,
                "start_ns": eg_ns,
                "end_ns": done_ns,
                "path_motion": window(t0 + round(p0 * S), t0 + round((p0 + path_s) * S)),
                "reference_xy": ref,
                "start_xy": start_xy,
                "theta": theta,
                "amplitude": amplitude[k],
            }
        )
        tau = tau + PATH_AT + path_s + RETURN_AFTER + RETURN_S

    t_end_run = runs_truth[-1]["end_ns"]
    add((t_end_run - t0) / S + 0.25, Machine.BMBOX, BmBoxState.TRANSMITTING_SCORE, "")
    add((t_end_run - t0) / S + 0.55, Machine.BMBOX, BmBoxState.END)

    # Truth at 120 Hz and what the mocap node published.
    t = frame_times(t0, end_s)
    ts = (t - t0) / S
    xy = np.full((len(t), 2), np.nan)
    for lo, hi, f in pieces:
        m = (ts >= lo) & (ts < hi)
        if m.any():
            xy[m] = f(ts[m])
    assert not np.isnan(xy).any(), "motion pieces must cover the whole recording"
    xyz = np.column_stack([xy, np.full(len(t), Z_M)])
    quat = quat_from_yaw(np.full(len(t), 0.3))
    loss_run, loss_at, reps, gaps = LOSS
    loss_t = runs_truth[loss_run]["path_motion"]["start_ns"] + round(loss_at * S)
    pub = simulate_mocap(
        t,
        xyz,
        quat,
        rng=rng,
        noise=MocapNoise(sigma_m=SIGMA_M),
        losses=[TrackingLoss(loss_t, reps, gaps)],
    )

    # Answers from the noiseless truth frames (the 2015 node's formula, see eq1).
    expected_runs: dict[int, dict[str, Any]] = {}
    for k, run in enumerate(runs_truth):
        item: dict[str, Any] = {"spec": run["spec"], "status": run["status"]}
        item["execution_time"] = (run["end_ns"] - run["start_ns"]) / S
        if run["status"] == "completed":
            m = (t >= run["start_ns"]) & (t <= run["end_ns"])
            err, kept, length = eq1(np.asarray(run["reference_xy"]), xy[m], run["spec"], D_MIN)
            item |= {"distance_error": err, "kept_samples": kept, "path_length": length}
        else:
            item["distance_error"] = None
        expected_runs[k] = item
    scored = {
        k: float(v["distance_error"])
        for k, v in expected_runs.items()
        if v["distance_error"] is not None
    }
    best = min(scored, key=lambda k: scored[k])

    # What the live 2015 node computed: the same formula on the *published* Pose2D messages
    # it received between the transitions (record times; pose2d is recorded 20 us after the
    # pose), the reference being the last one before COMPLETED_MANUAL_OPERATION. A scorer
    # reading the bag in `states` mode must find these numbers up to float rounding.
    t_pose2d = pub.t_record_ns + 20_000
    xy_pub = pub.xyz[:, :2]
    published: dict[int, dict[str, Any]] = {}
    for k, run in enumerate(runs_truth):
        entry: dict[str, Any] = {"spec": run["spec"]}
        if run["status"] == "completed":
            m = (t_pose2d >= run["start_ns"]) & (t_pose2d <= run["end_ns"])
            ref_i = int(np.searchsorted(t_pose2d, run["reference_ns"], side="right")) - 1
            err, kept, length = eq1(xy_pub[ref_i], xy_pub[m], run["spec"], D_MIN)
            entry |= {"distance_error": err, "execution_time": expected_runs[k]["execution_time"]}
            entry |= {"kept_samples": kept, "path_length": length}
        published[k] = entry
    live = {k: v["distance_error"] for k, v in published.items() if "distance_error" in v}
    live_best = min(live, key=lambda k: live[k])
    total_time = sum(v["execution_time"] for v in expected_runs.values())
    # The score payload as the 2015 node dumped it (yaml.dump sorts keys; a timed-out run
    # keeps only its spec).
    score_yaml = yaml.safe_dump(
        {
            "best_distance_error": live[live_best],
            "best_run": live_best,
            "execution_time": total_time,
            "runs_details": {
                k: {
                    kk: vv
                    for kk, vv in v.items()
                    if kk in ("spec", "distance_error", "execution_time")
                }
                for k, v in published.items()
            },
        },
        default_flow_style=False,
    )
    last_rec = int(pub.t_record_ns[-1]) + 50_000_000
    tr = [
        x
        if x.state != BmBoxState.TRANSMITTING_SCORE or x.machine is not Machine.BMBOX
        else Transition(x.t_ns, x.machine, x.state, score_yaml)
        for x in tr
    ]

    config_text = (
        "# FBM3@Work config of this simulated benchmark (seed Listing 14, 2015 D_MIN)\n"
        + yaml.safe_dump({"runs_specifications": list(SPECS), "d_min": D_MIN}, sort_keys=False)
    )
    phases = _still_phases(t, xy)
    eps_formula = SIGMA_M * math.sqrt(math.pi)
    for run in runs_truth:
        for key in ("reference", "start", "end"):
            ns = run[f"{key}_ns"]
            run[f"{key}_s"] = (ns - start) / S  # seconds from the bag's first message
    return SimulatedRun(
        benchmark=NAMESPACE,
        namespace=NAMESPACE,
        start_ns=start,
        end_ns=last_rec,
        transitions=tuple(tr),
        state_end_ns=last_rec,
        bodies={BODY: pub},
        configs={CONFIG_FILE: config_text},
        parameters={
            "namespace": NAMESPACE,
            "body": BODY,
            "topic": f"/{NAMESPACE}/{BODY}/pose2d",
            "rate_hz": 120.0,
            "sigma_m": SIGMA_M,
            "d_min": D_MIN,
            "runs_specifications": list(SPECS),
            "tracking_loss": {
                "run": loss_run,
                "at_s": loss_at,
                "repeat_frames": reps,
                "gap_frames": gaps,
            },
        },
        truth={
            "bag_start_ns": start,
            "runs": runs_truth,
            "phases": [window(a, b) for a, b in phases],
        },
        expected={
            "best_distance_error": scored[best],
            "best_run": best,
            "execution_time": sum(v["execution_time"] for v in expected_runs.values()),
            "runs_details": expected_runs,
            "tracking_losses": {loss_run: reps},
            "published": {
                "best_distance_error": live[live_best],
                "best_run": live_best,
                "runs_details": published,
            },
            "noise": {"epsilon": eps_formula, "suggested_d_min": 3 * eps_formula},
        },
        tolerance={
            "distance_error": tol(
                4.0e-4,
                "the run frame comes from single noisy reference and start samples: origin off "
                "by ~sigma*sqrt(2) = 0.07 mm, x axis by sqrt(2)*sigma/baseline = 0.9 mrad, i.e. "
                "~0.07 mm at the path's mean lever arm; 4 sigma of the sum; measured max 0.29 mm "
                "over seeds 0-19 in all three run-finding modes",
            ),
            "distance_error_noiseless": tol(
                5.0e-5,
                "with sigma = 0 only the tracking loss of run 1 differs from the truth (a "
                "straight segment over 9 frames): 0.03 mm; other runs agree to 1e-12",
            ),
            "execution_time": tol(1e-6, "state transitions are recorded at their exact times"),
            "published": tol(
                1e-12,
                "the same Pose2D messages and windows as a states-mode scorer reads from the "
                "bag; only float summation order differs",
            ),
            "noise.epsilon": tol(
                2.5e-5, "sampling error of the mean over ~2000 stationary pairs (6 std errors)"
            ),
        },
    )


def generate(outdir: Path, *, seed: int) -> list[Path]:
    """Write the FBM3@Work logs (ROS1 and rosbag2-MCAP) and their answers into ``outdir``."""
    sim = simulate(seed)
    stem = log_name(f"{NAMESPACE}_mocap", sim.start_ns, suffix="")
    paths = [outdir / f"{stem}.bag", outdir / f"{stem}_mcap"]
    for path_out, fmt in zip(paths, ("ros1", "rosbag2-mcap"), strict=True):
        with BagWriter(path_out, fmt) as bag:  # type: ignore[arg-type]
            publish_mocap(bag, NAMESPACE, BODY, sim.bodies[BODY])
            publish_states(bag, NAMESPACE, sim.transitions, end_ns=sim.state_end_ns)
            publish_environment(
                bag, NAMESPACE, sim.start_ns, sim.end_ns, bag_name=path_out.name, bodies=[BODY]
            )
    # The config the benchmark ran with (seed Listing 14 and the 2015 D_MIN).
    config = outdir / CONFIG_FILE
    config.write_text(sim.configs[CONFIG_FILE], encoding="utf-8")
    answers = write_answers(
        paths,
        benchmark="fbm3w",
        scenario="fbm3w",
        seed=seed,
        parameters=sim.parameters,
        truth=sim.truth,
        expected=sim.expected,
        tolerance=sim.tolerance,
    )
    return [*paths, config, answers]


def _still_phases(t: npt.NDArray[np.int64], xy: F64) -> list[tuple[int, int]]:
    """Stretches where the noiseless truth does not move (for ``--runs auto`` checks)."""
    moving = np.concatenate([[False], np.any(np.diff(xy, axis=0) != 0.0, axis=1)])
    out = []
    edges = np.diff(np.concatenate([[1], moving.astype(np.int8), [1]]))
    for a, b in zip(np.flatnonzero(edges == -1), np.flatnonzero(edges == 1) - 1, strict=True):
        if b > a:
            out.append((int(t[a]), int(t[b])))
    return out


# The sample competition's part (ertools.samples.competition_schedule): per team, the scale
# of its path deviation amplitude, per attempt.
COMPETITION_TEAMS: dict[str, tuple[float, float]] = {
    "b-it-bots": (1.1, 1.3),
    "robotto": (1.7, 2.2),
}


def competition_run(
    team: str, attempt: int, seed: int, start_ns: int, items: list[dict[str, Any]]
) -> SimulatedRun:
    """``team``'s ``attempt``-th execution in the sample competition (its knobs above)."""
    scale = COMPETITION_TEAMS[team][attempt - 1]
    return simulate(seed, start_ns=start_ns, amplitude=tuple(a * scale for a in AMPLITUDE))


def competition_score(
    exp: Mapping[str, Any], tolerance: Mapping[str, Any]
) -> tuple[dict[str, Any], dict[str, Any]]:
    """The fields of ``ertools score ... --format json`` a competition execution must show
    (from its ``expected``) and their tolerances (its ``tolerance``'s), by dotted path."""
    dist = given_tol(tolerance, "distance_error")
    timing = given_tol(tolerance, "execution_time")
    errors = sorted(
        float(r["distance_error"])
        for r in exp["runs_details"].values()
        if r["distance_error"] is not None
    )
    if len(errors) > 1 and errors[1] - errors[0] <= 2 * dist["abs"]:
        raise ValueError(f"best run ambiguous within the tolerance: {errors[:2]}")
    score: dict[str, Any] = {
        "best_run": exp["best_run"],
        "best_distance_error": exp["best_distance_error"],
        "execution_time": exp["execution_time"],
    }
    tols: dict[str, Any] = {
        "best_run": tol(0, "the best run's margin over the next exceeds twice the tolerance"),
        "best_distance_error": dist,
        "execution_time": timing,
    }
    for k, run in exp["runs_details"].items():
        path = f"runs_details.{k}"
        score[f"{path}.distance_error"] = run["distance_error"]
        tols[f"{path}.distance_error"] = (
            dist if run["distance_error"] is not None else tol(0, "a timed-out run has none")
        )
        score[f"{path}.execution_time"], tols[f"{path}.execution_time"] = (
            run["execution_time"],
            timing,
        )
    return score, tols
