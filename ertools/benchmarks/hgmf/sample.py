"""Scenario ``hgmf``: HGMF runs (ERL @Home 2019 FBM6, grasping and manipulation) in the RSBB's
layout, with known answers.

A plan (:class:`RunPlan`) says, per goal, which object the referee places where, its target,
where the robot puts it (lifting it 10 cm on the way, or pushing it without lifting) or that
the goal times out, and whether the object's tracking is lost around the lookup after the goal:
for more than the helper's 3 attempts of 1 s (the script finds no position and runs the goal
again) or for 0.3 s (tf interpolates across; ertools' default refuses it, ``hgmf.gt-gaps``).
:func:`build` turns it into an :class:`~ertools.simulator.rsbb_scenario.RsbbScenario`: the
manual operations and goals timed, the object's and the table's motion (the table turned
0.4 rad, its top 0.75 m up), the script's ``/object`` broadcasts at its successful lookups,
and its saves. The saves hold the 2019 script's score computed here as it did (the object
looked up at each broadcast's stamp in the published ``/tf``: linear position, slerp), not by
ertools' scorer.

``generate`` writes one run of four objects (sample_bags/hgmf/): goal_0 grasped and placed
3 cm from its target; goal_1 timed out (pushed, never lifted); goal_2 placed, its final lookup
lost for 3.5 s (restarted), then placed 5 cm off with 0.3 s of tracking lost around the
lookup; the referee stops the run while the fourth object is being placed. Answers
(``expected``; in ``<folder>.answers.yaml`` beside the layout folder, not in it), from the
noiseless truth: per goal the segment time, outcome, grasp and distance; the 2019 totals (Avg
over 3 completed goals, 3 grasps counted) and ertools' (the one measured goal).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import yaml
from scipy.spatial.transform import Rotation, Slerp

from ertools.atomic import write_text
from ertools.benchmarks.hgmf.config import SCRIPT_FRAMES
from ertools.frozen_dataclass import frozen_dataclass
from ertools.simulator.answers import RunAnswers, tol, window, write_layout_answers
from ertools.simulator.mocap import MocapNoise, TrackingLoss, frame_times, simulate_mocap
from ertools.simulator.rsbb import write_rsbb_run
from ertools.simulator.rsbb_scenario import (
    Body,
    Broadcast,
    Goal,
    ManualOperation,
    RsbbScenario,
    Save,
)

S = 1_000_000_000
MS = 1_000_000
CODE = "HGMF"
#: Its name in benchmarks_description.yaml (the season sample writes one).
DESCRIPTION_NAME = "Functionality Benchmark 6: Grasping and Manipulation Functionality"
TEAM = "simbot"
# Friday 12 April 2019, 10:00:00 UTC: a day of the ERL Consumer 2019 season.
T0 = 1_555_063_200 * S
OBJECTS = (
    {"id": 1, "description": "mug"},
    {"id": 2, "description": "box"},
    {"id": 3, "description": "can"},
    {"id": 4, "description": "ball"},
)
TABLE_SIZE = {"x": 1.0, "y": 1.5}
GOAL_TIMEOUT_S = 8.0
TABLE_XYZ = (1.2, -0.4, 0.75)
TABLE_YAW = 0.4
LIFT_M = 0.10
NOISE = MocapNoise(sigma_m=2e-4, sigma_rad=2e-4)
FRAME = SCRIPT_FRAMES[0]


@frozen_dataclass
class GoalPlan:
    """One goal: the object (id) placed at ``start`` (table frame), its ``target``; the robot
    puts it at ``final`` (None: the goal times out, the object pushed by ``push``); ``lift``:
    raised 10 cm on the way; ``lost_s``: tracking lost around the lookup after the goal."""

    object_id: int
    start: tuple[float, float]
    target: tuple[float, float]
    final: tuple[float, float] | None
    lift: bool = True
    push: tuple[float, float] = (0.02, 0.0)
    lost_s: float = 0.0
    then_lost_s: float = 0.0  # the restarted goal's own loss around its final lookup
    table_lost_s: float = 0.0  # the table untracked from 0.5 s into the goal (an arm over it)
    # the restarted goal's new target (the script draws one) and where the robot puts it
    then_target: tuple[float, float] | None = None
    then_final: tuple[float, float] | None = None


@frozen_dataclass
class RunPlan:
    """A run: its team and number, its goals in order, and the object the referee was placing
    when he stopped the run (None: the script ends it)."""

    team: str
    run: int
    t0_ns: int
    goals: tuple[GoalPlan, ...]
    stop_object: int | None = None
    objects: tuple[dict[str, Any], ...] = OBJECTS
    seed: int = 0


@dataclass
class _Keys:
    """The object's keyframes in the table's frame (time ns, x, y, z)."""

    rows: list[tuple[int, float, float, float]] = field(default_factory=list)

    def at(self, t: int, xy: tuple[float, float], z: float = 0.0) -> None:
        self.rows.append((t, xy[0], xy[1], z))


def _table_pose() -> tuple[np.ndarray, Rotation]:
    return np.asarray(TABLE_XYZ), Rotation.from_euler("z", TABLE_YAW)


def _world(xyz_table: np.ndarray) -> np.ndarray:
    p, r = _table_pose()
    return np.asarray(p + r.apply(xyz_table))


def _interp(
    t: np.ndarray, t_pub: np.ndarray, xyz: np.ndarray, quat: np.ndarray
) -> tuple[np.ndarray, Rotation]:
    """Published samples interpolated at ``t`` as tf does (linear position, slerp)."""
    k = np.clip(np.searchsorted(t_pub, t, side="right"), 1, len(t_pub) - 1)
    w = (t - t_pub[k - 1]) / (t_pub[k] - t_pub[k - 1])
    pos = (1 - w)[:, None] * xyz[k - 1] + w[:, None] * xyz[k]
    rots = [
        Slerp([0.0, 1.0], Rotation.from_quat(quat[[i - 1, i]]))([wi])[0]
        for i, wi in zip(k.tolist(), w.tolist(), strict=True)
    ]
    return pos, Rotation.concatenate(rots) if rots else Rotation.identity(0)


def _to_sec(ns: int) -> float:
    secs, nsecs = divmod(ns, S)
    return float(secs) + float(nsecs) / 1e9


def build(plan: RunPlan) -> tuple[RsbbScenario, dict[str, Any]]:
    """The run's scenario and its truth (per goal: times, outcome, lift, final position)."""
    descriptions = {int(o["id"]): str(o["description"]) for o in plan.objects}
    t = plan.t0_ns + 2 * S  # the referee's start
    keys = _Keys()
    keys.at(plan.t0_ns, (0.5, 0.2))
    manual: list[ManualOperation] = []
    goals: list[Goal] = []
    lookups: list[int] = []
    losses: list[tuple[int, float]] = []
    table_losses: list[tuple[int, float]] = []
    truth: list[dict[str, Any]] = []
    position = (0.5, 0.2)
    pending = list(plan.goals)
    while pending:
        g = pending.pop(0)
        name = descriptions[g.object_id]
        mo_req, mo_done = t + S // 2, t + 3 * S // 2
        keys.at(mo_req, position)
        keys.at(mo_done - S // 5, g.start)
        position = g.start
        manual.append(
            ManualOperation(
                mo_req, mo_done, f"Place the {name} on the table, with MoCap markers attached."
            )
        )
        lookups.append(mo_done + 10 * MS)
        request, start = mo_done + S // 2, mo_done + S
        payload = yaml.dump([g.target[0], g.target[1], g.object_id], default_flow_style=None)
        if g.final is None:
            end = request + round(GOAL_TIMEOUT_S * S)
            pushed = (g.start[0] + g.push[0], g.start[1] + g.push[1])
            keys.at(start + S, g.start)
            keys.at(start + 2 * S, pushed)
            position = pushed
            goals.append(Goal(request, start, end, payload, "timeout"))
        else:
            end = start + 3 * S
            lift = LIFT_M if g.lift else 0.0
            keys.at(start + S // 2, g.start)
            keys.at(start + S, g.start, lift)
            keys.at(start + 2 * S, g.final, lift)
            keys.at(start + 5 * S // 2, g.final)
            position = g.final
            goals.append(Goal(request, start, end, payload, "result", "{}"))
        restarted = g.final is not None and g.lost_s > 3.0
        if g.table_lost_s > 0.0:
            table_losses.append((start + S // 2, g.table_lost_s))
        if g.lost_s > 0.0:
            lost_from = end - S // 5 if restarted else end - 150 * MS
            losses.append((lost_from, g.lost_s))
        if g.final is not None and not restarted:
            lookups.append(end + 10 * MS)
        truth.append(
            {
                "object_id": g.object_id,
                "object": name,
                "start_ns": start,
                "end_ns": end,
                "completed": g.final is not None,
                "lifted": g.final is not None and g.lift,
                "restarted": restarted,
                "target": list(g.target),
                "final": None if g.final is None else list(g.final),
                "lost_s": g.lost_s,
            }
        )
        t = end + (4 * S if restarted else S // 2)
        if restarted:  # the same goal again, once tracking is back
            again = GoalPlan(
                g.object_id,
                g.start,
                g.then_target or g.target,
                g.then_final or g.final,
                g.lift,
                g.push,
                g.then_lost_s,
            )
            pending.insert(0, again)
    if plan.stop_object is not None:
        name = descriptions[plan.stop_object]
        manual.append(
            ManualOperation(
                t + S // 2, None, f"Place the {name} on the table, with MoCap markers attached."
            )
        )
        t_end, end_kind = t + 3 * S // 2, "stop"
    else:
        t_end, end_kind = t + S // 2, "end"
    keys.at(t_end + 3 * S, position)
    scenario, published = _scenario(
        plan, keys, manual, goals, lookups, (losses, table_losses), t_end, end_kind
    )
    scenario = _with_saves(scenario, published, truth, plan)
    return scenario, {"goals": truth, "t_start_ns": plan.t0_ns + 2 * S, "t_end_ns": t_end}


def _scenario(
    plan: RunPlan,
    keys: _Keys,
    manual: list[ManualOperation],
    goals: list[Goal],
    lookups: list[int],
    losses: tuple[list[tuple[int, float]], list[tuple[int, float]]],
    t_end: int,
    end_kind: str,
) -> tuple[RsbbScenario, dict[str, Any]]:
    rng = np.random.default_rng(plan.seed)
    frames = frame_times(plan.t0_ns, (t_end + 3 * S - plan.t0_ns) / S)
    rows = np.array(keys.rows, dtype=np.float64)
    order = np.argsort(rows[:, 0], kind="stable")
    rows = rows[order]
    local = np.column_stack([np.interp(frames, rows[:, 0], rows[:, c]) for c in (1, 2, 3)])
    p, r = _table_pose()
    obj_xyz = _world(local)
    obj_q = np.tile(r.as_quat(), (len(frames), 1))
    lost = [[TrackingLoss(t0, 0, round(s * 120)) for t0, s in part] for part in losses]
    actor = simulate_mocap(frames, obj_xyz, obj_q, rng=rng, noise=NOISE, losses=lost[0])
    table = simulate_mocap(
        frames,
        np.tile(p, (len(frames), 1)),
        np.tile(r.as_quat(), (len(frames), 1)),
        rng=rng,
        noise=NOISE,
        losses=lost[1],
    )
    identity = ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0))
    sc = RsbbScenario(
        code=CODE,
        team=plan.team,
        run=plan.run,
        season="2019",
        t_connect_ns=plan.t0_ns + S // 2,
        t_start_ns=plan.t0_ns + 2 * S,
        t_end_ns=t_end,
        end=end_kind,
        t_disconnect_ns=t_end + 2 * S,
        manual_operations=tuple(manual),
        goals=tuple(goals),
        broadcasts=tuple(Broadcast(t, FRAME.child, FRAME.parent, *identity) for t in lookups),
        params={
            "objects": [dict(o) for o in plan.objects],
            "table_size": dict(TABLE_SIZE),
            "goal_timeout": GOAL_TIMEOUT_S,
        },
        bodies=(
            Body("table_origin", table, record_topics=False),
            Body("actor_markerset", actor, record_topics=False),
        ),
    )
    # what the script's tf saw: /tf stamps are the header stamps + 5 us (ertools.simulator.rsbb)
    published = {
        "actor": (actor.t_header_ns + 5_000, actor.xyz, actor.quat_xyzw),
        "table": (table.t_header_ns + 5_000, table.xyz, table.quat_xyzw),
        "lookups": lookups,
    }
    return sc, published


def _in_table(published: dict[str, Any], t_ns: Sequence[int]) -> np.ndarray:
    """The object's position in the table's frame at the lookups, from the published /tf."""
    t = np.asarray(t_ns, dtype=np.int64)
    pa, _ = _interp(t, *published["actor"])
    pt, rt = _interp(t, *published["table"])
    return np.asarray(rt.inv().apply(pa - pt)).reshape(-1, 3)


def _with_saves(
    sc: RsbbScenario, published: dict[str, Any], truth: list[dict[str, Any]], plan: RunPlan
) -> RsbbScenario:
    """The script's saves (2019), its numbers from the published data: a save after each
    goal's segment time and one at the end of each iteration, then ``end_benchmark``'s."""
    n = len(plan.objects)
    score: dict[str, Any] = {}
    saves: list[Save] = []
    elapsed = completed = grasped = 0
    total: float = 0
    lookups = list(published["lookups"])
    index = 0
    lookups.pop(0)  # the first goal's reference lookup
    for g in truth:
        key = f"goal_{index}"
        entry: dict[str, Any] = {}
        score[key] = entry
        seg = g["end_ns"] - g["start_ns"]
        elapsed += seg
        entry["segment_time [s]"] = _to_sec(seg)
        saves.append(Save(g["end_ns"], _copy(score)))
        entry["timeout"] = not g["completed"]
        entry["completed"] = g["completed"]
        if g["completed"]:
            completed += 1
            grasped += int(g["lifted"])
            if g["restarted"]:
                elapsed -= seg
                lookups.pop(0)  # the next attempt's reference lookup
                continue
            final_ns = lookups.pop(0)
            x, y, _ = _in_table(published, [final_ns])[0]
            tx, ty = g["target"]
            distance = math.sqrt((tx - x) ** 2 + (ty - y) ** 2)
            total += distance
            entry["Object grasped"] = g["lifted"]
            entry["Distance error"] = distance
            entry["Target object position"] = "(%.2f, %.2f)" % (tx, ty)  # noqa: UP031
            entry["Measured object position"] = "(%.2f, %.2f)" % (x, y)  # noqa: UP031
            entry["Object type"] = "%s (id %d)" % (g["object"], g["object_id"])  # noqa: UP031
            score["Objects grasped"] = f"{grasped} out of {n}"
            score["Avg distance error"] = total / completed
        else:
            entry["result"] = "Not completed"
        score["execution_time"] = _to_sec(elapsed)
        saves.append(Save(g["end_ns"] + 50 * MS, _copy(score)))
        if lookups:
            lookups.pop(0)  # the next goal's reference lookup
        index += 1
    if plan.stop_object is not None:
        score[f"goal_{index}"] = {}
    saves.append(Save(sc.t_end_ns or sc.t_disconnect_ns, _copy(score)))
    return RsbbScenario(**{**sc.__dict__, "saves": tuple(saves)})


def _copy(score: dict[str, Any]) -> dict[str, Any]:
    return {k: dict(v) if isinstance(v, dict) else v for k, v in score.items()}


#: The sample run (``generate``): four objects, a timeout, a restart, a short loss, a stop.
SAMPLE = RunPlan(
    TEAM,
    1,
    T0,
    (
        GoalPlan(2, (0.30, 0.40), (0.62, 1.05), (0.65, 1.05)),
        GoalPlan(4, (0.70, 0.30), (0.40, 0.90), None, lift=False),
        GoalPlan(
            1,
            (0.25, 1.10),
            (0.70, 0.50),
            (0.70, 0.55),
            lost_s=3.5,
            then_lost_s=0.3,
            then_target=(0.75, 0.60),
            then_final=(0.75, 0.65),
        ),
    ),
    stop_object=3,
)


def expected(truth: dict[str, Any], objects: int) -> dict[str, Any]:
    """The answers from the noiseless truth: per goal its time, outcome, grasp and distance;
    the 2019 script's totals and ertools' (only measured goals, none across a 0.3 s gap)."""
    goals = []
    counted_2019 = grasped_2019 = counted = grasped = 0
    sum_2019 = sum_ertools = 0.0
    elapsed = 0
    index = 0
    for g in truth["goals"]:
        seg = g["end_ns"] - g["start_ns"]
        row: dict[str, Any] = {
            "goal": index,
            "object": g["object"],
            "segment_time": seg / 1e9,
            "completed": g["completed"],
            "timeout": not g["completed"],
            "grasped": g["lifted"],
            "restarted": g["restarted"],
            "distance_error": None,
        }
        elapsed += seg
        if g["completed"]:
            counted_2019 += 1
            grasped_2019 += int(g["lifted"])
        if g["completed"] and not g["restarted"]:
            d = math.dist(g["target"], g["final"])
            row["distance_error"] = d
            sum_2019 += d
            if g["lost_s"] <= 0.1:  # ertools' --max-gap: a longer loss leaves it unmeasured
                counted += 1
                grasped += int(g["lifted"])
                sum_ertools += d
        if g["restarted"]:
            elapsed -= seg
        else:
            index += 1
        goals.append(row)
    return {
        "goals": goals,
        "rules_2019": {
            "Objects grasped": f"{grasped_2019} out of {objects}",
            "Avg distance error": sum_2019 / counted_2019 if counted_2019 else None,
            "execution_time": elapsed / 1e9,
        },
        "ertools": {
            "Objects grasped": f"{grasped} out of {objects}",
            "Avg distance error": sum_ertools / counted if counted else None,
            "execution_time": elapsed / 1e9,
        },
    }


TOLERANCE = {
    "distance_error": tol(
        2e-3,
        "object and table each 0.2 mm and 0.2 mrad of mocap noise per axis; the table's "
        "rotation noise moves a point 1 m away 0.2 mm: a few sigma within 2 mm",
    ),
    "segment_time": tol(1e-9, "the RefBox's logged moments, exact"),
    "grasped": tol(0.0, "a 10 cm lift against a 3 cm threshold, or none: exact"),
}


def write_config(root: Path, objects: Sequence[dict[str, Any]] = OBJECTS) -> Path:
    """``rsbb_bmbox/scripts/benchmark_configs/HGMF.yaml`` under ``root``."""
    path = root / "rsbb_bmbox" / "scripts" / "benchmark_configs" / f"{CODE}.yaml"
    path.parent.mkdir(parents=True, exist_ok=True)
    data = {
        "objects": [dict(o) for o in objects],
        "table_size": dict(TABLE_SIZE),
        "goal_timeout": GOAL_TIMEOUT_S,
    }
    write_text(path, yaml.safe_dump(data, sort_keys=False))
    return path


def generate(outdir: Path, *, seed: int) -> list[Path]:
    """Write the sample run in the RSBB layout under ``outdir`` with its config, and its answers
    beside ``outdir`` (:func:`~ertools.simulator.answers.write_layout_answers`)."""
    plan = RunPlan(**{**SAMPLE.__dict__, "seed": seed})
    scenario, truth = build(plan)
    paths = write_rsbb_run(outdir, scenario, compression="bz2")
    config = write_config(outdir)
    run = RunAnswers(
        paths.bag,
        parameters={
            "table": {"xyz": list(TABLE_XYZ), "yaw": TABLE_YAW},
            "lift_m": LIFT_M,
            "noise": {"sigma_m": NOISE.sigma_m, "sigma_rad": NOISE.sigma_rad},
            "goal_timeout": GOAL_TIMEOUT_S,
        },
        truth={
            "run": window(truth["t_start_ns"], truth["t_end_ns"]),
            "goals": [
                {
                    **{k: v for k, v in g.items() if k not in ("start_ns", "end_ns")},
                    **window(g["start_ns"], g["end_ns"]),
                }
                for g in truth["goals"]
            ],
        },
        expected=expected(truth, len(plan.objects)),
        tolerance=TOLERANCE,
    )
    # beside the layout, not in it: rescore would list it as a file that is not a log
    answers = write_layout_answers(outdir, [run], benchmark="hgmf", scenario="hgmf", seed=seed)
    return [paths.bag, paths.result, config, answers]
