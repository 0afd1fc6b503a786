"""The toy's simulated log, with answers known by hand: 40 marker poses 0.1 m apart along x
(mean x 1.95 m), 2 poses without a position, and the BmBox states of an execution whose live
score is what the original node counted (42)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ertools.simulator.statemachine import Transition, publish_states
from ertools.simulator.writer import BagWriter
from ertools.states import BmBoxState, Machine
from tests.helpers.toybench.config import DEFAULT_TOPIC

T0 = 1_448_013_600 * 1_000_000_000  # 2015-11-20 10:00 UTC
MEASURED = 40
UNMEASURED = 2
MEAN_X = 1.95  # metres: the mean of 0.0, 0.1, ..., 3.9


def generate(outdir: Path, *, seed: int) -> Path:
    """Write ``outdir/toy.bag``; ``seed`` draws the y jitter, which the score does not read."""
    n = MEASURED + UNMEASURED
    t = T0 + np.arange(n, dtype=np.int64) * 100_000_000
    xyz = np.zeros((n, 3))
    xyz[:MEASURED, 0] = np.arange(MEASURED) / 10
    xyz[:, 1] = np.random.default_rng(seed).normal(0.0, 0.01, n)
    xyz[MEASURED:] = np.nan
    quat = np.tile([0.0, 0.0, 0.0, 1.0], (n, 1))
    live = f"count: {n}\nmean_x: {MEAN_X}\n"
    states = [
        Transition(T0, Machine.BMBOX, BmBoxState.START),
        Transition(T0 + 100_000_000, Machine.BMBOX, BmBoxState.WAITING_CLIENT),
        Transition(T0 + 200_000_000, Machine.BMBOX, BmBoxState.READY),
        Transition(T0 + 4_300_000_000, Machine.BMBOX, BmBoxState.TRANSMITTING_SCORE, live),
    ]
    outdir.mkdir(parents=True, exist_ok=True)
    bag = outdir / "toy.bag"
    with BagWriter(bag) as writer:
        writer.write_pose_stamped(DEFAULT_TOPIC, t, t, "world", xyz, quat)
        publish_states(writer, "toy", states, end_ns=int(t[-1]) + 200_000_000, validate=False)
    return bag
