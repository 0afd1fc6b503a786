"""FBM3@Work on arrays: d_min subsampling, the run frame and Eq. (1). No IO here.

As the 2015 node did (rockin_scoring/scripts/fbm3w, seed 7.3.1-7.3.3):

1. subsample the measured positions: keep the first one, then each one at least ``d_min`` from
   the last kept one (2015 compared ``sqrt(dx**2 + dy**2) >= D_MIN`` on Pose2D x, y);
2. the run frame: origin at the starting position (the first kept point), x axis along
   reference -> start (``atan2(start - reference)``);
3. ``l`` = cumulative length of the kept polyline (measured in the world, where it equals the
   run frame's), ``L`` its total; each kept point i >= 1 is compared with the target at
   ``l_i / L``; the start point counts with error 0;
4. distance_error = sum of the errors / N, N the number of kept points.

The d_min rule is :func:`subsample_d_min`, for :func:`score_path` (one run), :func:`kept_flags`
(paths side by side, column by column) and ``--runs auto`` (a candidate move in two frames,
with :func:`arc_fractions` and :func:`frame_errors`). The intervals' float32 pass over all
draws at once (``perturbed._subsample``) is its own copy of the rule.
"""

from __future__ import annotations

import math

import numpy as np

from ertools.arrays import F64, Bool, IntArr
from ertools.benchmarks.fbm3w.shapes import Shape
from ertools.errors import ErtoolsError, ScoringError
from ertools.frozen_dataclass import frozen_dataclass

# Samples probed one by one after each kept point before switching to a vectorised search:
# while the end effector moves, the next kept sample is usually within a few samples (cheap
# scalar test); while it stands still with noise below d_min the gap is long (vector search).
_SCALAR_PROBE = 8
_FIRST_WINDOW = 64
# Samples of the noiseless robot used for shape_floor.
FLOOR_SAMPLES = 10_001


def subsample_d_min(xy: F64, d_min: float) -> IntArr:
    """Indices of the samples kept by the 2015 d_min rule (always including index 0).

    The rule is sequential (each test is against the last *kept* point), so it cannot be one
    NumPy expression. After each kept point we test a few following samples as Python floats
    (the common case while moving) and, if none qualifies, search ahead in NumPy windows that
    double in size (the common case while standing still). Each sample is then examined O(1)
    times, in either form.

    Args:
        xy: (N, 2) positions in metres.
        d_min: threshold in metres (>= 0).

    Returns:
        (K,) increasing indices into ``xy``; empty when ``xy`` is empty.
    """
    pts = np.asarray(xy, dtype=np.float64)
    n = len(pts)
    if n == 0:
        return np.empty(0, dtype=np.intp)
    xs: list[float] = pts[:, 0].tolist()
    ys: list[float] = pts[:, 1].tolist()
    kept = [0]
    last = 0
    sqrt = math.sqrt
    while True:
        lx, ly = xs[last], ys[last]
        nxt = -1
        stop = min(n, last + 1 + _SCALAR_PROBE)
        for j in range(last + 1, stop):
            dx = xs[j] - lx
            dy = ys[j] - ly
            if sqrt(dx * dx + dy * dy) >= d_min:
                nxt = j
                break
        if nxt < 0:
            lo = stop
            width = _FIRST_WINDOW
            while lo < n:
                hi = min(n, lo + width)
                seg = pts[lo:hi]
                dist = np.sqrt((seg[:, 0] - lx) ** 2 + (seg[:, 1] - ly) ** 2)
                hit = np.flatnonzero(dist >= d_min)
                if hit.size:
                    nxt = lo + int(hit[0])
                    break
                lo = hi
                width *= 2
        if nxt < 0:
            break
        kept.append(nxt)
        last = nxt
    return np.asarray(kept, dtype=np.intp)


