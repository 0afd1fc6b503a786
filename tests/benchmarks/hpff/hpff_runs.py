"""Simulated HPFF runs for the tests: a person walking a circle with a tilted cap, the robot
following about 2 m behind, noisy mocap with dropouts; the script's lookups (broadcasts) laid
out as its schedule takes them (a check, then a relative and an absolute lookup every 0.5 s
from 8 s after the robot's start, a lookup missing where its body is lost); written in the
RSBB layout with the replay's own saves as the live score and the result file.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np
import yaml

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
from tests.helpers.rsbb_replay import hpff as replay_hpff
from tests.helpers.rsbb_replay.fromlog import timeline_from_bag
from tests.helpers.rsbb_replay.scenarios import T0, at
from tests.helpers.rsbb_replay.world import ReplayResult, World, run_script

TEAM = ([0.1, 0.05, -0.4], [0.0, 0.0, -0.1494, 0.9888])  # as a team's file writes it
PROMPT = "Failed to acquire pose of human or robot. Make sure they have detectable markersets."
MS = 1_000_000
S = 1_000_000_000


def _circle(t: np.ndarray, lag: float) -> tuple[np.ndarray, np.ndarray]:
    s = (t - T0) / 1e9 - lag
    x = 2.0 + 1.5 * np.cos(0.12 * s)
    y = 1.5 * np.sin(0.12 * s)
    heading = 0.12 * s + np.pi / 2
    return np.stack([x, y], -1), heading


def bodies(
    seconds: float,
    robot_lost: tuple[tuple[float, float], ...],
    person_lost: tuple[tuple[float, float], ...],
) -> tuple[Body, Body]:
    """The robot's marker set (16 s behind on the circle: about 2.1 m) and the person's cap
    (tilted 0.15 rad about x), each lost over the (start, seconds) spans given."""
    t = frame_times(T0, seconds)
    out = []
    for name, lag, z, tilt, lost, seed in (
        ("robot_markerset", 16.0 / 1.5, 0.7, 0.0, robot_lost, 3),
        ("actor_markerset", 0.0, 1.7, 0.15, person_lost, 4),
    ):
        xy, heading = _circle(t, lag)
        xyz = np.column_stack([xy, np.full(len(t), z)])
        cz, sz = np.cos(heading / 2), np.sin(heading / 2)
        cx, sx = np.cos(tilt / 2), np.sin(tilt / 2)
        quat = np.stack([sx * cz, sx * sz, cx * sz, cx * cz], -1)  # yaw then tilt about x
        losses = [TrackingLoss(at(a), 0, round(d * 120)) for a, d in lost]
        pub = simulate_mocap(
            t, xyz, quat, rng=np.random.default_rng(seed), noise=MocapNoise(), losses=losses
        )
        out.append(Body(name, pub))
    return out[0], out[1]


def _lost(t_s: float, spans: tuple[tuple[float, float], ...]) -> bool:
    # a lookup fails when the body's data at its moment did not come within the 0.2 s wait
    return any(a - 0.2 <= t_s <= a + d for a, d in spans)


def schedule(
    start_s: float,
    end_s: float,
    robot_lost: tuple[tuple[float, float], ...] = (),
    person_lost: tuple[tuple[float, float], ...] = (),
) -> list[float]:
    """The script's lookup moments (seconds after T0) from the robot's start to the goal's
    end: each sample's relative lookup 1 ms after it starts, its absolute one 6 ms after the
    relative (or 1 ms after the relative's failed 0.2 s attempt)."""
    out = []
    s = start_s + 8.0
    while s < end_s:
        rel = not _lost(s, robot_lost) and not _lost(s, person_lost)
        if rel:
            out.append(s + 0.001)
        absolute = s + (0.007 if rel else 0.201)
        if not _lost(absolute, robot_lost):
            out.append(absolute)
        s += 0.5
    return out


@dataclass(frozen=True)
class HpffRun:
    bag: Path
    params: dict[str, Any]
    replay: ReplayResult


def write_run(
    folder: Path,
    *,
    goal: Goal,
    lookups: list[float],
    end: tuple[str, float],
    manual: tuple[ManualOperation, ...] = (),
    robot_lost: tuple[tuple[float, float], ...] = (),
    person_lost: tuple[tuple[float, float], ...] = (),
    goal_timeout: float = 40.0,
    team: str = "homer",
) -> HpffRun:
    """Write the run twice (the second time with the replay's saves) and its side files."""
    params = {
        "min_following_distance": 0.15,
        "max_following_distance": 3.5,
        "desired_following_distance": 2.0,
        "goal_timeout": goal_timeout,
    }
    kind, t_end = end
    robot, person = bodies(t_end + 3.0, robot_lost, person_lost)
    sc = RsbbScenario(
        code="HPFF",
        team=team,
        run=1,
        season="2019",
        t_connect_ns=at(0.5),
        t_start_ns=at(2.0),
        t_end_ns=at(t_end),
        end=kind,
        t_disconnect_ns=at(t_end + 1.0),
        manual_operations=manual,
        goals=(goal,),
        broadcasts=tuple(
            Broadcast(at(s), "/robot", "/robot_markerset", tuple(TEAM[0]), tuple(TEAM[1]))
            for s in lookups
        ),  # type: ignore[arg-type]
        saves=(Save(at(1.0), {}),),
        params=params,
        bodies=(robot, person),
    )
    pair = [list(TEAM[0]), list(TEAM[1])]
    first = write_rsbb_run(folder / "draft", sc)
    replay = run_script(
        World(timeline_from_bag(first.bag, params, {"transform": pair}, team=team)),
        replay_hpff.execute,
    )
    saves = tuple(Save(t, s) for t, s in replay.saves if t <= at(t_end + 0.9))
    final = write_rsbb_run(folder / "season", replace(sc, saves=saves or (Save(at(1.0), {}),)))
    root = folder / "season"
    tdir = root / "rsbb_etc" / "transforms"
    tdir.mkdir(parents=True, exist_ok=True)
    (tdir / f"transform-{team}.yaml").write_text(
        f"team_name: {team}\nmarkerset_to_robot_transform: !!python/tuple\n"
        f"- {pair[0]}\n- {pair[1]}\n",
        encoding="utf-8",
    )
    cdir = root / "rsbb_bmbox" / "scripts" / "benchmark_configs"
    cdir.mkdir(parents=True, exist_ok=True)
    (cdir / "HPFF.yaml").write_text(yaml.safe_dump(params), encoding="utf-8")
    return HpffRun(final.bag, params, replay)
