"""FBM3@Work mocap logs written from the protocol (seed 7.3.3), not from the detector.

Independent of ertools' simulator (``ertools.benchmarks.fbm3w.sample``) and of ``--runs auto``: the
shapes are written out again from the manual (Listing 15) and ``configs/fbm3w.yaml``, the
motion from what the manual says a run is, and the detector's constants are not used.

A run, as the protocol has it: the robot places the end effector at the reference position
and stays there while the reference is taken (a still phase); it moves to the starting
position (the approach: any direction, 1-20 cm); it stays there while the sheet is oriented
(still); it follows the path, whose frame has its origin at the start and its x axis along
reference -> start (the 2015 node's run frame); it stays at the end (still) until the next
run's reference (a move there, or the end position itself) or the end of the log. The robot
draws each shape by arc length (a trapezoidal speed profile with smooth ramps) with a smooth
low-frequency wobble of a few mm, zero at both ends, and a heading error (a constant few
degrees plus a slow wobble). The mocap adds white noise to every frame at 120 Hz and drops
out (no message, or the last pose repeated) for 50-300 ms a few times.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import numpy.typing as npt
import yaml
from scipy.interpolate import CubicSpline

from ertools.simulator.writer import BagWriter

F64 = npt.NDArray[np.float64]
I64 = npt.NDArray[np.int64]
RATE_HZ = 120.0
T0_NS = 1_448_020_800_000_000_000  # 20 Nov 2015
TOPIC = "/fbm3w/robot_at_work/pose2d"

# The user shapes of configs/fbm3w.yaml (its commented example), as a config mapping.
USER_SHAPES = {
    "semi": {"x": "0.05 - 0.05*cos(pi*l)", "y": "0.048*sin(pi*l)"},
    "hook": {"points": [[0, 0], [0.05, 0.01], [0.10, 0.04]]},
}
SHAPES = ("line", "spline", "semi_ellipse", "semi", "hook")


def _hook_points(u: F64) -> F64:
    pts = np.array(USER_SHAPES["hook"]["points"], dtype=np.float64)
    chord = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(pts, axis=0).T))])
    return np.asarray(CubicSpline(chord / chord[-1], pts, bc_type="natural")(u))


def shape_curve(name: str, u: F64) -> F64:
    """The shapes by their definition (seed Listing 15; configs/fbm3w.yaml), (N, 2) metres."""
    if name == "line":
        return np.column_stack([0.15 * u, 0.045 * u])
    if name == "spline":
        return np.column_stack([0.15 * u, 0.075 * np.sin(12.5 * math.pi * 0.15 * u)])
    if name == "semi_ellipse":
        return np.column_stack([0.11 - 0.11 * np.cos(math.pi * u), 0.11 * np.sin(math.pi * u)])
    if name == "semi":
        return np.column_stack([0.05 - 0.05 * np.cos(math.pi * u), 0.048 * np.sin(math.pi * u)])
    if name == "hook":
        return _hook_points(u)
    raise KeyError(name)


def by_arc_length(name: str, frac: F64) -> tuple[F64, float]:
    """Points at fractions ``frac`` of the shape's arc length, and that length."""
    u = np.linspace(0.0, 1.0, 20001)
    dense = shape_curve(name, u)
    s = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(dense, axis=0).T))])
    return shape_curve(name, np.interp(frac * s[-1], s, u)), float(s[-1])


def speed_profile(duration: float, ramp: float, n: int) -> F64:
    """Fraction of the way travelled at n even times over ``duration``: constant speed with
    raised-cosine ramps of ``ramp`` s at both ends (a robot's trapezoid, smoothed)."""
    tau = np.linspace(0.0, duration, n)
    r = min(ramp, duration / 2)
    v = np.ones(n)
    up = tau < r
    v[up] = 0.5 - 0.5 * np.cos(math.pi * tau[up] / r)
    down = tau > duration - r
    v[down] = 0.5 - 0.5 * np.cos(math.pi * (duration - tau[down]) / r)
    s = np.concatenate([[0.0], np.cumsum(0.5 * (v[1:] + v[:-1]))])
    return s / s[-1]


@dataclass
class Truth:
    """What the generator did, times in seconds from the first pose."""

    specs: list[str] = field(default_factory=list)
    ref_phase: list[tuple[float, float]] = field(default_factory=list)
    start_phase: list[tuple[float, float]] = field(default_factory=list)
    path: list[tuple[float, float]] = field(default_factory=list)
    sigma: float = 0.0


@dataclass
class Log:
    """The logged samples, and the same samples without the mocap noise (``clean``)."""

    t_ns: I64
    xy: F64
    truth: Truth
    clean: F64


class _Timeline:
    def __init__(self, rng: np.random.Generator, xy0: F64) -> None:
        self.rng = rng
        self.count = 0  # samples so far; sample i is at i / RATE_HZ
        self.pieces: list[F64] = []
        self.pos = xy0

    def still(self, duration: float) -> tuple[float, float]:
        n = max(1, round(duration * RATE_HZ))
        self.pieces.append(np.tile(self.pos, (n, 1)))
        self.count += n
        return (self.count - n) / RATE_HZ, (self.count - 1) / RATE_HZ

    def draw(self, pts: F64) -> tuple[float, float]:
        """Samples already at 120 Hz; the first is the current position (the last sample)."""
        self.pieces.append(pts[1:])
        first = self.count - 1
        self.count += len(pts) - 1
        self.pos = pts[-1]
        return first / RATE_HZ, (self.count - 1) / RATE_HZ

    def move(self, to: F64, speed: float) -> tuple[float, float]:
        """A straight move (the approach or to the next reference)."""
        dist = float(np.hypot(*(to - self.pos)))
        duration = max(0.6, dist / speed)
        n = round(duration * RATE_HZ) + 1
        frac = speed_profile(duration, self.rng.uniform(0.15, 0.4), n)
        return self.draw(self.pos + np.outer(frac, to - self.pos))