def kept_flags(x: F64, y: F64, d_mins: F64) -> Bool:
    """(N, W) flags of the d_min rule for W paths side by side in the columns of ``x``, ``y``
    (N, W), column w with ``d_mins[w]``; NaN (padding) is never kept.

    :func:`subsample_d_min` column by column (the rule is written once): a NaN sample is never
    at least ``d_min`` from the last kept point, so padding is skipped as the rule stands.
    """
    n, w = x.shape
    flags = np.zeros((n, w), dtype=bool)
    for k in range(w):
        flags[subsample_d_min(np.column_stack([x[:, k], y[:, k]]), float(d_mins[k])), k] = True
    return flags


def arc_fractions(xk: F64, yk: F64, counts: IntArr) -> tuple[F64, F64]:
    """``l / L`` of every kept point and each path's ``L``, for D kept paths laid end to end
    in ``xk``, ``yk`` (M,), path i being ``counts[i]`` >= 1 points.

    ``l`` sums the steps in order within a path, as the 2015 loop; a path of zero length has
    ``l / L`` = 0.
    """
    m = xk.size
    starts = np.cumsum(counts) - counts
    run = np.empty(m)
    run[:1] = 0.0
    np.hypot(np.diff(xk), np.diff(yk), out=run[1:])
    run[starts] = 0.0
    np.cumsum(run, out=run)
    cum = np.subtract(run, np.repeat(run[starts], counts), out=run)
    total = cum[starts + counts - 1]
    with np.errstate(invalid="ignore", divide="ignore"):
        l_norm = np.divide(cum, np.repeat(total, counts), out=cum)
    np.clip(np.nan_to_num(l_norm, copy=False), 0.0, 1.0, out=l_norm)
    return l_norm, total


def frame_errors(xk: F64, yk: F64, counts: IntArr, target: F64, cos_yaw: F64, sin_yaw: F64) -> F64:
    """(M,) Eq. (1)'s distance of each kept point (laid out as for :func:`arc_fractions`)
    from its ``target`` (M, 2), in its path's run frame: origin at the path's first point, x
    axis at ``yaw`` (D,) in the world. Each first point counts 0 (2015 summed from the second).
    """
    starts = np.cumsum(counts) - counts
    dx = xk - np.repeat(xk[starts], counts)
    dy = yk - np.repeat(yk[starts], counts)
    c, s = np.repeat(cos_yaw, counts), np.repeat(sin_yaw, counts)
    # the run frame: (c dx + s dy, -s dx + c dy), each minus the target
    a: F64 = np.multiply(c, dx)
    a += np.multiply(s, dy)
    a -= target[:, 0]
    b = np.multiply(c, dy)
    b -= np.multiply(s, dx, out=c)
    b -= target[:, 1]
    np.hypot(a, b, out=a)
    a[starts] = 0.0
    return a


@frozen_dataclass
class RunFrame:
    """The 2015 run frame in world coordinates: origin at the start, x along ref -> start."""

    origin: tuple[float, float]
    yaw: float

    def to_frame(self, xy: F64) -> F64:
        """World (N, 2) -> run frame (N, 2)."""
        c, s = math.cos(self.yaw), math.sin(self.yaw)
        d = np.asarray(xy, dtype=np.float64) - np.asarray(self.origin)
        return np.column_stack([c * d[:, 0] + s * d[:, 1], -s * d[:, 0] + c * d[:, 1]])

    def to_world(self, xy: F64) -> F64:
        """Run frame (N, 2) -> world (N, 2)."""
        c, s = math.cos(self.yaw), math.sin(self.yaw)
        p = np.asarray(xy, dtype=np.float64)
        return np.column_stack(
            [self.origin[0] + c * p[:, 0] - s * p[:, 1], self.origin[1] + s * p[:, 0] + c * p[:, 1]]
        )


def run_frame(reference_xy: F64, start_xy: F64, *, as_2015: bool = False) -> RunFrame:
    """The run frame from the reference and starting positions.

    Raises:
        ScoringError: the two positions coincide, so the x axis is undefined (2015 silently
            used the world's x axis, ``as_2015``).
    """
    ref = np.asarray(reference_xy, dtype=np.float64)
    start = np.asarray(start_xy, dtype=np.float64)
    dx, dy = float(start[0] - ref[0]), float(start[1] - ref[1])
    if dx == 0.0 and dy == 0.0 and not as_2015:
        raise ScoringError(
            "the reference and starting positions coincide, so the run frame's x axis is "
            "undefined; check the reference time"
        )
    return RunFrame((float(start[0]), float(start[1])), math.atan2(dy, dx))


