"""Scenario ``hpff``: two simulated HPFF runs of team ``simbot`` in the RSBB's folder layout.

A person wearing a cap (tilted 0.1 rad forward) walks a circle of 1.5 m radius at 0.2 m/s;
the robot follows on the same circle, 11 s behind (about 2 m) give or take a slow sway of
1.5 s. Its marker set sits 0.4 m above its odometric centre, 10 cm ahead, 5 cm left, turned
-0.3 rad (``transform-simbot.yaml``). The mocap adds noise (0.2 mm, 0.5 mrad) and jitter,
on ``/tf`` only (the pose topics, which neither the script nor ertools reads, are left out to
keep the sample small).

- ``run_1``: the config's goal_timeout is 40 s; the RefBox times the goal out; the cap is lost
  for 2 s at 25 s (the relative lookups fail, the grid samples there are not measured); the
  script aborts the run after its loop (a RefBox STOP, as every HPFF run ends).
- ``run_2``: the referee stops the run at 20 s, while the script samples (its score ``{}``).

The script's lookups (its ``/robot`` broadcasts) follow its schedule: the check 10 ms after the
start, then from 8 s after the robot's start every 0.5 s a relative lookup 1 ms into the sample
and an absolute one 6 ms later (201 ms when the relative failed). Its saves hold the 2019
script's score computed from the published mocap with tf's arithmetic
(:mod:`ertools.simulator.tf_lookup`).

Answers (in ``<folder>.answers.yaml`` beside the layout folder, not in it, per run bag),
from the noiseless truth: for ertools' reading (a 2 Hz grid from 8 s after the
RefBox's goal start, horizontal distances, a sample measured where neither body's mocap has a
gap over 0.1 s around it) and for the 2019 script (its samples, distances in the cap's frame):
the samples, the average deviation, the distance covered, the reliability, the duration.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np

from ertools.arrays import F64
from ertools.geometry import compose, invert, quat_from_yaw, rotate
from ertools.rsbb.py2 import percent_py2, to_sec
from ertools.simulator.answers import RunAnswers, tol, write_layout_answers
from ertools.simulator.mocap import MocapNoise, TrackingLoss, frame_times, simulate_mocap
from ertools.simulator.rsbb import TF_STAMP_LAG_NS, write_rsbb_run
from ertools.simulator.rsbb_files import write_script_config, write_team_transform
from ertools.simulator.rsbb_scenario import Body, Broadcast, Goal, RsbbScenario, Save
from ertools.simulator.tf_lookup import Link, lookup

S = 1_000_000_000
MS = 1_000_000
T0 = 1_554_906_131 * S  # 2019-04-10 14:22:11 UTC (15:22:11 WEST)
TEAM = "simbot"
PARAMS = {
    "min_following_distance": 0.15,
    "max_following_distance": 3.5,
    "desired_following_distance": 2.0,
    "goal_timeout": 40,
}
RADIUS, SPEED, LAG_S, CAP_TILT = 1.5, 0.2, 11.0, 0.1
MARKER_TO_ROBOT = ((0.1, 0.05, -0.4), -0.3)
CAP_LOST = (25.0, 2.0)  # seconds after the run's start, for how long


def _quat(yaw: F64, tilt: float = 0.0) -> F64:
    """Yaw then a tilt about the body's y axis (forward), as (x, y, z, w) rows."""
    cz, sz = np.cos(yaw / 2), np.sin(yaw / 2)
    cy, sy = math.cos(tilt / 2), math.sin(tilt / 2)
    return np.stack([-sz * sy * np.ones_like(yaw), cz * sy, sz * cy, cz * cy], -1)


def _on_circle(s: F64) -> tuple[F64, F64]:
    """(x, y) and heading on the circle after ``s`` seconds of walking."""
    w = SPEED / RADIUS
    xy = np.stack([1.0 + RADIUS * np.cos(w * s), RADIUS * np.sin(w * s)], -1)
    return xy, w * s + np.pi / 2


def _truth(t_ns: np.ndarray, t0: int) -> tuple[F64, F64, F64, F64]:
    """Robot (x, y, yaw) and the cap's position (x, y, z) and rotation at ``t_ns``."""
    s = (np.asarray(t_ns) - t0) / 1e9
    cap_xy, cap_heading = _on_circle(s)
    lag = LAG_S + 1.5 * np.sin(2 * np.pi * s / 40.0)
    robot_xy, robot_heading = _on_circle(s - lag)
    robot = np.column_stack([robot_xy, robot_heading])
    cap = np.column_stack([cap_xy, np.full(len(s), 1.7)])
    return robot, cap, _quat(cap_heading, CAP_TILT), _quat(robot_heading)


def _team() -> tuple[F64, F64]:
    t, yaw = MARKER_TO_ROBOT
    return np.asarray(t), quat_from_yaw(yaw)


def _marker(robot: F64, robot_q: F64) -> tuple[F64, F64]:
    t_mr, q_mr = _team()
    t_rm, q_rm = invert(t_mr, q_mr)
    xyz = np.column_stack([robot[:, :2], np.zeros(len(robot))])
    n = len(robot)
    return compose(xyz, robot_q, np.tile(t_rm, (n, 1)), np.tile(q_rm, (n, 1)))