def generate(
    rng: np.random.Generator,
    specs: list[str],
    *,
    sigma: float | None = None,
    approach: float | None = None,
    still: tuple[float, float] = (2.0, 10.0),
    path_s: float | None = None,
    dropouts: int | None = None,
    turn: float = 0.0,
    pause: float = 0.0,
) -> Log:
    """One log of ``len(specs)`` runs (random everything not given).

    ``turn`` (rad): the robot draws the shape turned by this from the protocol's frame (an
    approach that does not come along the shape's heading). ``pause`` (s): the robot stops
    this long halfway along each path (the arc length splits there).
    """
    truth = Truth(specs=list(specs))
    tl = _Timeline(rng, rng.uniform(-1.0, 1.0, 2))
    end_phase = (0.0, 0.0)
    for k, spec in enumerate(specs):
        if k > 0 and rng.random() < 0.3:
            # the end position is the next reference: the end phase is the reference phase
            truth.ref_phase.append(end_phase)
        else:
            if k > 0:
                d = rng.uniform(0.05, 0.25)
                phi = rng.uniform(-math.pi, math.pi)
                to = tl.pos + d * np.array([math.cos(phi), math.sin(phi)])
                tl.move(to, rng.uniform(0.03, 0.1))
            truth.ref_phase.append(tl.still(rng.uniform(*still)))
        ref = tl.pos.copy()
        length = approach if approach is not None else rng.uniform(0.01, 0.20)
        heading = rng.uniform(-math.pi, math.pi)
        start = ref + length * np.array([math.cos(heading), math.sin(heading)])
        tl.move(start, rng.uniform(0.02, 0.05))
        truth.start_phase.append(tl.still(rng.uniform(*still)))
        drawn = _path(rng, spec, start, heading + turn, path_s)
        if pause > 0:
            half = len(drawn) // 2
            a, _ = tl.draw(drawn[: half + 1])
            tl.still(pause)  # holding the halfway point
            _, b = tl.draw(drawn[half:])
            truth.path.append((a, b))
        else:
            truth.path.append(tl.draw(drawn))
        end_phase = tl.still(rng.uniform(*still))
    xy = np.vstack([np.atleast_2d(p) for p in tl.pieces])
    n = len(xy)
    t_ns = T0_NS + np.round(np.arange(n) * (1e9 / RATE_HZ)).astype(np.int64)
    truth.sigma = sigma if sigma is not None else rng.uniform(0.3e-3, 1.3e-3)
    clean = xy.copy()
    xy = xy + rng.normal(0.0, truth.sigma, xy.shape)
    keep = np.ones(n, dtype=bool)
    for _ in range(dropouts if dropouts is not None else int(rng.integers(1, 5))):
        a = int(rng.integers(1, n - 40))
        b = a + round(rng.uniform(0.05, 0.3) * RATE_HZ)
        if rng.random() < 0.5:
            keep[a:b] = False  # no message
        else:
            xy[a:b] = xy[a - 1]  # the mocap node repeats the last pose
            clean[a:b] = clean[a - 1]
    return Log(t_ns[keep], xy[keep], truth, clean[keep])


def _path(
    rng: np.random.Generator, spec: str, start: F64, heading: float, path_s: float | None
) -> F64:
    """The robot's path at 120 Hz, world metres, from ``start``."""
    _, length = by_arc_length(spec, np.array([0.0]))
    duration = path_s if path_s is not None else length / rng.uniform(0.007, 0.03)
    n = round(duration * RATE_HZ) + 1
    frac = speed_profile(duration, rng.uniform(0.2, 0.8), n)
    pts, _ = by_arc_length(spec, frac)
    # a smooth wobble of 1-4 mm (0.5-2 cycles over the path), zero at both ends
    env = np.sin(math.pi * frac)
    wob = np.column_stack(
        [
            rng.uniform(0.001, 0.004)
            * np.sin(2 * math.pi * rng.uniform(0.5, 2) * frac + rng.uniform(0, 2 * math.pi))
            for _ in range(2)
        ]
    )
    pts = pts + env[:, None] * wob
    # the robot's heading: a constant error of up to 3 degrees plus a 1-degree slow wobble
    yaw = heading + math.radians(rng.uniform(-3, 3))
    yaw_t = yaw + math.radians(1.0) * np.sin(2 * math.pi * rng.uniform(0.2, 1) * frac)
    c, s = np.cos(yaw_t), np.sin(yaw_t)
    return start + np.column_stack([c * pts[:, 0] - s * pts[:, 1], s * pts[:, 0] + c * pts[:, 1]])


def write_bag(log: Log, path: Path, *, clean: bool = False) -> Path:
    """The log (or its noiseless twin) as a ROS1 bag of geometry_msgs/Pose2D, 2015 topic."""

    xy = log.clean if clean else log.xy
    with BagWriter(path, "ros1") as bag:
        bag.write_pose2d(TOPIC, log.t_ns, xy[:, 0], xy[:, 1], np.zeros(len(log.t_ns)))
    return path


def write_config(specs: list[str], path: Path) -> Path:
    path.write_text(
        yaml.safe_dump({"runs_specifications": specs, "d_min": 0.00033, "shapes": USER_SHAPES})
    )
    return path
