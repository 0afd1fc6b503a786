"""Scenario ``fbm1h``: an FBM1@Home benchmark of 10 items on a rotated, translated table.

The FBM1 table (marker set ``origin``) stands at a known place in the mocap world, turned
0.6 rad and tilted slightly; the reference board (``ref_board``) carries one item per run.
Per run the BmBox asks for the item (``WAITING_MANUAL_OPERATION``, payload ``Place item <id>
(<instance>) on the table``), the referee slides the board into a new place on the table
(board moving for ``MOVE_S``, then standing still), confirms (RefBox ``EXECUTING_GOAL``, BmBox
``COMPLETED_MANUAL_OPERATION``), the BmBox sends the goal, the robot answers after a while
(Client ``COMPLETED_GOAL`` with the YAML answer) and the BmBox returns to ``READY``. The last
run times out (RefBox ``END``, ``reason: timeout``) without answer. Then the BmBox sends the
score the 2015 node would have sent and ends.

To keep the bag small (<= ~2.5 MB) the two bodies are published at 120 Hz only around each
run (from the end of the board's approach to just after the result): the scorer needs the
stationary window before each goal and the board while the robot looks.

The robot answers (theta in degrees, as the 2015 robots did): runs 1-4 right with small pose
errors; run 5 right class, wrong instance; run 6 wrong class and instance; run 7 theta 190 deg
off (wrapped: -170); run 8 a translation error of 1.2 m (between 1 m and sqrt(2) m: the fixed
clip gives t = 1, the 2015 node left 1.2); run 9 theta answered 363 deg past the truth
(wrapped: 3 deg); run 10 no answer (timeout).

Written beside the bag: ``fbm1h.yaml`` (seed Listing 9, the 11 items with their transforms in
the board frame, as the 2015 list had) and the answers.

Answers (``expected``), computed here from the noiseless truth with 4x4 matrices (not with the
scorer): per run the item's ground-truth pose in the table frame (T_world_origin^-1 *
T_world_board * T_board_item, yaw in degrees), the answer, class/instance right, x/y/theta
errors, the translation and rotation terms, pose score, execution time (BmBox EXECUTING_GOAL to
the BmBox leaving WAITING_RESULT); totals with the fixed rules (``totals``) and with the 2015
rules (``totals_2015``: accuracies over 10, unclipped 1.2 m).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt
import yaml
from scipy.spatial.transform import Rotation

from ertools.arrays import F64
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
    frame_times,
    pose_topic,
    publish_environment,
    publish_mocap,
    simulate_mocap,
)
from ertools.simulator.simulated import SimulatedRun
from ertools.simulator.statemachine import Transition, publish_states
from ertools.simulator.writer import BagWriter
from ertools.states import BmBoxState, ClientState, Machine, RefBoxState

S = 1_000_000_000
MS = 1_000_000

NAMESPACE = "fbm1h"
ITEMS_FILE = "fbm1h.yaml"
NOON_NS = EPOCH_2015 + 2 * 3600 * S
SIGMA_M = 2.0e-4
SIGMA_RAD = 5.0e-4
RUNS = 10
# The table in the mocap world: position, yaw and a small tilt (roll, pitch), radians.
TABLE_XYZ = (1.5, -0.8, 0.72)
TABLE_RPY = (0.004, -0.006, 0.6)
# Items: (class, instance), ids 1..11 as the 2015 fbm1h.yaml.
ITEMS = (
    ("a", "a1"),
    ("a", "a2"),
    ("a", "a3"),
    ("a", "a4"),
    ("b", "b1"),
    ("b", "b2"),
    ("b", "b3"),
    ("c", "c1"),
    ("c", "c2"),
    ("d", "d1"),
    ("d", "d2"),
)
# Timeline of a run, seconds from its WAITING_MANUAL_OPERATION.
MOVE_START_S = 0.5  # the board starts sliding into place
MOVE_S = 0.5  # ... and stands still after this long
MOCAP_FROM_S = 0.75  # both bodies published from here (the board still moving)...
MOCAP_AFTER_S = 0.1  # ... to this long after the result
PLACED_S = 1.25  # referee confirms
GOAL_S = 1.75  # BmBox sends the goal
GAP_S = 0.3  # READY -> next WAITING_MANUAL_OPERATION
TIMEOUT_AFTER_S = 1.2  # the last run: RefBox timeout this long after the goal

# Per run: (class right, instance right, dx m, dy m, dtheta deg) added to the truth.
ANSWER_ERRORS: tuple[tuple[bool, bool, float, float, float], ...] = (
    (True, True, 0.012, -0.008, 2.5),
    (True, True, -0.004, 0.015, -4.0),
    (True, True, 0.020, 0.010, 1.0),
    (True, True, -0.030, -0.025, 8.0),
    (True, False, 0.010, 0.005, -3.0),
    (False, False, 0.050, -0.040, 12.0),
    (True, True, 0.008, 0.006, 190.0),
    (True, True, 1.2 * math.cos(0.7), 1.2 * math.sin(0.7), 5.0),
    (True, True, -0.006, 0.004, 363.0),
)


def _matrix(xyz: F64 | tuple[float, ...], rot: Rotation) -> F64:
    m = np.eye(4)
    m[:3, :3] = rot.as_matrix()
    m[:3, 3] = xyz
    return m


def _wrap_deg(a: float) -> float:
    return (a + 180.0) % 360.0 - 180.0


def item_list(rng: np.random.Generator) -> list[dict[str, Any]]:
    """Listing 9 items: transforms like the 2015 list (a few cm, rotated about z, tiny tilt)."""
    out = []
    for k, (cls, inst) in enumerate(ITEMS):
        trans = [float(v) for v in rng.uniform([0.0, 0.0, -0.002], [0.06, 0.06, 0.002])]
        yaw = float(rng.uniform(-1.2, 0.3))
        tilt = rng.normal(0.0, 0.004, size=2)
        rot = Rotation.from_euler("xyz", [tilt[0], tilt[1], yaw]).as_quat()
        item = {"class": cls, "id": k + 1, "instance": inst}
        item["rot"] = [float(v) for v in rot]
        item["trans"] = trans
        out.append(item)
    return out


def _board_poses(rng: np.random.Generator) -> list[tuple[F64, float]]:
    """Where the referee puts the board on the table each run: (x, y, z) and yaw."""
    out = []
    for _ in range(RUNS):
        xyz = np.array([rng.uniform(0.15, 0.55), rng.uniform(0.1, 0.45), 0.015])
        out.append((xyz, float(rng.uniform(-1.0, 1.0))))
    return out


def simulate(
    seed: int,
    *,
    start_ns: int = NOON_NS,
    answer_errors: tuple[tuple[bool, bool, float, float, float], ...] = ANSWER_ERRORS,
    items: list[dict[str, Any]] | None = None,
) -> SimulatedRun:
    """One FBM1@Home execution whose recorder starts at ``start_ns`` (module docstring);
    ``answer_errors`` (one per run but the last) are the robot's mistakes; ``items`` the
    item list of a whole competition (default: drawn from ``seed``)."""
    rng = np.random.default_rng(seed)
    items = item_list(rng) if items is None else items
    order = [int(i) + 1 for i in rng.permutation(len(ITEMS))[:RUNS]]
    boards = _board_poses(rng)
    answer_ms = rng.integers(400, 800, size=RUNS)  # the robot's thinking time, ms

    start = start_ns
    t0 = start + 500 * MS
    table_rot = Rotation.from_euler("xyz", TABLE_RPY)
    T_wt = _matrix(TABLE_XYZ, table_rot)

    tr: list[Transition] = [
        Transition(t0, Machine.BMBOX, BmBoxState.START),
        Transition(t0 + 20 * MS, Machine.REFBOX, RefBoxState.START),
        Transition(t0 + 40 * MS, Machine.CLIENT, ClientState.START),
        Transition(t0 + 100 * MS, Machine.BMBOX, BmBoxState.WAITING_CLIENT),
        Transition(t0 + 150 * MS, Machine.REFBOX, RefBoxState.WAITING_CLIENT),
        Transition(t0 + 160 * MS, Machine.CLIENT, ClientState.CONNECTING),
        Transition(t0 + 300 * MS, Machine.CLIENT, ClientState.READY),
        Transition(t0 + 350 * MS, Machine.REFBOX, RefBoxState.READY),
        Transition(t0 + 400 * MS, Machine.BMBOX, BmBoxState.READY),
        Transition(t0 + 450 * MS, Machine.CLIENT, ClientState.WAITING_GOAL),
    ]
    # Truth of both bodies, only inside each run's mocap window.
    t_parts: list[npt.NDArray[np.int64]] = []
    board_xyz: list[F64] = []
    board_quat: list[F64] = []
    runs_truth: list[dict[str, Any]] = []
    runs_expected: list[dict[str, Any]] = []
    t = t0 + 700 * MS
    prev_board = (np.array([-0.4, 0.3, 0.015]), 0.0)  # the board waits beside the table
    for k in range(RUNS):
        item = items[order[k] - 1]
        wmo = t
        payload = f"Place item {item['id']} ({item['instance']}) on the table"
        placed = wmo + round(PLACED_S * S)
        goal = wmo + round(GOAL_S * S)
        executing = goal + 100 * MS
        waiting = goal + 150 * MS
        last = k == RUNS - 1
        answered_at = waiting + int(answer_ms[k]) * MS
        result = goal + round(TIMEOUT_AFTER_S * S) if last else answered_at + 50 * MS
        tr += [
            Transition(wmo, Machine.BMBOX, BmBoxState.WAITING_MANUAL_OPERATION, payload),
            Transition(
                wmo + 30 * MS, Machine.REFBOX, RefBoxState.EXECUTING_MANUAL_OPERATION, payload
            ),
            Transition(placed, Machine.REFBOX, RefBoxState.EXECUTING_GOAL),
            Transition(placed + 20 * MS, Machine.BMBOX, BmBoxState.COMPLETED_MANUAL_OPERATION),
            Transition(goal, Machine.BMBOX, BmBoxState.TRANSMITTING_GOAL),
            Transition(goal + 50 * MS, Machine.CLIENT, ClientState.EXECUTING_GOAL),
            Transition(executing, Machine.BMBOX, BmBoxState.EXECUTING_GOAL),
            Transition(waiting, Machine.BMBOX, BmBoxState.WAITING_RESULT),
        ]

        # Board truth: slides from the previous place to this run's place, then still.
        move0 = wmo + round(MOVE_START_S * S)
        mocap_from = wmo + round(MOCAP_FROM_S * S)
        mocap_end = result + round(MOCAP_AFTER_S * S)
        tt = frame_times(mocap_from, (mocap_end - mocap_from) / S)
        s = np.clip((tt - move0) / (MOVE_S * S), 0.0, 1.0)
        s = s * s * (3.0 - 2.0 * s)  # smooth start and stop
        (p0, y0), (p1, y1) = prev_board, boards[k]
        p_tb = p0[None, :] + s[:, None] * (p1 - p0)[None, :]
        yaw_tb = y0 + s * (y1 - y0)
        # World pose of the board: T_wt * T_tb (the board lies flat on the tilted table).
        p_w = p_tb @ table_rot.as_matrix().T + np.asarray(TABLE_XYZ)
        r_w = table_rot * Rotation.from_euler("z", yaw_tb[:, None])
        t_parts.append(tt)
        board_xyz.append(p_w)
        board_quat.append(r_w.as_quat())
        prev_board = boards[k]

        # Ground truth of the item in the table frame, from the noiseless still pose.
        T_tb = _matrix(boards[k][0], Rotation.from_euler("z", boards[k][1]))
        T_wb = T_wt @ T_tb
        T_bi = _matrix(item["trans"], Rotation.from_quat(item["rot"]))
        T_ti = np.linalg.inv(T_wt) @ T_wb @ T_bi
        gt_x, gt_y = float(T_ti[0, 3]), float(T_ti[1, 3])
        gt_yaw = math.degrees(math.atan2(T_ti[1, 0], T_ti[0, 0]))
        run_truth: dict[str, Any] = {
            "run": k + 1,
            "item": item["id"],
            "board_in_table": {"xyz": boards[k][0], "yaw": boards[k][1]},
            "still": window(move0 + round(MOVE_S * S), int(tt[-1])),
            "goal": window(goal, goal),
        }
        exp: dict[str, Any] = {
            "run": k + 1,
            "status": "no_answer" if last else "scored",
            "item_id": item["id"],
            "item_class": item["class"],
            "item_instance": item["instance"],
            "gt_x": gt_x,
            "gt_y": gt_y,
            "gt_theta_deg": gt_yaw,
            "execution_time": (result - executing) / S,
        }
        if last:
            tr += [
                Transition(result - 10 * MS, Machine.REFBOX, RefBoxState.END, "reason: timeout"),
                Transition(result, Machine.BMBOX, BmBoxState.READY),
            ]
            exp.update(class_correct=False, instance_correct=False, pose_score=0.0)
        else:
            cls_ok, inst_ok, dx, dy, dth = answer_errors[k]
            other = items[order[(k + 1) % RUNS] - 1]
            a_cls = (
                item["class"]
                if cls_ok
                else ("z" if other["class"] == item["class"] else other["class"])
            )
            same_class = [i for i in items if i["class"] == item["class"] and i["id"] != item["id"]]
            a_inst = (
                item["instance"]
                if inst_ok
                else (same_class[0]["instance"] if cls_ok and same_class else "zz9")
            )
            # The robot's numbers, rounded as a robot printing mm and 0.01 deg would.
            ax = round(gt_x + dx, 4)
            ay = round(gt_y + dy, 4)
            ath = round(gt_yaw + dth, 2)
            answer = {"item_class": a_cls, "item_instance": a_inst, "theta": ath, "x": ax, "y": ay}
            text = yaml.safe_dump(answer, default_flow_style=True).strip()
            tr += [
                Transition(answered_at, Machine.CLIENT, ClientState.COMPLETED_GOAL, text),
                Transition(result, Machine.BMBOX, BmBoxState.READY),
                Transition(result + 30 * MS, Machine.CLIENT, ClientState.WAITING_GOAL),
            ]
            ex, ey = ax - gt_x, ay - gt_y
            dist = math.hypot(ex, ey)
            eth = _wrap_deg(ath - gt_yaw)
            t_term = min(dist, 1.0)
            t_2015 = 1.0 if dist > math.sqrt(2.0) else dist
            r_term = min(abs(eth) / 180.0, 1.0)
            raw = ath - gt_yaw
            raw = raw - 360.0 if raw > 180.0 else raw
            raw = raw + 360.0 if raw < -180.0 else raw
            r_2015 = min(abs(raw) / 180.0, 1.0)
            exp.update(
                answer=answer,
                class_correct=a_cls == item["class"],
                instance_correct=a_inst == item["instance"],
                error_x=ex,
                error_y=ey,
                error_translation=dist,
                error_theta_deg=eth,
                trans_term=t_term,
                rot_term=r_term,
                pose_score=1.0 - t_term / 2.0 - r_term / 2.0,
                pose_score_2015=1.0 - t_2015 / 2.0 - r_2015 / 2.0,
            )
        runs_truth.append(run_truth)
        runs_expected.append(exp)
        t = result + round(GAP_S * S)

    n_cls = sum(bool(e["class_correct"]) for e in runs_expected)
    n_inst = sum(bool(e["instance_correct"]) for e in runs_expected)
    exec_time = math.fsum(e["execution_time"] for e in runs_expected)
    totals = {
        "class_accuracy": n_cls / RUNS,
        "execution_time": exec_time,
        "instance_accuracy": n_inst / RUNS,
        "pose_score": math.fsum(e["pose_score"] for e in runs_expected) / RUNS,
    }
    totals_2015 = {
        "class_accuracy": n_cls / 10,
        "execution_time": exec_time,
        "instance_accuracy": n_inst / 10,
        "pose_score": math.fsum(e.get("pose_score_2015", 0.0) for e in runs_expected) / RUNS,
    }
    score_text = yaml.safe_dump(totals_2015, default_flow_style=True).strip()
    t_score = t + 100 * MS
    tr += [
        Transition(t_score, Machine.BMBOX, BmBoxState.TRANSMITTING_SCORE, score_text),
        Transition(t_score + 300 * MS, Machine.BMBOX, BmBoxState.END),
    ]

    # Mocap: the table is still (noise only); both bodies share the frame times.
    tt_all = np.concatenate(t_parts)
    n = tt_all.size
    noise = MocapNoise(sigma_m=SIGMA_M, sigma_rad=SIGMA_RAD)
    table_pub = simulate_mocap(
        tt_all,
        np.tile(np.asarray(TABLE_XYZ), (n, 1)),
        np.tile(table_rot.as_quat(), (n, 1)),
        rng=rng,
        noise=noise,
    )
    board_pub = simulate_mocap(
        tt_all, np.concatenate(board_xyz), np.concatenate(board_quat), rng=rng, noise=noise
    )

    end = t_score + 500 * MS
    items_text = yaml.safe_dump(
        {"items": items}, sort_keys=False, default_flow_style=None, width=100
    )
    return SimulatedRun(
        benchmark=NAMESPACE,
        namespace=NAMESPACE,
        start_ns=start,
        end_ns=end,
        transitions=tuple(tr),
        state_end_ns=end,
        bodies={"origin": table_pub, "ref_board": board_pub},
        configs={ITEMS_FILE: items_text},
        parameters={
            "namespace": NAMESPACE,
            "origin_topic": pose_topic(NAMESPACE, "origin"),
            "ref_board_topic": pose_topic(NAMESPACE, "ref_board"),
            "items": ITEMS_FILE,
            "sigma_m": SIGMA_M,
            "sigma_rad": SIGMA_RAD,
            "runs": RUNS,
            "theta_unit": "deg",
        },
        truth={
            "table": {"xyz": list(TABLE_XYZ), "rpy": list(TABLE_RPY)},
            "order": order,
            "runs": runs_truth,
        },
        expected={"runs": runs_expected, "totals": totals, "totals_2015": totals_2015},
        tolerance={
            "gt_xy": tol(
                3e-4,
                "mean of ~80 noisy samples (0.2 mm, 0.5 mrad per body at ~0.5 m lever): "
                "~0.03 mm standard error; 10 standard errors",
            ),
            "gt_theta_deg": tol(0.05, "0.7 mrad per sample, ~80 samples: ~0.005 deg; 10x"),
            "pose_score": tol(5e-4, "follows from gt_xy/2 + gt_theta_deg/180/2"),
            "execution_time": tol(1e-6, "transition times are exact in the state topics"),
            "accuracy": tol(0, "counts are exact"),
        },
    )


def generate(outdir: Path, *, seed: int) -> list[Path]:
    """Write the FBM1@Home log, its item list and its answers into ``outdir``."""
    sim = simulate(seed)
    bag_path = outdir / log_name(NAMESPACE, sim.start_ns)
    with BagWriter(bag_path, "ros1") as bag:
        for body, pub in sim.bodies.items():
            publish_mocap(bag, NAMESPACE, body, pub)
        publish_states(bag, NAMESPACE, sim.transitions, end_ns=sim.state_end_ns)
        publish_environment(
            bag,
            NAMESPACE,
            sim.start_ns,
            sim.end_ns,
            bag_name=bag_path.name,
            bodies=list(sim.bodies),
        )
    items_path = outdir / ITEMS_FILE
    items_path.write_text(sim.configs[ITEMS_FILE], encoding="utf-8")
    answers = write_answers(
        bag_path,
        benchmark=NAMESPACE,
        scenario="fbm1h",
        seed=seed,
        parameters=sim.parameters,
        truth=sim.truth,
        expected=sim.expected,
        tolerance=sim.tolerance,
    )
    return [bag_path, items_path, answers]


# The sample competition's part (ertools.samples.competition_schedule): per team, the scale of
# the pose errors of runs 1-6 and the runs (1-based) answered with a wrong class.
COMPETITION_TEAMS: dict[str, tuple[float, tuple[int, ...]]] = {
    "homer": (1.0, ()),
    "socrob": (1.8, (2, 3)),
    "skuba": (0.5, (1,)),
}


def answer_errors(
    scale: float, wrong: tuple[int, ...]
) -> tuple[tuple[bool, bool, float, float, float], ...]:
    """The default answers with runs 1-6's pose errors scaled and some classes wrong (runs 7-9
    keep their seam and clip cases)."""
    out = []
    for k, (cls, inst, dx, dy, dth) in enumerate(ANSWER_ERRORS):
        if k < 6:
            dx, dy, dth = dx * scale, dy * scale, dth * scale
        if k + 1 in wrong:
            cls = inst = False
        out.append((cls, inst, dx, dy, dth))
    return tuple(out)


def competition_run(
    team: str, attempt: int, seed: int, start_ns: int, items: list[dict[str, Any]]
) -> SimulatedRun:
    """``team``'s execution in the sample competition (its knobs above; the day's items)."""
    scale, wrong = COMPETITION_TEAMS[team]
    return simulate(seed, start_ns=start_ns, answer_errors=answer_errors(scale, wrong), items=items)


def competition_score(
    exp: Mapping[str, Any], tolerance: Mapping[str, Any]
) -> tuple[dict[str, Any], dict[str, Any]]:
    """The fields of ``ertools score ... --format json`` a competition execution must show
    (from its ``expected``) and their tolerances (its ``tolerance``'s), by dotted path."""
    score: dict[str, Any] = {}
    tols: dict[str, Any] = {}
    exact = tol(0, "counts are exact")
    pose = given_tol(tolerance, "pose_score")
    timing = given_tol(tolerance, "execution_time")
    totals = exp["totals"]
    for key, t in (
        ("class_accuracy", exact),
        ("instance_accuracy", exact),
        ("pose_score", pose),
        ("execution_time", timing),
    ):
        score[key], tols[key] = totals[key], t
    for run in exp["runs"]:
        k = f"runs.{run['run']}"
        score[f"{k}.status"], tols[f"{k}.status"] = run["status"], exact
        for key in ("class_correct", "instance_correct"):
            score[f"{k}.{key}"], tols[f"{k}.{key}"] = bool(run[key]), exact
        score[f"{k}.pose_score"], tols[f"{k}.pose_score"] = run["pose_score"], pose
        score[f"{k}.execution_time"], tols[f"{k}.execution_time"] = run["execution_time"], timing
    return score, tols
