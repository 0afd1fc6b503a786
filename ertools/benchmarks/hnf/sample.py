"""Scenario ``hnf``: two simulated HNF runs of team ``simbot`` in the RSBB's folder layout.

The robot's odometric centre drives between five waypoints (minimum-jerk arcs, zero speed at
both ends) and stops a known small error away from each; its marker set sits 0.4 m above it,
10 cm ahead and 5 cm to the left, turned -0.3 rad: the marker poses are the truth robot poses
composed with the inverse of ``markerset_to_robot_transform`` (``transform-simbot.yaml``).
The mocap adds noise (0.2 mm, 0.5 mrad) and timing jitter; it is on ``/tf`` only (the
body's pose topics, which neither the script nor ertools reads, are left out to keep the
sample small).

- ``run_1``: goals 1, 2 and 5 reached; goal 3 times out (the robot still driving: the
  RefBox's 20 s goal timeout); goal 4 is reached but the marker set is lost for 7 s around the
  script's lookup: five failed attempts, the referee's prompt, answered ``s`` (skipped); the
  script ends the run.
- ``run_2``: goals 1 and 2 reached, then the referee stops the run while the robot drives to
  waypoint 3 (the 2019 script writes no totals).

The script's lookups (its ``/robot`` broadcasts) are 12 ms after each goal's end, as the helper
took them; its saves (the live score and the result file) hold the 2019 script's score
computed from the published mocap with tf's arithmetic (:mod:`ertools.simulator.tf_lookup`).

Answers (in ``<folder>.answers.yaml`` beside the layout folder, not in it, per run bag), from
the noiseless truth at the lookup moments: per segment the robot pose, ``distance_error``,
``orientation_error`` (wrapped; the 2019 per-segment value is the same), and the totals of both
readings: ``ertools`` (completed goals with a pose) and ``2019`` (every pose's error /
completed goals; sin/cos of the unwrapped difference).
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from ertools.arrays import F64
from ertools.frozen_dataclass import frozen_dataclass
from ertools.geometry import compose, invert, quat_from_yaw, wrap_angle
from ertools.rsbb.py2 import to_sec
from ertools.simulator.answers import RunAnswers, tol, write_layout_answers
from ertools.simulator.mocap import MocapNoise, TrackingLoss, frame_times, simulate_mocap
from ertools.simulator.rsbb import TF_STAMP_LAG_NS, write_rsbb_run
from ertools.simulator.rsbb_files import write_script_config, write_team_transform
from ertools.simulator.rsbb_scenario import (
    Body,
    Broadcast,
    Goal,
    ManualOperation,
    RsbbScenario,
    Save,
)
from ertools.simulator.tf_lookup import Link, lookup

S = 1_000_000_000
MS = 1_000_000
T0 = 1_554_903_066 * S  # 2019-04-10 13:31:06 UTC (14:31:06 WEST)
TEAM = "simbot"
GOAL_TIMEOUT = 20
WAYPOINTS = [
    [1.6, 0.4, 0.5],
    [2.4, 2.2, 2.0],
    [0.8, 2.6, 3.0],
    [-1.1, 1.4, -2.0],
    [-0.6, -0.6, -0.4],
]
# where the robot stops for each waypoint (goal 3 never stops: it times out on the way)
STOPS = [
    [1.63, 0.36, 0.55],
    [2.32, 2.26, 1.88],
    [0.9, 2.5, -3.1],
    [-1.1, 1.45, -2.11],
    [-0.61, -0.6, -0.43],
]
MARKER_TO_ROBOT_T = (0.1, 0.05, -0.4)
MARKER_TO_ROBOT_YAW = -0.3
PROMPT = (
    "The position of the robot markerset could not be acquired!\nTry again or skip the "
    "waypoint? type 's' for skip, anything else to try again"
)


def _p3(v: Any) -> tuple[float, float, float]:
    return (float(v[0]), float(v[1]), float(v[2]))


def _min_jerk(tau: F64) -> F64:
    t = np.clip(tau, 0.0, 1.0)
    return np.asarray(10 * t**3 - 15 * t**4 + 6 * t**5)


@frozen_dataclass
class _Leg:
    t0_ns: int
    t1_ns: int
    a: tuple[float, float, float]
    b: tuple[float, float, float]


def _robot(t_ns: np.ndarray, start: tuple[float, float, float], legs: list[_Leg]) -> F64:
    """The robot's (x, y, yaw) at ``t_ns``: still, or on a leg."""
    out = np.tile(np.asarray(start, dtype=np.float64), (len(t_ns), 1))
    for leg in legs:
        a, b = np.asarray(leg.a), np.asarray(leg.b)
        d = b - a
        d[2] = float(wrap_angle(d[2]))
        s = _min_jerk((t_ns - leg.t0_ns) / (leg.t1_ns - leg.t0_ns))
        on = t_ns >= leg.t0_ns
        out[on] = a + np.outer(s[on], d)
    out[:, 2] = wrap_angle(out[:, 2])
    return out