def _in_cap_plane(robot: F64, cap: F64, cap_q: F64) -> F64:
    """The robot's odometric centre in the cap's frame, its x-y distance (the script's)."""
    rel = np.column_stack([robot[:, :2], np.zeros(len(robot))]) - cap
    local = rotate(cap_q * np.array([-1.0, -1.0, -1.0, 1.0]), rel)
    return np.asarray(np.hypot(local[:, 0], local[:, 1]))


def _stats(
    distance: F64, measured: np.ndarray, robot_xy: F64, robot_ok: np.ndarray
) -> dict[str, Any]:
    """The script's statistics (fbm5_person_following.py l. 105-131, 162-172)."""
    d = PARAMS["desired_following_distance"]
    dev_sum = 0.0
    covered = 0.0
    for k in range(len(distance)):
        if not measured[k]:
            continue
        dev_sum += abs(float(distance[k]) - d)
        in_range = (
            PARAMS["min_following_distance"] <= distance[k] <= PARAMS["max_following_distance"]
        )
        if in_range and k > 0 and robot_ok[k] and robot_ok[k - 1]:
            dx, dy = (float(v) for v in robot_xy[k] - robot_xy[k - 1])
            covered += math.hypot(dx, dy)
    n, f = int(measured.sum()), int((~measured).sum())
    percent = f / float(n + f) * 100
    return {
        "Average deviation from desired distance": dev_sum / n,
        "Distance covered while following": covered,
        "Benchmark reliability": percent_py2(100 - percent, 1),
    }


def _lost(t_s: float) -> bool:
    a, d = CAP_LOST
    return a - 0.2 <= t_s <= a + d


def _schedule(start_s: float, end_s: float) -> tuple[list[float], list[float], list[float]]:
    """The script's samples: (starts, relative moments or -1, absolute moments)."""
    starts, rel, ab = [], [], []
    s = start_s + 8.0
    while s < end_s:
        ok = not _lost(s)
        starts.append(s)
        rel.append(s + 0.001 if ok else -1.0)
        ab.append(s + (0.007 if ok else 0.201))
        s += 0.5
    return starts, rel, ab


def _run(
    outdir: Path, run: int, stop_s: float | None, seed: int, t0: int
) -> tuple[list[Path], RunAnswers]:
    rng = np.random.default_rng([seed, run])
    request, start = 3.0, 3.6
    timeout_end = request + PARAMS["goal_timeout"]
    loop_end = stop_s if stop_s is not None else timeout_end
    starts, rel, ab = _schedule(start, loop_end)
    end_s = (starts[-1] + 0.5 if stop_s is None else stop_s) + 0.1
    t = frame_times(t0, end_s + 2.0)
    robot, cap, cap_q, robot_q = _truth(t, t0)
    m_xyz, m_q = _marker(robot, robot_q)
    noise = MocapNoise()
    lost = [TrackingLoss(t0 + round(CAP_LOST[0] * S), 0, round(CAP_LOST[1] * 120))]
    lost = lost if CAP_LOST[0] + CAP_LOST[1] < end_s else []  # run 2 stops before it
    robot_pub = simulate_mocap(t, m_xyz, m_q, rng=rng, noise=noise)
    cap_pub = simulate_mocap(t, cap, cap_q, rng=rng, noise=noise, losses=lost)
    at = [t0 + round(x * S) for x in [2.01, *[r for r in rel if r >= 0], *ab]]
    at.sort()
    t_mr, q_mr = _team()
    team_t = (float(t_mr[0]), float(t_mr[1]), float(t_mr[2]))
    team_q = (float(q_mr[0]), float(q_mr[1]), float(q_mr[2]), float(q_mr[3]))
    team = (team_t, team_q)
    score: dict[str, Any] = {}
    if stop_s is None:
        track = Link(robot_pub.t_header_ns + TF_STAMP_LAG_NS, robot_pub.xyz, robot_pub.quat_xyzw)
        person = Link(cap_pub.t_header_ns + TF_STAMP_LAG_NS, cap_pub.xyz, cap_pub.quat_xyzw)
        ok = np.array([r >= 0 for r in rel])
        rel_ns = np.array(
            [t0 + round((r if r >= 0 else s) * S) for r, s in zip(rel, starts, strict=True)]
        )
        relative = [lookup(track, int(x), team, person).xyz for x in rel_ns]
        absolute = [lookup(track, t0 + round(a * S), team).xyz for a in ab]
        score = _stats(
            np.hypot([p[0] for p in relative], [p[1] for p in relative]),
            ok,
            np.array([[p[0], p[1]] for p in absolute]),
            np.ones(len(ab), dtype=bool),
        )
    sc = RsbbScenario(
        code="HPFF",
        team=TEAM,
        run=run,
        season="2019",
        t_connect_ns=t0 + 500 * MS,
        t_start_ns=t0 + 2 * S,
        t_end_ns=t0 + round(end_s * S),
        end="stop",
        t_disconnect_ns=t0 + round((end_s + 1.0) * S),
        goals=(
            Goal(
                t0 + round(request * S),
                t0 + round(start * S),
                None if stop_s is not None else t0 + round(timeout_end * S),
                "{}\n",
                "result" if stop_s is not None else "timeout",
            ),
        ),
        broadcasts=tuple(Broadcast(x, "/robot", "/robot_markerset", team_t, team_q) for x in at),
        saves=(Save(t0 + round(end_s * S), score),),
        params=PARAMS,
        # /tf only: the pose topics (the scripts and ertools read neither) would double the size
        bodies=(
            Body("robot_markerset", robot_pub, record_topics=False),
            Body("actor_markerset", cap_pub, record_topics=False),
        ),
        utc_offset_s=3600,
        tz_name="WEST",
    )
    paths = write_rsbb_run(outdir, sc, compression="bz2")
    return [paths.bag, paths.result], _answers(paths.bag, run, t0, starts, rel, ab, stop_s)


