"""Simulated HNF runs for the tests: a moving, noisy robot marker set, goals, the referee's
prompts, the script's lookups (broadcasts), written as a run bag in the RSBB layout with the
transform and config files beside it.

The script's saves (the live score and the result file) are the replay's own: a run is written
once without them, replayed (``rsbb_replay.hnf``), then written again with every save the
replay made, so that the recomputed score can be compared with what the script published.
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
from tests.helpers.rsbb_replay import hnf as replay_hnf
from tests.helpers.rsbb_replay.fromlog import timeline_from_bag
from tests.helpers.rsbb_replay.scenarios import T0, at
from tests.helpers.rsbb_replay.world import ReplayResult, World, run_script

PROMPT = replay_hnf.PROMPT
# markerset_to_robot_transform as a team's file writes it: 4 decimals, |q| = 0.99998
TEAM = ([0.12, -0.05, -0.31], [0.0, 0.0, 0.7071, 0.7071])
TEAM_2017 = ([0.12, -0.05, -0.31], [0.0, 0.0, 0.7071, 0.7071])


def moving_robot(seconds: float, losses: tuple[TrackingLoss, ...] = (), seed: int = 5) -> Body:
    """The robot's marker set: drifting, swaying, turning through +-pi (0.25 rad/s)."""
    t = frame_times(T0, seconds)
    s = (t - T0) / 1e9
    xyz = np.stack([0.5 + 0.05 * s, np.sin(0.3 * s), 0.3 + 0.0 * s], axis=-1)
    yaw = 2.5 + 0.25 * s
    quat = np.stack([np.zeros_like(s), np.zeros_like(s), np.sin(yaw / 2), np.cos(yaw / 2)], -1)
    pub = simulate_mocap(
        t, xyz, quat, rng=np.random.default_rng(seed), noise=MocapNoise(), losses=list(losses)
    )
    return Body("robot_markerset", pub)


def goal(
    request_s: float,
    start_s: float | None,
    end_s: float | None,
    wp: list[Any],
    outcome: str = "result",
    result: str = "{}",
) -> Goal:
    """A goal for waypoint ``wp`` (its payload the script's dump); ``stopped``: the benchmark
    stopped before its end (``end_s`` None)."""
    payload = yaml.dump(wp, default_flow_style=None)
    if outcome == "stopped":
        outcome, end_s = "result", None
    return Goal(
        at(request_s),
        None if start_s is None else at(start_s),
        None if end_s is None else at(end_s),
        payload,
        outcome,
        result if outcome == "result" else "",
    )


def prompt(request_s: float, done_s: float | None, answer: str = "") -> ManualOperation:
    return ManualOperation(at(request_s), None if done_s is None else at(done_s), PROMPT, answer)


def lookups(*seconds: float) -> tuple[Broadcast, ...]:
    return tuple(
        Broadcast(at(s), "/robot", "/robot_markerset", tuple(TEAM[0]), tuple(TEAM[1]))
        for s in seconds
    )  # type: ignore[arg-type]


@dataclass(frozen=True)
class HnfRun:
    """A written run: its bag, side files, and the replay's result on it."""

    bag: Path
    config: Path
    transform: Path
    result: Path
    params: dict[str, Any]
    replay: ReplayResult


def write_run(
    folder: Path,
    *,
    waypoints: list[list[Any]],
    goals: tuple[Goal, ...],
    manual: tuple[ManualOperation, ...] = (),
    broadcasts: tuple[Broadcast, ...] = (),
    end: tuple[str, float] = ("end", 0.0),
    seconds: float = 80.0,
    losses: tuple[TrackingLoss, ...] = (),
    version: str = "2bb8a41",
    team: str = "homer",
) -> HnfRun:
    """Write the run (twice: the second time with the replay's saves) and its side files."""
    params = {"starting_pose": [0.0, 0.0, 0.0], "waypoints": waypoints, "goal_timeout": 120}
    kind, t_end = end
    last = t_end if t_end else seconds - 4.0
    season = "2019" if version == "2bb8a41" else "2017"
    sc = RsbbScenario(
        code="HNF",
        team=team,
        run=1,
        season=season,
        t_connect_ns=at(0.5),
        t_start_ns=at(2.0),
        t_end_ns=at(last),
        end=kind,
        t_disconnect_ns=at(last + 1.0),
        manual_operations=manual,
        goals=goals,
        broadcasts=broadcasts,
        saves=(Save(at(1.0), {}),),
        params=params,
        bodies=(moving_robot(seconds, losses),),
    )
    key = (
        "markerset_to_robot_transform"
        if version in ("2bb8a41", "00e3106")
        else "marker_to_robot_transform"
    )
    pair = [list(TEAM[0]), list(TEAM[1])]

    def side(root: Path) -> tuple[Path, Path]:
        tdir = root / "rsbb_etc" / "transforms"
        tdir.mkdir(parents=True, exist_ok=True)
        transform = tdir / f"transform-{team}.yaml"
        transform.write_text(
            f"team_name: {team}\n{key}: !!python/tuple\n- {pair[0]}\n- {pair[1]}\n",
            encoding="utf-8",
        )
        cdir = root / "rsbb_bmbox" / "scripts" / "benchmark_configs"
        cdir.mkdir(parents=True, exist_ok=True)
        config = cdir / "HNF.yaml"
        config.write_text(yaml.safe_dump(params, default_flow_style=None), encoding="utf-8")
        return config, transform

    first = write_rsbb_run(folder / "draft", sc)
    replay = run_script(
        World(timeline_from_bag(first.bag, params, {"transform": pair}, team=team)),
        lambda w: replay_hnf.execute(w, version),
    )
    saves = tuple(Save(t, score) for t, score in replay.saves if t <= at(last + 0.9))
    final = write_rsbb_run(folder / "season", replace(sc, saves=saves or (Save(at(1.0), {}),)))
    config, transform = side(folder / "season")
    return HnfRun(final.bag, config, transform, final.result, params, replay)
