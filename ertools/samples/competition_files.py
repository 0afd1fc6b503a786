"""The files of the sample competition (:mod:`ertools.samples.competition`): GT logger split
files, benchmark manager logs and robot logs, each written from simulated executions.

Every writer returns the (first, last) record time it wrote, so the answers know each file's
span without reading it back.
"""

from __future__ import annotations

import json
import math
from collections.abc import Sequence
from dataclasses import fields, replace
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from ertools.arrays import I64
from ertools.frozen_dataclass import frozen_dataclass
from ertools.geometry import quat_from_yaw
from ertools.simulator.mocap import MocapPublished, publish_environment, publish_mocap
from ertools.simulator.simulated import SimulatedRun
from ertools.simulator.statemachine import publish_states
from ertools.simulator.writer import BagWriter

NS = 1_000_000_000
TF_PERIOD_NS = 100_000_000  # the static world -> map at 10 Hz, as every 2015 logger had it
GT_NAMESPACE = "mocap"  # the venue's logger: its map topics are /mocap/map...
ROBOT_RATE_NS = 100_000_000  # robots logged their marker pose estimate at 10 Hz
ROBOT_NOISE_M = 0.003
STATUS_PERIOD_NS = NS


@frozen_dataclass
class GtWindow:
    """One split file of the GT logger: record times in [start_ns, end_ns)."""

    rel: str
    start_ns: int
    end_ns: int
    recording_start_ns: int  # when the logger started (its first file's start)

    @property
    def first(self) -> bool:
        """The recording's first file (its /rosout start-up lines and the map)."""
        return self.start_ns == self.recording_start_ns


def _take(pub: MocapPublished, mask: npt.NDArray[np.bool_]) -> MocapPublished:
    """The messages of ``pub`` where ``mask`` (the per-message arrays only)."""
    n = len(pub)
    changes = {
        f.name: getattr(pub, f.name)[mask]
        for f in fields(pub)
        if isinstance(getattr(pub, f.name), np.ndarray) and getattr(pub, f.name).shape[:1] == (n,)
    }
    return replace(pub, **changes)


