"""Scenario ``timeline``: a folder of small bags from several machines, as a referee gets it.

Layout (times in seconds after :data:`T0`, the record times of each bag's first/last message)::

    gtlogger/log_fbm2h_mocap_<date>_0.bag          GT logger,  0.0 -  8.0
    gtlogger/log_fbm2h_mocap_<date>_1.bag          GT logger,  8.0 - 16.0 (contiguous split)
    gtlogger/log_fbm2h_mocap_<date>_2.bag          GT logger, 22.0 - 30.0 (6 s gap before it)
    gtlogger/log_fbm2h_mocap_<date>_3.bag.active   GT logger, 30.0 - 34.0, unindexed (recording)
    bmmanager/log_fbm2h_<date>_0.bag               benchmark log (state topics + mocap), 3 - 12
    robots/homer/FBM2H_<date>_homer.bag            robot log (/rockin/homer/...), 13 - 26
    usb_stick/FBM2H_<date>_homer.bag               the same robot log copied: one recording, a copy
    gtlogger_work/log_fbm3w_mocap_<date>_0.bag     GT logger whose mocap node's clock was 3.2 s
                                                   behind the recorder's, 40 - 46
    old/log_fbm2h_mocap_<date>_0.bag               a GT bag truncated at 55 % of its bytes

Every bag holds only topics whose record times the scenario sets, so each bag's span is known
exactly. Answers (``expected``), computed here without ``ertools.timelines.build``:

- ``bags``: per file (path relative to the folder): start, end (epoch s), kind;
- ``overlaps``: per readable file, the files whose closed spans intersect its own (a plain
  double loop);
- ``sessions``: groups of readable files chained by overlaps or by pauses of at most
  ``gap_tolerance_s`` (a union-find over pairs);
- ``pairings``: per benchmark/robot log, the GT files overlapping it, the covered percentage
  (measured on a 1 ms grid, not by interval arithmetic; pauses of at most
  ``coverage_join_s`` between GT files count as covered) and the uncovered spans;
- ``problems``: per file, a keyword its problem line must contain (``gap``, ``index``,
  ``duplicated``, ``clock``) or ``any`` for the truncated file.
"""

from __future__ import annotations

import shutil
import struct
from pathlib import Path

import numpy as np

from ertools.arrays import I64
from ertools.geometry import quat_from_yaw
from ertools.simulator.answers import EPOCH_2015, log_name, tol, write_answers
from ertools.simulator.mocap import FRAME_NS
from ertools.simulator.writer import BagWriter
from ertools.states import BmBoxState, ClientState, Machine, RefBoxState

NS = 1_000_000_000
T0 = EPOCH_2015 + 5 * 3600 * NS  # 15:00 UTC
FBM2H = "fbm2h"  # the namespace of the FBM2@Home logs this folder holds: data
GT_TOPIC = "/fbm2h/robot_at_home/pose"
WORK_TOPIC = "/fbm3w/robot_at_work/pose"
ROBOT_TOPIC = "/rockin/homer/marker_pose"
UNSYNC_S = 3.2
GAP_TOLERANCE_S = 1.0
COVERAGE_JOIN_S = 0.1
TRUNCATE_AT = 0.55


def _grid(start_s: float, end_s: float, period_ns: int) -> I64:
    """Record times from start to end (inclusive) on a fixed period."""
    a = T0 + round(start_s * NS)
    b = T0 + round(end_s * NS)
    n = (b - a) // period_ns
    t = a + np.arange(n + 1, dtype=np.int64) * period_ns
    if t[-1] != b:
        t = np.append(t, b)
    return t


def _poses(bag: BagWriter, topic: str, t_rec: I64, header_shift_ns: int = -300_000) -> None:
    """A marker set circling slowly; header stamps ``header_shift_ns`` from the record time."""
    s = (t_rec - T0) / NS
    xyz = np.column_stack([np.cos(0.3 * s), np.sin(0.3 * s), np.full(s.shape, 0.45)])
    bag.write_pose_stamped(
        topic,
        t_rec,
        t_rec + header_shift_ns,
        "world",
        xyz,
        quat_from_yaw(0.3 * s + np.pi / 2),
        callerid="/mocap_node",
    )


def _gt_bag(
    path: Path, start_s: float, end_s: float, *, topic: str = GT_TOPIC, shift: int = -300_000
) -> I64:
    t = _grid(start_s, end_s, FRAME_NS)
    path.parent.mkdir(parents=True, exist_ok=True)
    with BagWriter(path, "ros1", compression="bz2") as bag:
        _poses(bag, topic, t, shift)
    return t