@frozen_dataclass(eq=False)
class PathScore:
    """Eq. (1) for one run.

    Attributes:
        distance_error: mean error over the N kept points (start included, error 0), metres.
        kept: (N,) indices of the kept samples into the input.
        frame: the run frame.
        kept_frame: (N, 2) kept points in the run frame.
        l_norm: (N,) normalised path length l/L of each kept point.
        target: (N, 2) target positions at l/L.
        errors: (N,) per-point distances (0 for the start).
        path_length: L, metres (kept polyline).
        raw_length: length of the polyline through every sample (inflated by jitter).
    """

    distance_error: float
    kept: IntArr
    frame: RunFrame
    kept_frame: F64
    l_norm: F64
    target: F64
    errors: F64
    path_length: float
    raw_length: float


def score_path(
    xy: F64, reference_xy: F64, shape: Shape, d_min: float, *, as_2015: bool = False
) -> PathScore:
    """Score the measured positions ``xy`` (N, 2, world) of one run against ``shape``.

    ``as_2015``: what the 2015 node computed where ertools refuses to score: a path of one
    kept point is ``error_sum / N`` = 0.0 (scripts/fbm3w 50b173b, lines 273-295, run no loop),
    and a start on the reference gives the world's x axis (``atan2(0, 0)``).

    Raises:
        ScoringError: fewer than 2 samples or kept points (one with ``as_2015``), a path of
            zero length, coincident reference and start, non-finite positions.
    """
    pts = np.asarray(xy, dtype=np.float64)
    if len(pts) < (1 if as_2015 else 2):
        raise ScoringError(f"the run has {len(pts)} pose sample(s); at least 2 are needed")
    if not np.all(np.isfinite(pts)):
        raise ScoringError("the run has non-finite positions (NaN or inf)")
    kept = subsample_d_min(pts, d_min)
    path = pts[kept]
    if len(path) < 2 and not as_2015:
        raise ScoringError(
            f"the path has zero length: no sample moved d_min = {d_min * 1000:.3g} mm from the "
            "starting position"
        )
    one = np.array([len(path)])
    l_norm, totals = arc_fractions(path[:, 0], path[:, 1], one)
    total = float(totals[0])
    if total <= 0.0 and not (as_2015 and len(path) == 1):
        raise ScoringError("the path has zero length")
    frame = run_frame(reference_xy, path[0], as_2015=as_2015)
    target = shape(l_norm)
    cos_yaw, sin_yaw = np.array([math.cos(frame.yaw)]), np.array([math.sin(frame.yaw)])
    errors = frame_errors(path[:, 0], path[:, 1], one, target, cos_yaw, sin_yaw)
    in_frame = frame.to_frame(path)
    raw_length = float(np.sum(np.hypot(*np.diff(pts, axis=0).T)))
    return PathScore(
        float(np.sum(errors) / len(path)),
        kept,
        frame,
        in_frame,
        l_norm,
        target,
        errors,
        total,
        raw_length,
    )


def shape_floor(shape: Shape, d_min: float) -> float:
    """distance_error of a noiseless robot exactly on ``shape`` (1e4 samples), metres.

    0 up to the d_min quantisation for shapes parametrised by arc length; 8.4 mm for the 2015
    ``sine``, whose parameter is proportional to x, not to the length travelled.
    """
    pts = shape(np.linspace(0.0, 1.0, FLOOR_SAMPLES))
    reference = np.array([-0.05, 0.0])  # run frame = world frame
    try:
        return score_path(pts, reference, shape, d_min).distance_error
    except ErtoolsError:
        return math.nan


def try_score(xy: F64, ref_xy: F64, shape: Shape, d_min: float) -> float | None:
    """``distance_error`` of the run at ``d_min``, or None where it cannot be scored."""
    try:
        return score_path(xy, ref_xy, shape, d_min).distance_error
    except ErtoolsError:
        return None
