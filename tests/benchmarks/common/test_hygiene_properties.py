"""Impossible samples on hostile streams against a plain reading of their rules, sample by sample
in Python: NaN, infinite and far rows, repeats, gaps, spikes, steps, unsorted and tiny streams.

Coordinates are multiples of 1/64 m (and far values that are whole numbers): every difference
and sum of squares is exact, so the plain arithmetic and NumPy's agree to the bit and no
threshold comparison depends on the order of additions.
"""

from __future__ import annotations

import math
import statistics
from itertools import pairwise
from unittest.mock import patch

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from ertools.benchmarks.common import hygiene
from ertools.benchmarks.common.hygiene import (
    EXCURSION_MAX_S,
    FAR_M,
    JUMP_MIN_M,
    MAX_COORD_M,
    MAX_SPEED_M_S,
    impossible_samples,
)

Row = tuple[float, float, float]


def _distance(a: Row, b: Row) -> float:
    dx, dy, dz = a[0] - b[0], a[1] - b[1], a[2] - b[2]
    return math.sqrt(dx * dx + dy * dy + dz * dz)


def plain_impossible(
    t: list[int], rows: list[Row], jumps: bool
) -> tuple[list[bool], list[bool], list[tuple[int, float, float]]]:
    """(far, jump, steps as (t_ns, metres, m/s)) by the rules of hygiene's docs, one sample at
    a time."""
    n = len(t)
    finite = [all(math.isfinite(c) for c in r) for r in rows]
    far = [finite[i] and any(abs(c) > MAX_COORD_M for c in rows[i]) for i in range(n)]
    usable = [i for i in range(n) if finite[i] and not far[i]]
    if usable:
        every = max(1, len(usable) // 10_000)
        centre = tuple(statistics.median(rows[i][k] for i in usable[::every]) for k in range(3))
        for i in usable:
            far[i] = _distance(rows[i], centre) > FAR_M  # type: ignore[arg-type]
    jump = [False] * n
    if not jumps:
        return far, jump, []
    # A measurement: finite, near, and not the previous row re-sent (whatever that row was).
    measured = [
        i
        for i in range(n)
        if finite[i]
        and not far[i]
        and not (i > 0 and all(a == b for a, b in zip(rows[i], rows[i - 1], strict=True)))
    ]
    if len(measured) < 2:
        return far, jump, []
    gaps = [t[b] - t[a] for a, b in pairwise(measured)]
    ahead = [g for g in gaps if g > 0]
    period = int(statistics.median(ahead)) if ahead else 1

    def too_fast(a: int, b: int, elapsed: int) -> tuple[bool, float, float]:
        d = _distance(rows[b], rows[a])
        v = d / (max(elapsed, period, 1) / 1e9)
        return d > JUMP_MIN_M and v > MAX_SPEED_M_S, d, v

    # Stretches of measured samples between jumps, as (first, last) sample numbers.
    stretches: list[list[int]] = [[measured[0], measured[0]]]
    for k, (a, b) in enumerate(pairwise(measured)):
        if too_fast(a, b, gaps[k])[0]:
            stretches.append([b, b])
        else:
            stretches[-1][1] = b
    length = [t[b] - t[a] for a, b in stretches]
    home = length.index(max(length))
    brief = [x <= round(EXCURSION_MAX_S * 1e9) for x in length]
    if brief[home]:
        brief = [False] * len(stretches)
    keep = [False] * len(stretches)
    keep[home] = True
    steps: list[tuple[int, float, float]] = []
    for direction in (1, -1):
        last_kept = stretches[home][1 if direction > 0 else 0]
        s = home + direction
        while 0 <= s < len(stretches):
            entry, leave = stretches[s] if direction > 0 else stretches[s][::-1]
            fast, d, v = too_fast(last_kept, entry, abs(t[entry] - t[last_kept]))
            if fast and brief[s]:
                s += direction  # a glitch: left out, the body still where it was
                continue
            if fast:
                steps.append((t[max(last_kept, entry)], d, v))
            keep[s] = True
            last_kept = leave
            s += direction
    starts = [a for a, _ in stretches]
    for i in range(n):
        # the stretch a sample belongs to: the last one starting at or before it (the first
        # one for samples before any measurement)
        own = max([k for k, a in enumerate(starts) if a <= i], default=0)
        jump[i] = not keep[own] and finite[i] and not far[i]
    return far, jump, steps[:3]


MS = 1_000_000
T0 = 1_700_000_000 * 1_000_000_000

# What happens between two samples: mostly a 120 Hz step, sometimes none (a repeated stamp),
# backwards, a gap, a long gap.
_STEPS = st.sampled_from([8 * MS] * 6 + [0, -5 * MS, 1 * MS, 300 * MS, 2_000 * MS])
# What a sample is: mostly a small move, sometimes the previous row again, NaN, infinite, far,
# beyond any frame, a spike of a metre or a step that stays; each stream has a few of these.
_EVENTS = ["repeat", "nan", "inf", "far", "huge", "spike", "step"]


@st.composite
def hostile_streams(draw: st.DrawFn) -> tuple[np.ndarray, np.ndarray]:
    n = draw(st.integers(0, 40))
    kinds = draw(st.lists(st.sampled_from(_EVENTS), max_size=3, unique=True))
    events = st.sampled_from(["move"] * 6 + kinds)
    t, rows = [], []
    now, here = T0, [1.0, 2.0, 0.5]
    for _ in range(n):
        now += draw(_STEPS)
        event = draw(events)
        move = [draw(st.integers(-3, 3)) / 64 for _ in range(3)]
        here = [h + m for h, m in zip(here, move, strict=True)]
        row: list[float] = list(here)
        if event == "repeat" and rows:
            row = list(rows[-1])
        elif event == "nan":
            row[draw(st.integers(0, 2))] = math.nan
        elif event == "inf":
            row[draw(st.integers(0, 2))] = -math.inf
        elif event == "far":
            row[0] += draw(st.sampled_from([1001.0, 1200.0, 2000.0]))
        elif event == "huge":
            row[1] = 3e8
        elif event == "spike":
            row[2] += 1.0
        elif event == "step":
            here[0] += 2.0
            row = list(here)
        t.append(now)
        rows.append(row)
    return np.array(t, dtype=np.int64), np.array(rows, dtype=np.float64).reshape(-1, 3)


def _check(t: np.ndarray, xyz: np.ndarray, jumps: bool) -> None:
    got = impossible_samples(t, xyz, jumps=jumps)
    far, jump, steps = plain_impossible(
        t.tolist(),
        [tuple(r) for r in xyz.tolist()],
        jumps,  # type: ignore[misc]
    )
    assert got.far.tolist() == far
    assert got.jump.tolist() == jump
    assert [(s.t_ns, s.distance_m, s.speed_m_s) for s in got.steps] == steps


@pytest.mark.slow
@settings(max_examples=300, deadline=None)
@given(hostile_streams(), st.booleans(), st.sampled_from([1, 2, 5, 1 << 14]))
def test_impossible_samples_match_the_plain_rules(
    stream: tuple[np.ndarray, np.ndarray], jumps: bool, rows_per_chunk: int
) -> None:
    t, xyz = stream
    # Small chunks put the rows the bounds compare on both sides of a chunk's edge.
    with patch.object(hygiene, "BOUND_ROWS", rows_per_chunk):
        _check(t, xyz, jumps)
        # A strided copy has no flat view: the bounds are not used, the answer is the same.
        _check(t, np.asfortranarray(xyz), jumps)


def test_a_spike_on_a_chunk_edge_is_found() -> None:
    """A one-frame spike of 0.2 m on the first row of the bounds' second chunk (and one just
    before it): the bounds see it, the exact test drops it."""
    n = 3 * hygiene.BOUND_ROWS
    t = T0 + np.arange(n, dtype=np.int64) * 8 * MS
    xyz = np.zeros((n, 3))
    xyz[:, 0] = np.arange(n) / 1024  # 1/1024 m per frame: 0.12 m/s
    for row in (hygiene.BOUND_ROWS, 2 * hygiene.BOUND_ROWS - 1):
        spiked = xyz.copy()
        spiked[row, 1] += 0.25
        found = impossible_samples(t, spiked)
        assert np.flatnonzero(found.jump).tolist() == [row]
        assert not found.far.any()
    assert impossible_samples(t, xyz).count == 0


def test_a_stream_wholly_beyond_any_frame_is_far() -> None:
    """Every row 2e8 m out and close together: near each other, yet all beyond any frame."""
    t = T0 + np.arange(50, dtype=np.int64) * 8 * MS
    xyz = np.full((50, 3), 2e8)
    xyz[:, 0] += np.arange(50) / 64
    assert impossible_samples(t, xyz).far.all()
    assert impossible_samples(t, -xyz, jumps=False).far.all()