def make_active(path: Path) -> Path:
    """Turn a closed ROS1 bag into what ``rosbag record`` leaves while still recording.

    rosbag writes the bag header with index_pos 0 and no connection/chunk counts first, and
    fills them in (and appends the index) only on close: drop the index and zero the fields.
    """
    data = bytearray(path.read_bytes())
    pos = len(b"#ROSBAG V2.0\n")
    header_len = struct.unpack_from("<i", data, pos)[0]
    fields_at = pos + 4
    index_pos = None
    i = fields_at
    while i < fields_at + header_len:
        flen = struct.unpack_from("<i", data, i)[0]
        name, _, _ = bytes(data[i + 4 : i + 4 + flen]).partition(b"=")
        value_at = i + 4 + len(name) + 1
        if name == b"index_pos":
            index_pos = struct.unpack_from("<Q", data, value_at)[0]
            struct.pack_into("<Q", data, value_at, 0)
        elif name in (b"conn_count", b"chunk_count"):
            struct.pack_into("<i", data, value_at, 0)
        i += 4 + flen
    if index_pos is None:
        raise ValueError(f"{path}: no index_pos in the bag header")
    active = path.with_name(path.name + ".active")
    active.write_bytes(bytes(data[:index_pos]))
    path.unlink()
    return active