def _team() -> tuple[F64, F64]:
    return np.asarray(MARKER_TO_ROBOT_T), quat_from_yaw(MARKER_TO_ROBOT_YAW)


def _marker(robot: F64) -> tuple[F64, F64]:
    """Marker set poses for robot (x, y, yaw) rows: T_world_robot * T_marker_robot^-1."""
    t_mr, q_mr = _team()
    t_rm, q_rm = invert(t_mr, q_mr)
    xyz = np.column_stack([robot[:, 0], robot[:, 1], np.zeros(len(robot))])
    return compose(
        xyz,
        quat_from_yaw(robot[:, 2]),
        np.tile(t_rm, (len(robot), 1)),
        np.tile(q_rm, (len(robot), 1)),
    )


@frozen_dataclass
class _Plan:
    """One run's timeline: goals (request, start, end, outcome), lookups, prompts, end."""

    goals: list[tuple[int, int, int | None, str]]
    legs: list[_Leg]
    lookups: list[int]
    prompts: list[tuple[int, int, str]]
    losses: list[TrackingLoss]
    end: tuple[str, int]
    lookup_of: dict[int, int]  # goal index -> lookup time


def _plan(stop_at_goal: int | None) -> _Plan:
    t = 3 * S
    pose: tuple[float, float, float] = (0.0, 0.0, 0.0)
    goals: list[tuple[int, int, int | None, str]] = []
    legs: list[_Leg] = []
    lookups: list[int] = []
    prompts: list[tuple[int, int, str]] = []
    losses: list[TrackingLoss] = []
    lookup_of: dict[int, int] = {}
    for k, stop in enumerate(STOPS):
        request, start = t, t + 600 * MS
        drive0 = start + 1 * S
        if stop_at_goal == k:
            legs.append(_Leg(drive0, drive0 + 12 * S, pose, _p3(stop)))
            goals.append((request, start, None, "stopped"))
            return _Plan(goals, legs, lookups, prompts, losses, ("stop", drive0 + 5 * S), lookup_of)
        if k == 2:  # too slow: the RefBox times the goal out while the robot drives
            legs.append(_Leg(drive0, drive0 + 30 * S, pose, _p3(stop)))
            end = request + GOAL_TIMEOUT * S
            goals.append((request, start, end, "timeout"))
            at = end + 12 * MS
            pose = _p3(_robot(np.array([at], np.int64), pose, legs[-1:])[0])
            legs.append(_Leg(at, at + 1, pose, pose))  # the robot stops where it was
        else:
            legs.append(_Leg(drive0, drive0 + 7 * S, pose, _p3(stop)))
            end = drive0 + 7 * S + 1500 * MS
            goals.append((request, start, end, "result"))
            pose = _p3(stop)
        if k == 3:  # the marker set lost for 7 s: five failed attempts, the prompt, "s"
            losses.append(TrackingLoss(end - 300 * MS, 0, 7 * 120))
            prompts.append((end + 5050 * MS, end + 8 * S, "s"))
            t = end + 9 * S
            continue
        at = end + 12 * MS
        lookups.append(at)
        lookup_of[k] = at
        t = at + 800 * MS
    return _Plan(goals, legs, lookups, prompts, losses, ("end", t), lookup_of)


