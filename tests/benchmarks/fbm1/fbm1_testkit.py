"""Small FBM1 benchmarks built by hand: state streams, noiseless mocap, and tiny bags.

Timeline of run k (seconds from the log start): WAITING_MANUAL_OPERATION at 10 + 10 k, board
placed at +3, goal at +4 (EXECUTING_GOAL +4.1, WAITING_RESULT +4.2), answer at +6, READY at
+6.1. The board stands still at the run's pose from +1 to +9.5 and jumps between runs (the
referee lifting it away); the table never moves. Mocap at 120 Hz, no noise.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

from ertools.simulator.mocap import MocapNoise, publish_mocap, simulate_mocap
from ertools.simulator.statemachine import Transition, publish_states
from ertools.simulator.writer import BagWriter
from ertools.states import BmBoxState, ClientState, Machine, RefBoxState
from ertools.streams import PoseStream, StateStream

S = 1_000_000_000
T0 = 1_448_020_000 * S  # a 2015 epoch start
RATE_NS = S // 120
WMO_S, PLACED_S, GOAL_S, EXEC_S, WAIT_S, ANSWER_S, READY_S = 0.0, 3.0, 4.0, 4.1, 4.2, 6.0, 6.1


@dataclass(frozen=True)
class RunSpec:
    """One hand-made run: what the BmBox/RefBox say, where the board is, what the robot says.

    board_xyz/board_yaw_deg: the board in the TABLE frame. answer: payload text (None: no
    answer). bmbox_payload/refbox_payload: the manual-operation payloads.
    """

    bmbox_payload: str
    answer: str | None
    board_xyz: tuple[float, float, float] = (0.3, 0.2, 0.03)
    board_yaw_deg: float = 0.0
    refbox_payload: str = ""
    timeout: bool = False


def run_start_s(k: int) -> float:
    return 10.0 + 10.0 * k


def ns(seconds: float) -> int:
    return T0 + round(seconds * S)


def transitions(runs: Sequence[RunSpec]) -> list[tuple[Machine, float, int, str]]:
    """(machine, seconds, state, payload) of a whole benchmark."""
    tr: list[tuple[Machine, float, int, str]] = [
        (Machine.BMBOX, 1.0, BmBoxState.START, ""),
        (Machine.REFBOX, 1.0, RefBoxState.START, ""),
        (Machine.CLIENT, 1.0, ClientState.START, ""),
        (Machine.BMBOX, 2.0, BmBoxState.WAITING_CLIENT, ""),
        (Machine.CLIENT, 2.5, ClientState.READY, ""),
        (Machine.REFBOX, 2.6, RefBoxState.READY, ""),
        (Machine.BMBOX, 3.0, BmBoxState.READY, ""),
        (Machine.CLIENT, 3.5, ClientState.WAITING_GOAL, ""),
    ]
    for k, run in enumerate(runs):
        b = run_start_s(k)
        tr += [
            (Machine.BMBOX, b + WMO_S, BmBoxState.WAITING_MANUAL_OPERATION, run.bmbox_payload),
            (
                Machine.REFBOX,
                b + WMO_S + 0.05,
                RefBoxState.EXECUTING_MANUAL_OPERATION,
                run.refbox_payload,
            ),
            (Machine.REFBOX, b + PLACED_S, RefBoxState.EXECUTING_GOAL, ""),
            (Machine.BMBOX, b + PLACED_S + 0.02, BmBoxState.COMPLETED_MANUAL_OPERATION, ""),
            (Machine.BMBOX, b + GOAL_S, BmBoxState.TRANSMITTING_GOAL, ""),
            (Machine.CLIENT, b + GOAL_S + 0.05, ClientState.EXECUTING_GOAL, ""),
            (Machine.BMBOX, b + EXEC_S, BmBoxState.EXECUTING_GOAL, ""),
            (Machine.BMBOX, b + WAIT_S, BmBoxState.WAITING_RESULT, ""),
        ]
        if run.timeout:
            tr.append((Machine.REFBOX, b + ANSWER_S, RefBoxState.END, "reason: timeout"))
        elif run.answer is not None:
            tr += [
                (Machine.CLIENT, b + ANSWER_S, ClientState.COMPLETED_GOAL, run.answer),
                (Machine.CLIENT, b + READY_S + 0.05, ClientState.WAITING_GOAL, ""),
            ]
        tr.append((Machine.BMBOX, b + READY_S, BmBoxState.READY, ""))
    end = run_start_s(len(runs))
    tr += [
        (Machine.BMBOX, end, BmBoxState.TRANSMITTING_SCORE, "{class_accuracy: 0.5}"),
        (Machine.BMBOX, end + 0.5, BmBoxState.END, ""),
    ]
    return tr


def state_streams(runs: Sequence[RunSpec]) -> dict[Machine, StateStream]:
    """The state topics as streams (transitions only: no heartbeats needed by the scorer)."""
    out: dict[Machine, StateStream] = {}
    tr = sorted(transitions(runs), key=lambda x: x[1])
    for m in Machine:
        mine = [x for x in tr if x[0] is m]
        out[m] = StateStream(
            m,
            np.array([ns(x[1]) for x in mine], dtype=np.int64),
            np.array([x[2] for x in mine], dtype=np.uint8),
            tuple(x[3] for x in mine),
        )
    return out


@dataclass(frozen=True)
class Table:
    """The table (origin) in the world: position and yaw (degrees)."""

    xyz: tuple[float, float, float] = (2.0, 1.0, 0.75)
    yaw_deg: float = 90.0


def bodies(
    runs: Sequence[RunSpec], table: Table = Table(), *, end_s: float | None = None
) -> tuple[PoseStream, PoseStream]:
    """Noiseless origin and ref_board streams (world frame) for the runs."""
    end = end_s if end_s is not None else run_start_s(len(runs)) + 1.0
    t = T0 + np.arange(0, round(end * S), RATE_NS, dtype=np.int64)
    n = t.size
    r_t = Rotation.from_euler("z", math.radians(table.yaw_deg))
    origin = PoseStream(
        t,
        np.tile(np.asarray(table.xyz, dtype=float), (n, 1)),
        np.tile(r_t.as_quat(), (n, 1)),
        "world",
        "origin",
        "test:origin",
    )
    # The board waits beside the table before run 0 and between runs.
    rel_xyz = np.tile([-0.5, -0.5, 0.0], (n, 1)).astype(float)
    rel_yaw = np.zeros(n)
    secs = (t - T0) / S
    for k, run in enumerate(runs):
        b = run_start_s(k)
        on = (secs >= b + 1.0) & (secs < b + 9.5)
        rel_xyz[on] = run.board_xyz
        rel_yaw[on] = math.radians(run.board_yaw_deg)
    xyz = rel_xyz @ r_t.as_matrix().T + np.asarray(table.xyz)
    quat = (r_t * Rotation.from_euler("z", rel_yaw[:, None])).as_quat()
    board = PoseStream(t, xyz, quat, "world", "ref_board", "test:ref_board")
    return origin, board


ITEMS_YAML = """items:
- {class: a, id: 1, instance: a1, rot: [0, 0, 0, 1], trans: [0.1, 0.0, 0.0]}
- {class: b, id: 2, instance: b1, rot: [0, 0, 0.7071067811865476, 0.7071067811865476],
   trans: [0.0, 0.2, 0.0]}