def _benchmark_bag(path: Path, start_s: float, end_s: float) -> I64:
    path.parent.mkdir(parents=True, exist_ok=True)
    t_states = _grid(start_s, end_s, NS // 10)
    t_pose = _grid(start_s + 0.05, end_s - 0.05, FRAME_NS)
    with BagWriter(path, "ros1", compression="bz2") as bag:
        n = t_states.size
        half = n // 2
        bag.write_state(
            Machine.BMBOX,
            "/fbm2h/bmbox_state",
            t_states,
            [int(BmBoxState.READY)] * half + [int(BmBoxState.EXECUTING_GOAL)] * (n - half),
            "",
            callerid="/fbm2h/bmbox",
        )
        bag.write_state(
            Machine.REFBOX,
            "/fbm2h/refbox_state",
            t_states + 1_000_000,
            [int(RefBoxState.READY)] * half + [int(RefBoxState.EXECUTING_GOAL)] * (n - half),
            "",
            callerid="/fbm2h/refbox",
        )
        bag.write_state(
            Machine.CLIENT,
            "/fbm2h/client_state",
            t_states + 2_000_000,
            [int(ClientState.WAITING_GOAL)] * half + [int(ClientState.EXECUTING_GOAL)] * (n - half),
            "",
            callerid="/fbm2h/client",
        )
        _poses(bag, GT_TOPIC, t_pose)
    return np.concatenate([t_states, t_states + 2_000_000, t_pose])


def _robot_bag(path: Path, start_s: float, end_s: float) -> I64:
    path.parent.mkdir(parents=True, exist_ok=True)
    t = _grid(start_s, end_s, NS // 10)
    with BagWriter(path, "ros1") as bag:
        _poses(bag, ROBOT_TOPIC, t, -2_000_000)
    return t


# --- independent answers -------------------------------------------------------------------


def _overlaps(spans: dict[str, tuple[int, int]]) -> dict[str, list[str]]:
    names = sorted(spans)
    return {
        a: [
            b for b in names if b != a and spans[a][0] <= spans[b][1] and spans[b][0] <= spans[a][1]
        ]
        for a in names
    }


def _sessions(spans: dict[str, tuple[int, int]], gap_ns: int) -> list[list[str]]:
    """Union-find: two files join when their spans overlap or lie within gap_ns of each other."""
    names = sorted(spans)
    parent = {n: n for n in names}

    def find(n: str) -> str:
        while parent[n] != n:
            n = parent[n]
        return n

    for a in names:
        for b in names:
            (s1, e1), (s2, e2) = spans[a], spans[b]
            if s1 <= e2 + gap_ns and s2 <= e1 + gap_ns:
                parent[find(a)] = find(b)
    groups: dict[str, list[str]] = {}
    for n in names:
        groups.setdefault(find(n), []).append(n)
    return sorted(groups.values(), key=lambda g: min(spans[n][0] for n in g))


def _coverage(
    span: tuple[int, int], covers: list[tuple[int, int]]
) -> tuple[float, list[list[float]]]:
    """Covered percent on a 1 ms grid, and the uncovered spans (epoch s) found on it.

    A pause of at most :data:`COVERAGE_JOIN_S` between two GT files is covered (consecutive
    split files leave one frame period between them).
    """
    grid = np.arange(span[0], span[1] + 1, 1_000_000, dtype=np.int64)
    covered = np.zeros(grid.size, dtype=bool)
    for a, b in covers:
        covered |= (grid >= a) & (grid <= b)
    join = round(COVERAGE_JOIN_S * NS)
    for _a1, b1 in covers:
        for a2, _b2 in covers:
            if 0 < a2 - b1 <= join:
                covered |= (grid >= b1) & (grid <= a2)
    pct = 100.0 * float(covered.mean())
    edges = np.flatnonzero(np.diff(covered.astype(np.int8)))
    holes: list[list[float]] = []
    start = None if covered[0] else grid[0]
    for i in edges:
        if covered[i] and not covered[i + 1]:
            start = grid[i]
        elif start is not None:
            holes.append([int(start) / NS, int(grid[i + 1]) / NS])
            start = None
    if start is not None:
        holes.append([int(start) / NS, int(grid[-1]) / NS])
    return pct, holes


def generate(outdir: Path, *, seed: int) -> list[Path]:
    """Write the folder ``outdir/bags/`` and ``outdir/timeline.answers.yaml``."""
    del seed  # every value is fixed: the scenario tests the timeline, not statistics
    root = outdir / "bags"
    gt_start = T0 - 400_000_000

    def name(kind: str, i: int) -> str:
        return log_name(kind, gt_start, index=i)

    times: dict[str, I64] = {}
    kinds: dict[str, str] = {}
    gt = [f"gtlogger/{name('fbm2h_mocap', i)}" for i in range(4)]
    for rel, (a, b) in zip(
        gt, ((0, 8), (8 + 1 / 120, 16), (22, 30), (30 + 1 / 120, 34)), strict=True
    ):
        times[rel] = _gt_bag(root / rel, a, b)
        kinds[rel] = "gt"
    active_path = make_active(root / gt[3])
    active = str(active_path.relative_to(root))
    times[active] = times.pop(gt[3])
    kinds[active] = kinds.pop(gt[3])

    bench = f"bmmanager/{log_name(FBM2H, T0 + 2 * NS)}"
    times[bench] = _benchmark_bag(root / bench, 3, 12)
    kinds[bench] = "benchmark"
    robot = "robots/homer/FBM2H_201511201500_homer.bag"
    times[robot] = _robot_bag(root / robot, 13, 26)
    kinds[robot] = "robot"
    dup = "usb_stick/FBM2H_201511201500_homer.bag"
    (root / dup).parent.mkdir(parents=True)
    shutil.copyfile(root / robot, root / dup)
    times[dup] = times[robot]
    kinds[dup] = "robot"
    unsync = f"gtlogger_work/{log_name('fbm3w_mocap', T0 + 39 * NS)}"
    times[unsync] = _gt_bag(root / unsync, 40, 46, topic=WORK_TOPIC, shift=-round(UNSYNC_S * NS))
    kinds[unsync] = "gt"
    trunc = f"old/{log_name('fbm2h_mocap', T0 + 59 * NS)}"
    _gt_bag(root / trunc, 60, 65)
    raw = (root / trunc).read_bytes()
    (root / trunc).write_bytes(raw[: int(len(raw) * TRUNCATE_AT)])

    spans = {k: (int(v.min()), int(v.max())) for k, v in times.items()}
    # The byte copy is the robot log's recording again: it leaves overlaps, sessions, pairings.
    originals = {k: v for k, v in spans.items() if k != dup}
    gt_files = [k for k, v in kinds.items() if v == "gt"]
    pairings = {}
    for k, kind in sorted(kinds.items()):
        if kind not in ("benchmark", "robot") or k == dup:
            continue
        over = sorted(
            g for g in gt_files if spans[g][0] <= spans[k][1] and spans[k][0] <= spans[g][1]
        )
        pct, holes = _coverage(spans[k], [spans[g] for g in over])
        # Every log here and its GT files name fbm2h (topics /fbm2h/..., FBM2H_... robot log).
        pairings[k] = {"gt": over, "coverage": pct, "uncovered": holes, "basis": "content"}
    answers = write_answers(
        outdir / "timeline.bag",  # names the answers file timeline.answers.yaml
        benchmark="timeline",
        scenario="timeline",
        seed=0,
        parameters={
            "folder": "bags",
            "gap_tolerance_s": GAP_TOLERANCE_S,
            "coverage_join_s": COVERAGE_JOIN_S,
            "clock_tolerance_s": 0.5,
            "unsync_s": UNSYNC_S,
            "truncate_at": TRUNCATE_AT,
        },
        truth={
            "bags": {
                k: {"start": spans[k][0] / NS, "end": spans[k][1] / NS, "kind": kinds[k]}
                for k in sorted(spans)
            },
            "truncated": trunc,
        },
        expected={
            "readable": len(spans),
            "overlaps": _overlaps(originals),
            "sessions": _sessions(originals, round(GAP_TOLERANCE_S * NS)),
            "copies": {dup: robot},
            "pairings": pairings,
            "problems": {
                gt[2]: "gap",
                active: "index",
                dup: "same recording",
                unsync: "clock",
                trunc: "any",
            },
            "split_gap_s": (spans[gt[2]][0] - spans[gt[1]][1]) / NS,
            "clock_offset_s": UNSYNC_S,
        },
        tolerance={
            "times": tol(1e-6, "epoch seconds as float: microseconds survive"),
            "coverage": tol(0.02, "the answer is measured on a 1 ms grid"),
            "clock_offset_s": tol(1e-3, "header shift is exact; the median is of exact values"),
        },
    )
    return [root, answers]