def _live_score(plan: _Plan, published: Link, t_start: int) -> dict[str, Any]:
    """The 2019 script's score (fbm2_navigation.py l. 96-238) from the published mocap."""
    t_mr, q_mr = _team()
    transform = (tuple(float(v) for v in t_mr), tuple(float(v) for v in q_mr))
    score: dict[str, Any] = {}
    sum_d = sum_s = sum_c = 0.0
    elapsed = 0
    reached = timed_out = 0
    for k, (_, start, end, outcome) in enumerate(plan.goals):
        seg: dict[str, Any] = {"start_segment_time[s]": to_sec(start - t_start)}
        if end is None:
            stop = plan.end[1]
            seg.update(
                {
                    "end_segment_time[s]": to_sec(stop - t_start),
                    "segment_time[s]": to_sec(stop - start),
                }
            )
            seg.update({"timeout": None, "completed": False})
            score[f"segment_{k + 1}"] = seg
            return score  # stopped: no totals
        seg.update(
            {"end_segment_time[s]": to_sec(end - t_start), "segment_time[s]": to_sec(end - start)}
        )
        elapsed += end - start
        seg["timeout"] = outcome == "timeout"
        seg["completed"] = outcome == "result"
        timed_out += outcome == "timeout"
        if outcome == "result":
            reached += 1
            seg["result"] = None
        w = WAYPOINTS[k]
        seg["target_pose"] = _dump(w)
        at = plan.lookup_of.get(k)
        if at is None:
            seg["robot_pose"] = "null\n...\n"
        else:
            p = lookup(published, at, transform)
            x, y, th = p.xyz[0], p.xyz[1], p.yaw
            seg["robot_pose"] = _dump([x, y, th])
            d = math.sqrt((x - w[0]) ** 2 + (y - w[1]) ** 2)
            s, c = math.sin(abs(th - w[2])), math.cos(abs(th - w[2]))
            sum_d, sum_s, sum_c = sum_d + d, sum_s + s, sum_c + c
            seg["distance_error"] = d
            seg["orientation_error"] = math.atan2(abs(s), c)
        score[f"segment_{k + 1}"] = seg
    score["reached_waypoints"] = reached
    score["timed_out_waypoints"] = timed_out
    score["execution_time[s]"] = to_sec(elapsed)
    score["position_accuracy[m]"] = sum_d / reached if reached else None
    score["orientation_accuracy[rad]"] = math.atan2(abs(sum_s), sum_c) if reached else None
    return score


def _dump(pose: list[float]) -> str:
    state = ", ".join(repr(float(v)) for v in pose)
    return f"!!python/object/new:geometry_msgs.msg._Pose2D.Pose2D\nstate: [{state}]\n"


def _answers(plan: _Plan, robot_at: Any, t0: int) -> dict[str, Any]:
    segments = []
    for k, (_, start, end, outcome) in enumerate(plan.goals):
        row: dict[str, Any] = {
            "segment": k + 1,
            "outcome": outcome,
            "start_s": (start - t0) / S,
            "end_s": None if end is None else (end - t0) / S,
        }
        at = plan.lookup_of.get(k)
        if at is not None:
            x, y, yaw = (float(v) for v in robot_at(at))
            w = WAYPOINTS[k]
            row.update(
                robot_pose=[x, y, yaw],
                distance_error=math.hypot(x - w[0], y - w[1]),
                orientation_error=abs(float(wrap_angle(yaw - w[2]))),
                dtheta_unwrapped=yaw - w[2],
            )
        segments.append(row)
    done = [r for r in segments if r["outcome"] != "stopped"]
    posed = [r for r in done if "distance_error" in r]
    completed = [r for r in done if r["outcome"] == "result"]
    both = [r for r in posed if r["outcome"] == "result"]
    out: dict[str, Any] = {"segments": segments}
    if both:
        s = sum(math.sin(r["orientation_error"]) for r in both)
        c = sum(math.cos(r["orientation_error"]) for r in both)
        out["ertools"] = {
            "position_accuracy": sum(r["distance_error"] for r in both) / len(both),
            "orientation_accuracy": math.atan2(s, c),
        }
    if plan.end[0] == "end" and completed:
        s = sum(math.sin(abs(r["dtheta_unwrapped"])) for r in posed)
        c = sum(math.cos(abs(r["dtheta_unwrapped"])) for r in posed)
        out["2019"] = {
            "position_accuracy": sum(r["distance_error"] for r in posed) / len(completed),
            "orientation_accuracy": math.atan2(abs(s), c),
            "reached_waypoints": len(completed),
            "timed_out_waypoints": sum(r["outcome"] == "timeout" for r in done),
        }
    return out


