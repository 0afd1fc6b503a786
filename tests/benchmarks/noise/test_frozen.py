"""``frozen_around``: runs of identical poses around query moments, by hand."""

from __future__ import annotations

import numpy as np

from ertools.benchmarks.common.frozen import FrozenSpan, frozen_around
from ertools.streams import PoseStream

FRAME = 8_333_333  # 120 Hz


def _stream(n: int, frozen: list[tuple[int, int]]) -> PoseStream:
    """Distinct poses, except samples a..b (inclusive) which repeat sample a."""
    rng = np.random.default_rng(0)
    xyz, quat = rng.normal(size=(n, 3)), rng.normal(size=(n, 4))
    for a, b in frozen:
        xyz[a : b + 1] = xyz[a]
        quat[a : b + 1] = quat[a]
    return PoseStream(np.arange(n, dtype=np.int64) * FRAME, xyz, quat)


def test_runs_longer_than_the_threshold_only() -> None:
    # 13 samples (12 frames = 99.99996 ms, not > 0.1 s) and 14 samples (108.3 ms).
    s = _stream(200, [(20, 32), (100, 113)])
    t = s.t_ns
    got = frozen_around(s, [t[26], t[106], t[99], t[113], t[114], t[150]])
    run = FrozenSpan(int(t[100]), int(t[113]), 14)
    # Inside; just before (its next sample is frozen); the last repeat; just after (the
    # sample there is a fresh measurement); elsewhere.
    assert got == [None, run, run, run, None, None]
    assert abs(run.duration_s - 13 * FRAME / 1e9) < 1e-15


def test_between_samples_and_only_position_repeated() -> None:
    s = _stream(100, [(10, 40)])
    # A moment between samples 40 and 41: sample 40 is the last repeat.
    assert frozen_around(s, [s.t_ns[40] + 1])[0] == FrozenSpan(int(s.t_ns[10]), int(s.t_ns[40]), 31)
    # The same position with another orientation is not a repeated pose (all 7 numbers): sample
    # 25 splits the run into 10..24 and 26..40.
    quat = s.quat_xyzw.copy()
    quat[25] += 1e-9
    moved = PoseStream(s.t_ns, s.xyz, quat)
    spans = frozen_around(moved, [s.t_ns[12], s.t_ns[38]])
    assert spans == [
        FrozenSpan(int(s.t_ns[10]), int(s.t_ns[24]), 15),
        FrozenSpan(int(s.t_ns[26]), int(s.t_ns[40]), 15),
    ]