def write_gt_file(path: Path, window: GtWindow, sims: Sequence[SimulatedRun]) -> tuple[int, int]:
    """One hour of the GT logger: /tf world -> map at 10 Hz and every body the mocap node
    tracked in that hour (``rosbag record`` split by record time)."""
    path.parent.mkdir(parents=True, exist_ok=True)
    a, b = window.start_ns, window.end_ns
    times: list[int] = []
    with BagWriter(path, "ros1", compression="bz2") as bag:
        if window.first:
            # Start-up /rosout lines and the map at the recording's start, tf from +300 ms.
            publish_environment(bag, GT_NAMESPACE, a, b - 1, bag_name=path.name)
            last_tick = a + 300_000_000 + (b - 1 - a - 300_000_000) // TF_PERIOD_NS * TF_PERIOD_NS
            times += [a, last_tick]
        else:
            # The same 10 Hz grid, continued: the logger never stopped between files.
            grid0 = window.recording_start_ns + 300_000_000
            first_tick = grid0 + -(-(a - grid0) // TF_PERIOD_NS) * TF_PERIOD_NS
            t = np.arange(first_tick, b, TF_PERIOD_NS, dtype=np.int64)
            bag.write_tf(
                t,
                t + TF_PERIOD_NS,
                "world",
                "map",
                (0.0, 0.0, 0.0),
                (0.0, 0.0, 0.0, 1.0),
                callerid=f"/{GT_NAMESPACE}/world_map_bc",
            )
            times += [int(t[0]), int(t[-1])]
        for sim in sims:
            for body, pub in sim.bodies.items():
                mask = (pub.t_record_ns >= a) & (pub.t_record_ns < b)
                if not mask.any():
                    continue
                part = _take(pub, mask)
                publish_mocap(bag, sim.namespace, body, part)
                # pose at the record time, pose2d 20 us and /tf 40 us later (publish_mocap)
                times += [int(part.t_record_ns[0]), int(part.t_record_ns[-1]) + 40_000]
    return min(times), max(times)


def write_benchmark_log(path: Path, sim: SimulatedRun, *, chunk_size: int) -> tuple[int, int]:
    """The benchmark manager's log of one execution: its /rosout start-up line and the three
    state topics (no mocap: that is the GT logger's)."""
    path.parent.mkdir(parents=True, exist_ok=True)
    ns = sim.namespace
    with BagWriter(path, "ros1", chunk_size=chunk_size) as bag:
        bag.write_log(
            sim.start_ns,
            sim.start_ns - 300_000,
            f"/{ns}/log_bmbox",
            f"Recording to {path.name}.",
            file="recorder.cpp",
            function="Recorder::startWriting",
            line=387,
        )
        msgs = publish_states(bag, ns, sim.transitions, end_ns=sim.state_end_ns)
    last = max(int(m.t_ns[-1]) for m in msgs.values() if len(m))
    return sim.start_ns, last


RobotPoses = tuple[I64, npt.NDArray[np.float64], npt.NDArray[np.float64]]


def write_robot_log(
    path: Path,
    team: str,
    start_ns: int,
    end_ns: int,
    poses: RobotPoses | None,
    header_offset_ns: int,
) -> tuple[int, int]:
    """A team's own log (rockin_logger): a 1 Hz status line and ``poses`` (true times, xyz,
    quaternions: the robot's estimate of its marker set's pose, see :func:`robot_poses`).

    Record times are the logging laptop's (synchronised), 2 ms after the true time; header
    stamps are the robot PC's, ``header_offset_ns`` ahead of the true time.
    """
    path.parent.mkdir(parents=True, exist_ok=True)
    caller = f"/rockin/{team}/logger"
    t_status = np.arange(start_ns, end_ns + 1, STATUS_PERIOD_NS, dtype=np.int64)
    if t_status[-1] != end_ns:
        t_status = np.append(t_status, end_ns)
    with BagWriter(path, "ros1") as bag:
        bag.write_string(
            f"/rockin/{team}/status",
            t_status,
            ["running"] * len(t_status),
            callerid=caller,
        )
        if poses is not None:
            t, xyz, quat = poses
            bag.write_pose_stamped(
                f"/rockin/{team}/marker_pose",
                t + 2_000_000,
                t + header_offset_ns,
                "world",
                xyz,
                quat,
                callerid=caller,
            )
    return start_ns, end_ns


def robot_poses(
    sim: SimulatedRun | None, start_ns: int, end_ns: int, rng: np.random.Generator
) -> RobotPoses | None:
    """The robot's 10 Hz estimate of its marker set's pose: (true times, xyz, quaternions).

    FBM2H: the marker set's truth at every 12th fresh mocap frame, from 1 s after the mocap
    starts to 1 s before it ends (so every pose has GT on both sides), plus a constant bias
    (N(0, 1 cm) per axis) and white noise (:data:`ROBOT_NOISE_M`); the orientation is the
    truth's. ``sim`` None: a test drive (a 1 m circle at 0.2 rad/s). Other benchmarks: None
    (the robot logged no pose).
    """
    if sim is None:
        t = np.arange(start_ns + NS, end_ns - NS, ROBOT_RATE_NS, dtype=np.int64)
        s = (t - start_ns) / NS
        w = 0.2
        xyz = np.column_stack([np.cos(w * s), np.sin(w * s), np.full(s.shape, 0.85)])
        xyz = xyz + rng.normal(0.0, ROBOT_NOISE_M, size=xyz.shape)
        return t, xyz, quat_from_yaw(w * s + math.pi / 2)
    if sim.benchmark != "fbm2h":
        return None
    (pub,) = sim.bodies.values()
    inner = (pub.t_frame_ns >= pub.t_frame_ns[0] + NS) & (pub.t_frame_ns <= pub.t_frame_ns[-1] - NS)
    fresh = np.flatnonzero(~pub.repeated & inner)
    keep = fresh[:: round(ROBOT_RATE_NS / 8_333_333)]  # every 12th mocap frame: 10 Hz
    bias = rng.normal(0.0, 0.01, size=3)
    xyz = pub.truth_xyz[keep] + bias + rng.normal(0.0, ROBOT_NOISE_M, size=(keep.size, 3))
    return pub.t_frame_ns[keep], xyz, pub.truth_quat_xyzw[keep]


def organiser_manifest(executions: Sequence[dict[str, Any]], no_team: str) -> str:
    """The manifest an organiser writes for the day (``ertools rescore --config``,
    docs/rescore.md): each benchmark's config files, each FBM2H team's marker-to-robot
    transform (a team whose file is missing is not listed: its execution stays unscoreable
    with that reason), and the one execution nothing in the logs names the team of
    (``no_team``: its benchmark log and GT files, named from the schedule).
    """
    shared: dict[str, dict[str, str]] = {}
    teams: dict[str, dict[str, str]] = {}
    for e in executions:
        for key, rel in e["inputs"].items():
            if key == "transform":
                if e["status"] == "scored":
                    teams[e["team"]] = {"transform": rel}
            else:
                shared.setdefault(e["benchmark"], {})[key] = rel
    lines = ["version: 1", "title: Sample competition (Friday 2015-11-20)", "benchmarks:"]
    for bench, values in sorted(shared.items()):
        lines += [f"  {bench}:", "    inputs:"]
        lines += [f"      {k}: {v}" for k, v in values.items()]
        if bench == "fbm2h":
            lines.append("    teams:")
            for team, tv in sorted(teams.items()):
                lines.append(f"      {team}: {{transform: {tv['transform']}}}")
    (lost,) = [e for e in executions if e["id"] == no_team]
    bags = ", ".join(json.dumps(p) for p in [lost["bmbox_log"], *lost["gt_files"]])
    lines += [
        "executions:",
        f"  - benchmark: {lost['benchmark']}",
        f"    team: {lost['team']}",
        f"    bags: [{bags}]",
    ]
    return "\n".join(lines) + "\n"
