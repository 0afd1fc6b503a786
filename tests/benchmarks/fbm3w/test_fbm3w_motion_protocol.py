"""The still-phase detector of ``--runs auto`` (fbm3w.track.protocol_track) on tracks with
known motion."""

from __future__ import annotations

import numpy as np
import pytest

from ertools.benchmarks.common.phases import stationary_phases
from ertools.benchmarks.fbm3w.track import noise_sigma, protocol_track, window_speed

FRAME_NS = 8_333_333  # 120 Hz


def _times(n: int) -> np.ndarray:
    return np.arange(n, dtype=np.int64) * FRAME_NS


def _still_move_still(
    still_s: float = 3.0, move_s: float = 2.0, speed: float = 0.02
) -> tuple[np.ndarray, np.ndarray, float, float]:
    """Still, a constant-speed move along x (no ramp), still; (t, xy, onset_s, stop_s)."""
    n_still = round(still_s * 120)
    n_move = round(move_s * 120)
    x = np.concatenate(
        [
            np.zeros(n_still),
            speed * np.arange(1, n_move + 1) / 120,
            np.full(n_still, speed * n_move / 120),
        ]
    )
    t = _times(len(x))
    onset = (n_still - 1) * FRAME_NS / 1e9
    stop = (n_still + n_move - 1) * FRAME_NS / 1e9
    return t, np.column_stack([x, np.zeros(len(x))]), onset, stop


def test_noise_sigma_ignores_motion_and_repeated_poses() -> None:
    rng = np.random.default_rng(1)
    t, xy, _, _ = _still_move_still()
    sigma = 0.8e-3
    noisy = xy + rng.normal(0, sigma, xy.shape)
    noisy[500:536] = noisy[499]  # a tracking loss repeating one pose for 0.3 s
    # median of |second differences| of ~1000 samples: ~3% standard error
    assert noise_sigma(t, noisy) == pytest.approx(sigma, rel=0.1)
    assert noise_sigma(t, xy) == pytest.approx(0.0, abs=1e-9)


def test_window_speed_of_a_constant_speed_is_exact() -> None:
    t = _times(600)
    v = np.array([0.012, -0.005])
    xy = np.outer(t / 1e9, v)
    speed = window_speed(t, xy, 0.25, 120.0)
    inside = ~np.isnan(speed)
    # the halves' mean positions lie on the line at their mean times: exact
    assert speed[inside] == pytest.approx(float(np.hypot(*v)), rel=1e-9)
    # too few samples in a half at the ends: unknown
    assert np.isnan(speed[0]) and np.isnan(speed[-1])


def test_edges_of_a_noiseless_move() -> None:
    t, xy, onset, stop = _still_move_still()
    track = protocol_track(t, xy)
    assert len(track.phases) == 2
    # never after the robot set off (nor before it stopped): the positions are smoothed over
    # +-0.15 s, so they leave at most 0.15 s early, and the edge is moved back by at most
    # 0.1 s; a frame of slack for the sampling
    frame = FRAME_NS / 1e9
    assert onset - 0.25 <= track.onset_ns[0] / 1e9 <= onset + frame
    assert stop - frame <= track.arrival_ns[0] / 1e9 <= stop + 0.25
    assert track.still_xy[1] == pytest.approx([0.04, 0.0], abs=1e-12)


@pytest.mark.parametrize(("gap_s", "phases"), [(0.3, 2), (0.7, 2), (2.5, 3)])
def test_a_dropout_in_a_still_phase(gap_s: float, phases: int) -> None:
    """No message for gap_s inside the first still phase. Up to MAX_GAP_S (0.5 s) the window
    bridges it; longer, the phase ends there, but the two sides are joined again when the
    body is where it was (within 2 s); after a longer gap they stay two phases."""
    rng = np.random.default_rng(2)
    t, xy, _, _ = _still_move_still(still_s=6.0)
    xy = xy + rng.normal(0, 0.5e-3, xy.shape)
    lost = (t >= 1.0e9) & (t < 1.0e9 + gap_s * 1e9)
    track = protocol_track(t[~lost], xy[~lost])
    assert len(track.phases) == phases


def test_high_noise_does_not_chop_a_still_phase() -> None:
    """1.3 mm of noise per axis: the 0.2 s window of stationary_phases sees 2-6 mm/s; the
    noise-sized window (0.4 s here) sees one still phase each side of the move."""
    rng = np.random.default_rng(3)
    t, xy, onset, stop = _still_move_still(still_s=4.0, move_s=5.0, speed=0.01)
    noisy = xy + rng.normal(0, 1.3e-3, xy.shape)
    track = protocol_track(t, noisy)
    assert len(track.phases) == 2
    assert track.half_s == pytest.approx(0.4, abs=0.05)
    assert track.onset_ns[0] / 1e9 == pytest.approx(onset, abs=0.5)
    assert track.arrival_ns[0] / 1e9 == pytest.approx(stop, abs=0.5)

    assert len(stationary_phases(t, noisy)) > 2  # the old detector: chopped
