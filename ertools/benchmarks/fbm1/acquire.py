"""Offline FBM1 item acquisition (seed 7.1.4): item transforms from a mocap log.

For each item of a vanilla list the referee set the item on the reference board and put the
board so that the item stood exactly at the table origin (aligned with the table axes). Then
the item frame is the origin frame and the item's transform in the board frame is
T_board_item = T_world_board^-1 * T_world_origin. The 2015 script (``acquire_items``) took one
tf lookup of it when the operator pressed ENTER; ertools averages it over the window in which
the board stood still and reports the spread. Windows are given, or found as the consecutive
stationary phases of the board near the origin, one per item in list order.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import field, replace
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from ertools.benchmarks.common import motion
from ertools.benchmarks.fbm1.gt import board_in_table, coverage_problem
from ertools.benchmarks.fbm1.logs import read_body
from ertools.benchmarks.fbm1.rules import RULE_ACQUIRE_WINDOW
from ertools.configs.items import Item, ItemList, ItemSpread, load_items
from ertools.errors import ConfigError, SegmentationError
from ertools.fidelity import Deviation
from ertools.frozen_dataclass import frozen_dataclass
from ertools.geometry import invert, mean_pose
from ertools.io.summary import summary
from ertools.streams import Interval, PoseStream, Provenance
from ertools.timeutil import NS_PER_S, resolve_time

if TYPE_CHECKING:
    from ertools.io.model import PoseSource

# The look-ahead over which a still board must not move (long against mocap noise, short
# against a referee's hand).
LOOKAHEAD_NS = NS_PER_S // 4


@frozen_dataclass
class AcquireOptions:
    """Stationary-phase detection and window trimming.

    Attributes:
        min_still_s: shorter still phases are not item placements.
        still_m: the board moving less than this over 0.25 s is still (metres).
        still_deg: likewise for the rotation (degrees).
        max_distance_m: a phase counts only with the board frame this close to the origin
            (the board lying on a side table is still too).
        trim_s: seconds dropped at both ends of a found phase (hands leaving the board).
        max_gap_s: a given window with a longer mocap gap fails (found phases may span
            short occlusions: a still board is still).
    """

    min_still_s: float = 2.0
    still_m: float = 0.002
    still_deg: float = 0.5
    max_distance_m: float = 0.5
    trim_s: float = 0.2
    max_gap_s: float = 0.5


@frozen_dataclass
class AcquireResult:
    """The acquired item list and how it was measured.

    Attributes:
        items: every item of the vanilla list; acquired ones carry trans/rot and spread.
        windows: the window used per item (same order), None where none was found.
        found_phases: every stationary phase seen (when windows were searched).
        t0_ns: the log's start (window times in the output are relative to it).
        warnings: large spreads, unused phases.
        deviations: where this differs from the 2015 script.
        failures: items that could not be acquired (one line each).
    """

    items: tuple[Item, ...]
    windows: tuple[Interval | None, ...]
    found_phases: tuple[Interval, ...] = ()
    t0_ns: int = 0
    warnings: tuple[str, ...] = ()
    deviations: tuple[Deviation, ...] = ()
    failures: tuple[str, ...] = ()
    provenance: Provenance = field(default_factory=Provenance)

    @property
    def nothing_scored(self) -> bool:
        """Not one item acquired (each failed): the CLI prints only the failures, not the
        vanilla list back (``ertools.benchmarks.document.all_failed``)."""
        return len(self.failures) >= len(self.items)


def still_phases(rel: PoseStream, options: AcquireOptions) -> list[Interval]:
    """Maximal intervals where ``rel`` (board in the table frame) stays still, vectorised.

    A sample is still when the pose 0.25 s later is within tolerance; phases are runs of
    still samples; phases shorter than ``min_still_s`` are dropped, the others trimmed.
    """

    n = len(rel)
    if n < 2:
        return []
    t = rel.t_ns
    window_s = LOOKAHEAD_NS / NS_PER_S
    still = motion.still_mask(
        t,
        rel.xyz,
        window_s=window_s,
        max_move=options.still_m,
        quat_xyzw=rel.quat_xyzw,
        max_turn=math.radians(options.still_deg),
        kind="ahead",
        inclusive=True,
    )
    still &= np.linalg.norm(rel.xyz, axis=1) <= options.max_distance_m
    # The last still sample was compared with the one 0.25 s later: still until then.
    _, ahead, _ = motion.window_ends(t, window_s, kind="ahead")
    runs = motion.still_runs(
        t, still, min_duration_ns=round(options.min_still_s * NS_PER_S), reach=ahead
    )
    trim = round(options.trim_s * NS_PER_S)
    return [Interval(int(t[a]) + trim, int(t[int(ahead[b])]) - trim) for a, b in runs]


def _measure(rel: PoseStream, item: Item, win: Interval, t0_ns: int) -> tuple[Item, list[str]]:
    part = rel.window(win.start_ns, win.end_ns)
    if len(part) == 0:
        raise SegmentationError(
            f"item {item.id} ({item.instance}): no board sample with a known origin in "
            f"t={(win.start_ns - t0_ns) / NS_PER_S:.3f}..{(win.end_ns - t0_ns) / NS_PER_S:.3f} s"
        )
    # T_board_origin = (T_origin_board)^-1 per sample, then averaged.
    t_bo, q_bo = invert(part.xyz, part.quat_xyzw)
    mean = mean_pose(t_bo, q_bo)
    spread = ItemSpread(
        position_m=mean.position_std,
        angle_deg=math.degrees(mean.angle_std),
        samples=mean.count,
        start_s=(part.start_ns - t0_ns) / NS_PER_S,
        end_s=(part.end_ns - t0_ns) / NS_PER_S,
    )
    trans = (float(mean.xyz[0]), float(mean.xyz[1]), float(mean.xyz[2]))
    # q and -q are the same rotation: write the one with w >= 0, as people expect to read.
    q = -mean.quat_xyzw if mean.quat_xyzw[3] < 0 else mean.quat_xyzw
    rot = (float(q[0]), float(q[1]), float(q[2]), float(q[3]))
    warnings = []
    if spread.position_m > 0.002 or spread.angle_deg > 0.5:
        warnings.append(
            f"item {item.id} ({item.instance}): spread {spread.position_m * 1000:.1f} mm / "
            f"{spread.angle_deg:.2f} deg over its window: was the board still?"
        )
    return replace(item, trans=trans, rot=rot, spread=spread), warnings


def acquire_items(
    origin: PoseStream,
    board: PoseStream,
    items: ItemList,
    *,
    windows: Sequence[Interval] | None = None,
    options: AcquireOptions | None = None,
    t0_ns: int = 0,
    provenance: Provenance | None = None,
) -> AcquireResult:
    """Measure every item's transform (pure: streams in, result out).

    Raises:
        SegmentationError: the number of windows (given or found) differs from the items.
    """
    opts = options or AcquireOptions()
    max_gap = round(opts.max_gap_s * NS_PER_S)
    rel = board_in_table(origin, board, max_gap)
    found: list[Interval] = []
    if windows is None:
        found = still_phases(rel, opts)
        if len(found) != len(items):
            listed = ", ".join(
                f"{(w.start_ns - t0_ns) / NS_PER_S:.1f}:{(w.end_ns - t0_ns) / NS_PER_S:.1f}"
                for w in found[:12]
            )
            raise SegmentationError(
                f"found {len(found)} still phase(s) of the board near the origin "
                f"({listed or 'none'}) for {len(items)} item(s); give --windows START:END,... "
                "(seconds from the log start) or tune --still-min/--max-distance"
            )
        use: list[Interval] = found
    else:
        if len(windows) != len(items):
            raise SegmentationError(
                f"{len(windows)} window(s) given for {len(items)} item(s): give one per item, "
                "in list order"
            )
        use = list(windows)
    out_items: list[Item] = []
    warnings: list[str] = []
    failures: list[str] = []
    for item, win in zip(items.items, use, strict=True):
        try:
            for stream, name in ((origin, "origin"), (board, "ref_board")):
                if windows is None:
                    break  # found phases are where the board was seen
                problem = coverage_problem(stream, name, win.start_ns, win.end_ns, max_gap, t0_ns)
                if problem:
                    raise SegmentationError(f"item {item.id} ({item.instance}): {problem}")
            acquired, item_warnings = _measure(rel, item, win, t0_ns)
        except SegmentationError as err:
            failures.append(err.message)
            out_items.append(item)
            continue
        out_items.append(acquired)
        warnings.extend(item_warnings)
    deviations = (
        RULE_ACQUIRE_WINDOW.deviation(
            "each transform is the mean over the item's still window, spread written beside "
            "it; the 2015 acquire_items took one tf lookup when ENTER was pressed"
        ),
    )
    return AcquireResult(
        tuple(out_items),
        tuple(use),
        tuple(found),
        t0_ns,
        tuple(warnings),
        deviations,
        tuple(failures),
        provenance or Provenance(),
    )


def acquire_items_bag(
    paths: Sequence[str | Path],
    items_path: str | Path,
    *,
    namespace: str = "fbm1h",
    windows_s: Sequence[tuple[float, float]] | None = None,
    options: AcquireOptions | None = None,
    sources: tuple[PoseSource | None, PoseSource | None] | None = None,
) -> AcquireResult:
    """Read a log and a vanilla list, then :func:`acquire_items`.

    ``windows_s``: (start, end) per item, seconds from the log's first message (or epoch
    seconds, see ``timeutil.resolve_time``).
    """

    plist = [Path(p) for p in paths]
    items = load_items(items_path, require_transforms=False)
    infos = [summary(p) for p in plist]
    t0 = min(i.start_ns for i in infos)
    t_end = max(i.end_ns for i in infos)
    windows = None
    if windows_s is not None:
        windows = [Interval(resolve_time(a, t0), resolve_time(b, t0)) for a, b in windows_s]
        bad = [k + 1 for k, w in enumerate(windows) if w.end_ns <= w.start_ns]
        if bad:
            raise ConfigError(f"--windows: window(s) {bad} end before they start")
        # Every window outside the log is a wrong time base (epoch vs log seconds), not
        # untracked items: say it once rather than once per item. One stray window stays a
        # failure of its item (the others are still acquired).
        outside = [w for w in windows if w.end_ns < t0 or w.start_ns > t_end]
        if windows and len(outside) == len(windows):
            raise ConfigError(
                f"--windows: every window lies outside the log ({plist[0]}: 0 to "
                f"{(t_end - t0) / NS_PER_S:.1f} s from its first message); give seconds from "
                "the log's first message or epoch seconds"
            )
    src_origin, src_board = sources if sources is not None else (None, None)
    origin = read_body(plist, src_origin, f"/{namespace}/origin/pose", "origin")
    board = read_body(plist, src_board, f"/{namespace}/ref_board/pose", "ref_board")
    prov = Provenance(
        inputs=(*[str(p) for p in plist], str(items_path)),
        parameters=(("origin", origin.source), ("ref_board", board.source)),
    )
    return acquire_items(
        origin, board, items, windows=windows, options=options, t0_ns=t0, provenance=prov
    )
