"""Timed RSBB scenarios for the reader's, the layout's and the replays' tests.

Times are seconds after T0; a body stands still (noiseless mocap at 120 Hz) so that every
number a test expects is known.
"""

from __future__ import annotations

from dataclasses import replace
from typing import Any

import numpy as np

from ertools.simulator.mocap import MocapNoise, TrackingLoss, frame_times, simulate_mocap
from ertools.simulator.rsbb_scenario import (
    Body,
    Broadcast,
    Goal,
    ManualOperation,
    RsbbScenario,
    Save,
    still_pose,
)

S = 1_000_000_000
MS = 1_000_000
T0 = 1_555_000_000 * S  # 2019-04-11 16:26:40 UTC
QUIET = MocapNoise(
    sigma_m=0.0,
    sigma_rad=0.0,
    header_jitter_ns=0,
    latency_ns=300_000,
    latency_jitter_ns=0,
    latency_spike_prob=0.0,
)


def at(seconds: float) -> int:
    return T0 + round(seconds * S)


def still_body(
    name: str,
    xyz: tuple[float, float, float],
    seconds: float = 70.0,
    losses: tuple[TrackingLoss, ...] = (),
) -> Body:
    """A noiseless body standing at ``xyz`` from T0 for ``seconds``."""
    t = frame_times(T0, seconds)
    p, q = still_pose(t, xyz, (0.0, 0.0, 0.0, 1.0))
    return Body(
        name,
        simulate_mocap(t, p, q, rng=np.random.default_rng(0), noise=QUIET, losses=list(losses)),
    )


def hnf_scenario(**changes: Any) -> RsbbScenario:
    """An HNF run: goal 1 reached (result ``{}``), goal 2 timed out, a prompt answered ``s``,
    goal 3 reached; the robot's lookups 10 ms after goals 1 and 3; the script ends it."""
    robot = (0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0)
    sc = RsbbScenario(
        code="HNF",
        team="teamA",
        run=1,
        season="2019",
        t_connect_ns=at(0.5),
        t_start_ns=at(2.0),
        t_end_ns=at(55.0),
        end="end",
        t_disconnect_ns=at(60.0),
        manual_operations=(ManualOperation(at(27.0), at(29.0), "try again or skip?", "s"),),
        goals=(
            Goal(at(3.0), at(4.0), at(10.0), "[1.0, 0.0, 0.0]\n", "result", "{}"),
            Goal(at(11.0), at(12.0), at(21.0), "[2.0, 0.0, 0.0]\n", "timeout"),
            Goal(at(30.0), None, at(30.5), "[3.0, 0.0, 0.0]\n", "timeout"),
            Goal(at(31.0), at(32.0), at(40.0), "[3.0, 0.0, 0.0]\n", "result", "reached: 3"),
        ),
        broadcasts=(
            Broadcast(at(10.01), "/robot", "/robot_markerset", *robot),
            Broadcast(at(21.01), "/robot", "/robot_markerset", *robot),
            Broadcast(at(40.01), "/robot", "/robot_markerset", *robot),
        ),
        saves=(
            Save(at(10.0), {"segment_1": {"segment_time[s]": 6.0}}),
            Save(at(55.0), {"segment_1": {"segment_time[s]": 6.0}, "reached_waypoints": 2}),
        ),
        params={"starting_pose": [0.0, 0.0, 0.0], "goal_timeout": 120.0},
        referee_score=(
            {
                "group_name": "Penalized Behaviors",
                "desc": "bumps",
                "current_value": 1,
                "type": "uint",
            },
        ),
        bodies=(still_body("robot_markerset", (1.5, 0.0, 0.3)),),
    )
    return replace(sc, **changes)