def _run(
    outdir: Path, run: int, stop_at_goal: int | None, seed: int, t0: int
) -> tuple[list[Path], RunAnswers]:
    rng = np.random.default_rng([seed, run])
    plan = _plan(stop_at_goal)
    t_end = plan.end[1]
    t = frame_times(t0, t_end / S + 2.0)
    robot = _robot(t - t0, (0.0, 0.0, 0.0), [_Leg(x.t0_ns, x.t1_ns, x.a, x.b) for x in plan.legs])
    xyz, quat = _marker(robot)
    noise = MocapNoise()
    losses = [TrackingLoss(x.t_ns + t0, x.repeat_frames, x.gap_frames) for x in plan.losses]
    pub = simulate_mocap(t, xyz, quat, rng=rng, noise=noise, losses=losses)
    published = Link(pub.t_header_ns + TF_STAMP_LAG_NS, pub.xyz, pub.quat_xyzw)
    t_start = t0 + 2 * S
    t_mr, q_mr = _team()
    team_t = (float(t_mr[0]), float(t_mr[1]), float(t_mr[2]))
    team_q = (float(q_mr[0]), float(q_mr[1]), float(q_mr[2]), float(q_mr[3]))
    absolute = [(r + t0, s + t0, None if e is None else e + t0, o) for r, s, e, o in plan.goals]
    shifted = _Plan(
        absolute,
        plan.legs,
        [x + t0 for x in plan.lookups],
        [(a + t0, b + t0, c) for a, b, c in plan.prompts],
        plan.losses,
        (plan.end[0], t_end + t0),
        {k: v + t0 for k, v in plan.lookup_of.items()},
    )
    score = _live_score(shifted, published, t_start)
    t_mr, q_mr = _team()
    params = {
        "starting_pose": [0.0, 0.0, 0.0],
        "waypoints": WAYPOINTS,
        "goal_timeout": GOAL_TIMEOUT,
    }
    sc = RsbbScenario(
        code="HNF",
        team=TEAM,
        run=run,
        season="2019",
        t_connect_ns=t0 + 500 * MS,
        t_start_ns=t_start,
        t_end_ns=t_end + t0,
        end=plan.end[0],
        t_disconnect_ns=t_end + t0 + 1 * S,
        manual_operations=tuple(ManualOperation(a, b, PROMPT, c) for a, b, c in shifted.prompts),
        goals=tuple(
            Goal(
                r,
                s,
                e,
                yaml.dump(WAYPOINTS[k], default_flow_style=None),
                "result" if o == "stopped" else o,
                "",
            )
            for k, (r, s, e, o) in enumerate(shifted.goals)
        ),
        broadcasts=tuple(
            Broadcast(at, "/robot", "/robot_markerset", team_t, team_q) for at in shifted.lookups
        ),
        saves=(Save(t_end + t0, score),),
        params=params,
        # /tf only: the pose topics (the scripts and ertools read neither) would double the size
        bodies=(Body("robot_markerset", pub, record_topics=False),),
        utc_offset_s=3600,
        tz_name="WEST",
    )
    paths = write_rsbb_run(outdir, sc, compression="bz2")  # a third of the size

    def robot_at(at: int) -> F64:
        return np.asarray(_robot(np.array([at - t0], np.int64), (0.0, 0.0, 0.0), plan.legs)[0])

    answers = RunAnswers(
        paths.bag,
        parameters={
            "team": TEAM,
            "run": run,
            "goal_timeout": GOAL_TIMEOUT,
            "marker_to_robot_t": list(MARKER_TO_ROBOT_T),
            "marker_to_robot_yaw": MARKER_TO_ROBOT_YAW,
        },
        truth={"waypoints": WAYPOINTS, "stops": STOPS},
        expected=_answers(shifted, robot_at, t0),
        tolerance={
            "distance": tol(
                1e-3,
                "mocap noise: 0.2 mm per axis, and 0.5 mrad through the marker set's 0.42 m "
                "lever arm (0.2 mm), about 0.3 mm per axis: 1 mm is over 3 sigma; lookup time: "
                "the robot stands still at each lookup but goal 3's (timed out at 8 cm/s), "
                "where tf's interpolation over one 8.3 ms frame lags by at most 0.17 mm",
            ),
            "angle": tol(
                2e-3,
                "mocap noise 0.5 mrad per axis: 4 sigma of a yaw; lookup time: at goal 3 "
                "(turning at 0.07 rad/s) the interpolation lags by at most 0.15 mrad",
            ),
        },
    )
    return [paths.bag, paths.result], answers


def generate(outdir: Path, *, seed: int) -> list[Path]:
    """Write both runs and the side files into ``outdir`` (the RSBB's folder layout), and
    their answers beside it (:func:`~ertools.simulator.answers.write_layout_answers`)."""
    written_1, answers_1 = _run(outdir, 1, None, seed, T0)
    written_2, answers_2 = _run(outdir, 2, 2, seed, T0 + 600 * S)
    # beside the layout, not in it: rescore would list it as a file that is not a log
    answers = write_layout_answers(
        outdir, [answers_1, answers_2], benchmark="hnf", scenario="hnf", seed=seed
    )
    t_mr, q_mr = _team()
    transform = write_team_transform(outdir, TEAM, t_mr, q_mr)
    params = {
        "starting_pose": [0.0, 0.0, 0.0],
        "waypoints": WAYPOINTS,
        "goal_timeout": GOAL_TIMEOUT,
    }
    config = write_script_config(outdir, "HNF", params, flow_style=None)
    return [*written_1, *written_2, transform, config, answers]
