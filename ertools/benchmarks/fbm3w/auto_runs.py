"""Finding the FBM3@Work runs from motion alone (``--runs auto``), as the protocol runs them.

Still at the reference, the approach move, still at the start, the path, still at the end.
Still phases are found with a window sized to the log's own noise and hysteresis; each move
after a still phase that follows another is a candidate path, matched to the run's shape with
Eq. (1) on smoothed positions; the runs are assigned to candidates in the config's order, as
many as the log holds, least error first (see :func:`find_auto`). Like every finder of
:mod:`ertools.benchmarks.fbm3w.runs` it returns :class:`~ertools.benchmarks.fbm3w.runs.RunWindow` s.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
import numpy.typing as npt

from ertools.arrays import F64
from ertools.benchmarks.common.motion import moving_mean
from ertools.benchmarks.common.phases import DEFAULT_MIN_STILL_S, DEFAULT_STILL_SPEED, Phase
from ertools.benchmarks.fbm3w.formula import arc_fractions, frame_errors, subsample_d_min
from ertools.benchmarks.fbm3w.runs import RunWindow
from ertools.benchmarks.fbm3w.settings import Fbm3wConfig
from ertools.benchmarks.fbm3w.shapes import Shape
from ertools.benchmarks.fbm3w.track import Track, protocol_track
from ertools.errors import ConfigError, SegmentationError
from ertools.frozen_dataclass import frozen_dataclass
from ertools.streams import PoseStream

# Still time kept at each side of an auto-detected path: the edge of a move is where the
# smoothed position left the still one by 4 noise sigmas (>= 0.5 mm), which a robot
# accelerating over half a second reaches about 0.4 s after it set off.
AUTO_MARGIN_S = 0.3
# A move is a run's path when Eq. (1) after the best rotation about the start is at most this
# fraction of the target's length: a straight move 30% shorter or longer than a line fails,
# and so does any other shape; a robot's wobble of a few mm passes.
AUTO_MATCH = 0.15
# Moves joined into one candidate path (a robot pausing mid-path is still on its run), and
# the cost each pause adds so that a single move wins a tie.
AUTO_MAX_SPAN = 3
AUTO_SPAN_PENALTY = 0.01
# Positions are smoothed over +-this (s) for matching, and subsampled at this many sigmas of
# the smoothed noise (or d_min when larger), so jitter adds no length.
AUTO_SMOOTH_S = 0.1
AUTO_DETECT_SIGMAS = 6.0


@frozen_dataclass
class _Candidate:
    """Moves ``first..last`` (between still phases ``first`` and ``last + 1``) as one path."""

    first: int
    last: int
    e_free: float  # Eq. (1) mean error after the best rotation about the start (m)
    e_frame: float  # the same in the frame reference -> start (the 2015 placement)
    cost: float


def _match(path: F64, start: F64, ref: F64, shape: Shape, d_det: float) -> tuple[float, float]:
    """(e_free, e_frame): Eq. (1) of ``path`` (smoothed, world) against ``shape``.

    The protocol fixes the start at t(0) and the x axis along reference -> start; the run is
    matched both ways: with the rotation about the start that fits best (so a short or
    skewed approach move cannot hide the run) and in the protocol's frame (which tells the
    run's path from a look-alike move). ``shape`` is taken by arc length and the positions are
    subsampled at ``d_det`` (above the smoothed noise), so a robot exactly on the shape scores
    about 0 whatever its speed or the jitter.
    """
    kept = path[subsample_d_min(path, d_det)]
    if len(kept) < 2:
        return math.inf, math.inf
    one = np.array([len(kept)])
    l_norm, _ = arc_fractions(kept[:, 0], kept[:, 1], one)
    target = shape(l_norm)
    rel = kept - start
    # least-squares rotation of rel onto target (2-D Kabsch about the fixed start): the frame
    # whose x axis is at -atan2(cross, dot) in the world
    cross = float(np.sum(rel[:, 0] * target[:, 1] - rel[:, 1] * target[:, 0]))
    dot = float(np.sum(rel[:, 0] * target[:, 0] + rel[:, 1] * target[:, 1]))
    errs = []
    for yaw in (-math.atan2(cross, dot), math.atan2(*(start - ref)[::-1])):
        c, s = np.array([math.cos(yaw)]), np.array([math.sin(yaw)])
        errs.append(float(np.mean(frame_errors(kept[:, 0], kept[:, 1], one, target, c, s))))
    return errs[0], errs[1]


def find_auto(
    poses: PoseStream,
    config: Fbm3wConfig,
    *,
    still_speed: float = DEFAULT_STILL_SPEED,
    min_still_s: float = DEFAULT_MIN_STILL_S,
) -> list[RunWindow]:
    """Runs from motion alone, as the protocol (seed 7.3.3) makes them.

    A run is: still at the reference, a move to the start, still at the start, the path,
    still at the end. The still phases come from
    :func:`~ertools.benchmarks.fbm3w.track.protocol_track` (noise-sized window, hysteresis,
    dropouts bridged). Every move j >= 1 (and up to :data:`AUTO_MAX_SPAN` moves joined across
    short pauses) is a candidate path for each run's shape, matched with Eq. (1) on the
    smoothed positions (see :func:`_match`); it is acceptable when its best-rotation error is
    at most :data:`AUTO_MATCH` of the target's length. The runs are then assigned in the
    config's order to candidates in time order, at least two moves apart (the next run's
    approach lies between), taking as many runs as the log holds and, among those
    assignments, the least total error: best-rotation error plus protocol-frame error, the
    latter at most :data:`AUTO_MATCH` of the target's length.

    Window of a run: the reference time is the middle of the still phase before the
    approach; the path runs from :data:`AUTO_MARGIN_S` before the robot left the start to
    as long after it reached the end (within the still phases).

    Raises:
        SegmentationError: the first run is not found; the message lists the still phases and
            moves found (seconds from the first pose) and what is missing.
    """

    # NaN poses (the mocap's "not tracked") carry no position: left out, as a dropout
    finite = np.all(np.isfinite(poses.xyz[:, :2]), axis=1)
    t = poses.t_ns[finite]
    xy = poses.xyz[finite, :2]
    track = protocol_track(t, xy, speed=still_speed, min_duration_s=min_still_s)
    phases = track.phases
    specs = config.runs_specifications
    if len(phases) < 3:
        raise SegmentationError(
            f"{poses.source}: {_missing_phases(track, poses, still_speed, min_still_s)}; "
            "use --runs windows"
        )
    smooth_half = max(1, round(AUTO_SMOOTH_S * track.rate_hz))
    smooth = moving_mean(xy, smooth_half)
    sigma_smooth = track.sigma / math.sqrt(2 * smooth_half + 1)
    d_det = max(config.d_min, AUTO_DETECT_SIGMAS * sigma_smooth)
    n_moves = len(phases) - 1
    shapes: dict[str, Shape | None] = {}
    for spec in specs:
        try:
            shapes[spec] = config.shape(spec).by_arc_length()
        except ConfigError:
            shapes[spec] = None
    matches: dict[tuple[str, int, int], tuple[float, float]] = {}
    for spec, shape in shapes.items():
        if shape is None:
            continue
        for j in range(1, n_moves):
            for last in range(j, min(j + AUTO_MAX_SPAN, n_moves)):
                a, b = track.onsets[j], track.arrivals[last]
                path = np.vstack([track.still_xy[j], smooth[a : b + 1], track.still_xy[last + 1]])
                matches[spec, j, last] = _match(
                    path, track.still_xy[j], track.still_xy[j - 1], shape, d_det
                )
    chosen = _assign(specs, shapes, matches, n_moves)
    if not chosen:
        raise SegmentationError(
            f"{poses.source}: no move between still phases matches run 0's shape "
            f"{specs[0]!r} ({_no_match(track, poses, t, specs[0], shapes[specs[0]], matches)}); "
            "use --runs windows"
        )
    runs: list[RunWindow] = []
    margin = round(AUTO_MARGIN_S * 1e9)
    for k, cand in enumerate(chosen):
        ref_p, start_p, end_p = phases[cand.first - 1], phases[cand.first], phases[cand.last + 1]
        onset = track.onset_ns[cand.first]
        arrival = track.arrival_ns[cand.last]
        start_ns = _between(poses.t_ns, max(start_p.start_ns, onset - margin), first=True)
        end_ns = _between(poses.t_ns, min(end_p.end_ns, arrival + margin), first=False)
        ref_ns = _between(poses.t_ns, (ref_p.start_ns + ref_p.end_ns) // 2, first=False)
        shape = shapes[specs[k]]
        fit = (
            f"; matches the shape to {cand.e_free * 1000:.1f} mm (best rotation), "
            f"{cand.e_frame * 1000:.1f} mm (reference -> start frame)"
            if shape is not None
            else ""
        )
        runs.append(
            RunWindow(
                k,
                None,
                ref_ns,
                start_ns,
                end_ns,
                "completed",
                "auto",
                f"reference: middle of the still phase {_span(ref_p, poses)}; path: from "
                f"{AUTO_MARGIN_S:g} s before the robot left the start to {AUTO_MARGIN_S:g} s "
                f"after it stopped{fit}",
            )
        )
    return runs


def _assign(
    specs: Sequence[str],
    shapes: dict[str, Shape | None],
    matches: dict[tuple[str, int, int], tuple[float, float]],
    n_moves: int,
) -> list[_Candidate]:
    """Runs 0..R-1 on candidates in time order (>= 2 moves apart), R largest, then least cost.

    Dynamic programming over runs: ``best[k][m]`` = least total cost of runs 0..k with run k
    ending at move m.
    """
    inf = math.inf
    best: list[list[tuple[float, _Candidate | None, int]]] = []
    for k, spec in enumerate(specs):
        shape = shapes[spec]
        length = shape.length() if shape is not None else 1.0
        row: list[tuple[float, _Candidate | None, int]] = [(inf, None, -1)] * n_moves
        # prefix minimum of the previous run's totals over its last move
        prev_best: list[tuple[float, int]] = []
        if k:
            acc = (inf, -1)
            for m in range(n_moves):
                if best[k - 1][m][0] < acc[0]:
                    acc = (best[k - 1][m][0], m)
                prev_best.append(acc)
        for j in range(1, n_moves):
            base, back = (0.0, -1) if k == 0 else (prev_best[j - 2] if j >= 2 else (inf, -1))
            if base == inf:
                continue
            spans = range(j, min(j + AUTO_MAX_SPAN, n_moves)) if shape is not None else (j,)
            for last in spans:
                if shape is None:
                    # unknown shape: the next move; the run fails at scoring with the reason
                    cand = _Candidate(j, last, inf, inf, 1.0)
                else:
                    e_free, e_frame = matches[spec, j, last]
                    if not e_free <= AUTO_MATCH * length:
                        continue
                    # a joined span pays for each pause, so a whole single move wins a tie
                    # the protocol frame speaks for a run drawn in it (the usual case); for a
                    # robot that drew its shape turned from the approach every frame is off,
                    # so the error counts only up to the acceptance limit
                    frame = min(e_frame, AUTO_MATCH * length)
                    cost = (e_free + frame) / length + AUTO_SPAN_PENALTY * (last - j)
                    cand = _Candidate(j, last, e_free, e_frame, cost)
                total = base + cand.cost
                if total < row[last][0]:
                    row[last] = (total, cand, back)
        if all(r[0] == inf for r in row):
            break
        best.append(row)
    if not best:
        return []
    m = min(range(n_moves), key=lambda i: best[-1][i][0])
    out: list[_Candidate] = []
    for k in range(len(best) - 1, -1, -1):
        _, found, back = best[k][m]
        assert found is not None
        out.append(found)
        m = back
    return out[::-1]


def _between(t_all: npt.NDArray[np.int64], t_ns: int, *, first: bool) -> int:
    """A time halfway between two samples that keeps the same samples as ``t_ns``.

    ``first``: the window starts at t_ns (the first sample at or after it is in); else it
    ends there (the last sample at or before it is in; also the reference sample). Reports
    print times to the microsecond: a time on a sample would, given back with ``--run``,
    take or drop that sample; half a frame away it keeps them all.
    """
    n = len(t_all)
    if first:
        i = int(np.searchsorted(t_all, t_ns, side="left"))
        return t_ns if i <= 0 or i >= n else (int(t_all[i - 1]) + int(t_all[i])) // 2 + 1
    i = int(np.searchsorted(t_all, t_ns, side="right")) - 1
    return t_ns if i < 0 or i + 1 >= n else (int(t_all[i]) + int(t_all[i + 1])) // 2


def _rel(t_ns: int, poses: PoseStream) -> float:
    return (t_ns - poses.start_ns) / 1e9


def _phase_list(track: Track, poses: PoseStream, limit: int = 8) -> str:
    items = [_span(p, poses) for p in track.phases]
    if len(items) > limit:
        items = [*items[: limit - 1], "...", items[-1]]
    return ", ".join(items) if items else "none"


def _missing_phases(track: Track, poses: PoseStream, speed: float, min_s: float) -> str:
    """What a log with fewer than three still phases shows and lacks."""
    n = len(track.phases)
    text = (
        f"found {n} still phase(s) ({_phase_list(track, poses)}; still: below "
        f"{speed * 1000:g} mm/s for {min_s:g} s, noise {track.sigma * 1000:.2f} mm); a run "
        "needs three: the reference, the start (after the approach move) and the end (after "
        "the path)"
    )
    end_s = _rel(int(poses.t_ns[-1]), poses) if len(poses) else 0.0
    if n == 0:
        return text + f"; the robot never stood still in the {end_s:.2f} s of poses"
    first, last = track.phases[0], track.phases[-1]
    notes = []
    if _rel(first.start_ns, poses) > min_s:
        notes.append(f"moving from the first pose to {_rel(first.start_ns, poses):.2f} s")
    if end_s - _rel(last.end_ns, poses) > min_s:
        notes.append(
            f"moving from {_rel(last.end_ns, poses):.2f} s to the last pose at {end_s:.2f} s "
            "(no end phase: the log ends during a move)"
        )
    return text + (f"; {'; '.join(notes)}" if notes else "")


def _no_match(
    track: Track,
    poses: PoseStream,
    t: npt.NDArray[np.int64],
    spec: str,
    shape: Shape | None,
    matches: dict[tuple[str, int, int], tuple[float, float]],
) -> str:
    """The still phases, the moves and how far each is from the shape."""
    moves = []
    for j in range(len(track.phases) - 1):
        a, b = track.onsets[j], track.arrivals[j]
        size = float(np.hypot(*(track.still_xy[j + 1] - track.still_xy[j])))
        what = f"{_rel(int(t[a]), poses):.2f}-{_rel(int(t[b]), poses):.2f} s, {size * 100:.1f} cm"
        if j == 0:
            what += ", no still phase before it for the reference"
        elif shape is not None and (spec, j, j) in matches:
            err = matches[spec, j, j][0]
            what += (
                f", off the shape by {err * 1000:.1f} mm ({err / shape.length():.0%} of its length)"
            )
        moves.append(what)
    if len(moves) > 8:
        moves = [*moves[:7], "...", moves[-1]]
    limit = f"{AUTO_MATCH:.0%}" if shape is None else f"{AUTO_MATCH * shape.length() * 1000:.1f} mm"
    return (
        f"still phases {_phase_list(track, poses)}; moves {'; '.join(moves)}; a path must "
        f"follow a still phase, the approach move and a still phase, and match the shape "
        f"within {limit} (mean error after the best rotation about the start, "
        f"{AUTO_MATCH:.0%} of its length)"
    )


def _span(phase: Phase, poses: PoseStream) -> str:
    t0 = poses.start_ns
    return f"{(phase.start_ns - t0) / 1e9:.2f}-{(phase.end_ns - t0) / 1e9:.2f} s"