def _answers(
    bag: Path,
    run: int,
    t0: int,
    starts: list[float],
    rel: list[float],
    ab: list[float],
    stop_s: float | None,
) -> RunAnswers:
    grid_end = stop_s if stop_s is not None else 3.0 + PARAMS["goal_timeout"]
    grid = np.arange(3.6 + 8.0, grid_end - 1e-9, 0.5)
    g_ns = t0 + np.round(grid * S).astype(np.int64)
    robot, cap, _, _ = _truth(g_ns, t0)
    a, d = CAP_LOST
    measured = ~((grid > a - 0.05) & (grid < a + d + 0.05))  # inside the gap (12 ms of margin)
    horizontal = np.hypot(robot[:, 0] - cap[:, 0], robot[:, 1] - cap[:, 1])
    expected: dict[str, Any] = {
        "ertools": {
            "samples": len(grid),
            "measured": int(measured.sum()),
            **_stats(horizontal, measured, robot[:, :2], np.ones(len(grid), dtype=bool)),
            "duration": (grid_end - 3.6) if stop_s is None else None,
        }
    }
    if stop_s is None:
        rel_ok = np.array([r >= 0 for r in rel])
        r_ns = t0 + np.round(
            np.array([r if r >= 0 else s for r, s in zip(rel, starts, strict=True)]) * S
        ).astype(np.int64)
        robot_r, cap_r, cap_q_r, _ = _truth(r_ns, t0)
        robot_a, _, _, _ = _truth(t0 + np.round(np.array(ab) * S).astype(np.int64), t0)
        expected["2019"] = {
            "samples": len(starts),
            "measured": int(rel_ok.sum()),
            **_stats(
                _in_cap_plane(robot_r, cap_r, cap_q_r),
                rel_ok,
                robot_a[:, :2],
                np.ones(len(ab), dtype=bool),
            ),
            "duration": to_sec(round((starts[-1] + 0.5 - 3.6) * S)),
        }
    return RunAnswers(
        bag,
        parameters={"team": TEAM, "run": run, **PARAMS, "cap_lost": list(CAP_LOST), "stop": stop_s},
        truth={"radius": RADIUS, "speed": SPEED, "lag_s": LAG_S, "cap_tilt": CAP_TILT},
        expected=expected,
        tolerance={
            "deviation": tol(
                1e-3,
                "mocap noise: 0.2 mm per axis on each body, 0.5 mrad through the robot's 0.42 m "
                "lever arm (0.2 mm) and the cap's 0.5 mrad tilt noise over 2 m (1 mm, in the "
                "script's cap frame), averaged over ~60 samples: 0.15 mm; lookup time: both "
                "walk at 0.2 m/s, the header jitter (0.2 ms) moves a sample by 0.04 mm, and "
                "tf's linear interpolation on the circle errs by under 1 um",
            ),
            "covered": tol(
                5e-3,
                "mocap noise: each step's length errs by the noise along the walk (~0.4 mm); "
                "along a slowly turning path the sum telescopes, to about 1 mm; lookup time: "
                "the header jitter moves each end by 0.04 mm",
            ),
            "duration": tol(1e-6, "the log's moments"),
        },
    )


def generate(outdir: Path, *, seed: int) -> list[Path]:
    """Write both runs and the side files into ``outdir`` (the RSBB's folder layout), and
    their answers beside it (:func:`~ertools.simulator.answers.write_layout_answers`)."""
    written_1, answers_1 = _run(outdir, 1, None, seed, T0)
    written_2, answers_2 = _run(outdir, 2, 20.0, seed, T0 + 900 * S)
    # beside the layout, not in it: rescore would list it as a file that is not a log
    answers = write_layout_answers(
        outdir, [answers_1, answers_2], benchmark="hpff", scenario="hpff", seed=seed
    )
    t_mr, q_mr = _team()
    transform = write_team_transform(outdir, TEAM, t_mr, q_mr)
    config = write_script_config(outdir, "HPFF", PARAMS, flow_style=False)
    return [*written_1, *written_2, transform, config, answers]