- {class: b, id: 3, instance: b2, rot: [0, 0, 0, 1], trans: [0.05, 0.05, 0.0]}
"""


def write_items(path: Path, text: str = ITEMS_YAML) -> Path:
    path.write_text(text, encoding="utf-8")
    return path


def write_bag(
    path: Path,
    runs: Sequence[RunSpec],
    table: Table = Table(),
    *,
    namespace: str = "fbm1h",
    drop: Sequence[tuple[str, float, float]] = (),
    omit: Sequence[str] = (),
    no_client: bool = False,
) -> Path:
    """A ROS1 bag of the runs: states with 10 Hz heartbeats, both bodies on their topics.

    drop: (body, from_s, to_s) windows with no mocap message of that body (tracking lost).
    omit: bodies not recorded at all. no_client: no /<ns>/client_state topic.
    """

    origin, board = bodies(runs, table)
    tr = [
        Transition(ns(s), m, st, p)
        for m, s, st, p in transitions(runs)
        if not (no_client and m is Machine.CLIENT)
    ]
    no_noise = MocapNoise(
        sigma_m=0.0, sigma_rad=0.0, header_jitter_ns=0, latency_jitter_ns=0, latency_spike_prob=0
    )
    rng = np.random.default_rng(0)
    with BagWriter(path, "ros1") as bag:
        for name, stream in (("origin", origin), ("ref_board", board)):
            if name in omit:
                continue
            keep = np.ones(len(stream), dtype=bool)
            for body, a, b in drop:
                if body == name:
                    keep &= ~((stream.t_ns >= ns(a)) & (stream.t_ns <= ns(b)))
            s = stream.take(keep)
            pub = simulate_mocap(s.t_ns, s.xyz, s.quat_xyzw, rng=rng, noise=no_noise)
            publish_mocap(bag, namespace, name, pub)
        publish_states(bag, namespace, tr, validate=False)
    return path
