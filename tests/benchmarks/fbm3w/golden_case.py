"""The deterministic benchmark behind the Listing 16 golden file (no bag, no randomness)."""

from __future__ import annotations

import numpy as np

from ertools.benchmarks.fbm3w.config import Fbm3wOptions
from ertools.benchmarks.fbm3w.pipeline import score_paths
from ertools.benchmarks.fbm3w.result import Fbm3wResult
from ertools.benchmarks.fbm3w.runs import RunWindow
from ertools.benchmarks.fbm3w.settings import Fbm3wConfig
from ertools.benchmarks.fbm3w.shapes import builtin_shapes
from ertools.streams import concatenate_poses
from tests.benchmarks.fbm3w.fbm3w_synth import T0, one_run

S = 1_000_000_000


def golden_result() -> Fbm3wResult:
    """A line 2 mm off, a semi-ellipse 1 mm off, and a line ended by a timeout."""
    shapes = builtin_shapes()
    u = np.linspace(0.0, 1.0, 600)
    bump = np.sin(np.pi * u)[:, None] * np.array([[0.0, 1.0]])
    runs = [("line", 0.002, (1.0, 2.0), 0.3), ("semi_ellipse", 0.001, (1.5, 2.5), -0.2)]
    streams, windows = [], []
    for i, (name, amp, origin, yaw) in enumerate(runs):
        stream, window = one_run(
            shapes[name](u) + amp * bump,
            origin=origin,
            yaw=yaw,
            spec=name,
            t0=T0 + i * 20 * S,
            index=i,
        )
        streams.append(stream)
        windows.append(window)
    end = windows[-1].end_ns
    assert end is not None
    windows.append(RunWindow(2, "line", None, end + 1 * S, end + 4 * S, "timeout", "states"))
    # Listing 16's layout alone: no intervals (--draws 0); the interval keys are checked by
    # the CLI tests and the e2e golden outputs
    return score_paths(
        concatenate_poses(streams),
        windows,
        Fbm3wConfig(),
        options=Fbm3wOptions(draws=0),
        bag_start_ns=T0 - S // 2,
    )
