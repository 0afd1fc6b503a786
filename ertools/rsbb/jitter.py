"""A mocap body's measurement noise, estimated from its own ``/tf`` track (for the RSBB
benchmarks' intervals).

At 120 Hz a walking robot or person moves smoothly between frames, while the measurement
noise is white: the second difference ``p[k+1] - 2 p[k] + p[k-1]`` of three evenly spaced
samples is dominated by the noise, with a standard deviation of ``sqrt(6)`` sigma. A robust
spread (1.4826 times the median absolute deviation) keeps tracking glitches out. Only triples
of consecutive samples one frame apart count (a gap breaks the spacing).
"""

from __future__ import annotations

import math

import numpy as np

from ertools.frozen_dataclass import frozen_dataclass
from ertools.rsbb.tf import TfTrack, euler_yaw

#: Stated when a track has too few evenly spaced samples: OptiTrack's sub-millimetre noise on
#: a still marker set (the 2015 FBM2 log's ~0.8 mm per still step) and 5 mrad of yaw.
DEFAULT_SIGMA_M = 0.5e-3
DEFAULT_SIGMA_RAD = 5e-3
MIN_TRIPLES = 100


@frozen_dataclass
class MocapNoise:
    """Per-axis position sigma (m), yaw sigma (rad), measured or a stated default."""

    sigma_m: float
    sigma_rad: float
    measured: bool
    note: str


def _robust_sigma(second: np.ndarray) -> float:
    mad = float(np.median(np.abs(second - np.median(second))))
    return 1.4826 * mad / math.sqrt(6.0)


def mocap_noise(track: TfTrack) -> MocapNoise:
    """The noise of ``track`` from its evenly spaced triples, or the defaults."""
    t = track.t_ns
    if len(t) >= 3:
        dt = np.diff(t)
        period = float(np.median(dt))
        even = np.abs(dt - period) <= 0.25 * period
        triple = np.flatnonzero(even[:-1] & even[1:]) + 1
    else:
        triple = np.empty(0, np.intp)
    if triple.size < MIN_TRIPLES:
        return MocapNoise(
            DEFAULT_SIGMA_M,
            DEFAULT_SIGMA_RAD,
            False,
            f"{triple.size} evenly spaced sample triples (fewer than {MIN_TRIPLES}): defaults",
        )
    xy = track.xyz[:, :2]
    second = xy[triple + 1] - 2.0 * xy[triple] + xy[triple - 1]
    yaw = np.unwrap(euler_yaw(track.quat_xyzw))
    second_yaw = yaw[triple + 1] - 2.0 * yaw[triple] + yaw[triple - 1]
    return MocapNoise(
        _robust_sigma(second.ravel()),
        _robust_sigma(second_yaw),
        True,
        f"{triple.size} evenly spaced sample triples of {track.child}",
    )
