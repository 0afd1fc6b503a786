"""FBM2@Home on bad ground truth: frozen poses at a reached moment, frame names changing, GT
lost at a reached moment (with and without ``--unscored-segments 2015``).
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from ertools.benchmarks.fbm2h.goal import GoalList
from ertools.benchmarks.fbm2h.pipeline import compute
from ertools.benchmarks.fbm2h.runs import from_states, unreached_reasons
from ertools.cli.main import main
from ertools.configs.transform import MarkerTransform
from ertools.io.reader import read_poses
from ertools.simulator.writer import BagWriter
from ertools.states import BmBoxState as B
from ertools.states import ClientState as C
from ertools.states import Machine
from ertools.states import RefBoxState as R
from ertools.streams import PoseStream, StateStream

S = 1_000_000_000
T0 = 1_448_020_800 * S
TOL = 1e-12

Events = list[tuple[int, int, str]]


# --- simulated edge cases --------------------------------------------------------------------

_Q = Rotation.from_euler("xyz", [0.02, -0.01, -0.3]).as_quat().tolist()
TRANSFORM = MarkerTransform("sim", "0", (0.12, -0.05, -0.85), (_Q[0], _Q[1], _Q[2], _Q[3]), "t")
# Robot stop poses, a few cm and rad from waypoints; waypoint 1 sits on the +-pi seam.
WAYPOINTS = ((1.0, 0.5, 0.4), (2.0, 1.5, math.pi), (0.5, 2.0, -2.0), (-0.5, 0.5, 1.0))
STOPS = ((1.03, 0.46, 0.45), (2.02, 1.55, -math.pi + 0.04), (0.4, 2.1, -1.9), (-0.5, 0.6, 1.1))
HZ = 120


def _states(machine: Machine, events: list[tuple[float, int, str]]) -> StateStream:
    return StateStream(
        machine,
        np.array([T0 + round(t * S) for t, _, _ in events], dtype=np.int64),
        np.array([s for _, s, _ in events], dtype=np.uint8),
        tuple(p for _, _, p in events),
        f"/fbm2h/{machine.value}_state",
        "sim",
    )


def _marker(
    stops: list[tuple[float, float, float]], reached_s: list[float], end_s: float, seed: int
) -> PoseStream:
    """The marker set: still at each stop from 1 s before its reached moment, moving linearly
    in between (0.2 mm / 0.5 mrad of noise), composed with the inverse transform."""
    rng = np.random.default_rng(seed)
    t_s = np.arange(0.0, end_s + 1.0, 1 / HZ)
    keys_t = [0.0]
    keys = [(0.0, 0.0, 0.0)]
    for stop, at in zip(stops, reached_s, strict=True):
        keys_t += [at - 1.0, at + 1.0]
        keys += [stop, stop]
    kt = np.array(keys_t)
    kx = np.array(keys)
    yaw = np.unwrap(kx[:, 2])
    x = np.interp(t_s, kt, kx[:, 0]) + rng.normal(0, 2e-4, len(t_s))
    y = np.interp(t_s, kt, kx[:, 1]) + rng.normal(0, 2e-4, len(t_s))
    th = np.interp(t_s, kt, yaw) + rng.normal(0, 5e-4, len(t_s))
    r_robot = Rotation.from_euler("z", th[:, None])
    r_mr = Rotation.from_quat(list(TRANSFORM.quat_xyzw))
    r_marker = r_robot * r_mr.inv()
    p_marker = np.column_stack([x, y, np.zeros_like(x)]) - r_marker.apply(
        list(TRANSFORM.translation)
    )
    t_ns = T0 + np.round(t_s * S).astype(np.int64)
    return PoseStream(t_ns, p_marker, r_marker.as_quat(), "world", "robot_at_home", "sim")


def _run(segments_done: int, end_payload: str, seed: int) -> dict[str, Any]:
    """Segments 0..done-1 reached 5 s apart; segment ``done`` started, then RefBox END."""
    bm: list[tuple[float, int, str]] = [(0.0, B.READY, "")]
    cl: list[tuple[float, int, str]] = [(0.0, C.WAITING_GOAL, "")]
    reached = []
    for i in range(segments_done + 1):
        t0 = 1.0 + 5.0 * i
        bm += [
            (t0, B.TRANSMITTING_GOAL, "waypoints: []" if i == 0 else ""),
            (t0 + 0.2, B.EXECUTING_GOAL, ""),
            (t0 + 0.21, B.WAITING_RESULT, ""),
        ]
        cl.append((t0 + 0.1, C.EXECUTING_GOAL, ""))
        if i < segments_done:
            reached.append(t0 + 4.0)
            bm.append((t0 + 4.2, B.READY, ""))
            cl += [(t0 + 4.0, C.COMPLETED_GOAL, f"{{int: {i}}}"), (t0 + 4.1, C.WAITING_GOAL, "")]
    t_end = 1.0 + 5.0 * segments_done + 3.3
    bm.append((t_end + 0.1, B.END, ""))
    rb = [(0.0, R.EXECUTING_GOAL, ""), (t_end, R.END, end_payload)]
    marker = _marker(list(STOPS[:segments_done]), reached, t_end, seed)
    bms, cls, rbs = (
        _states(Machine.BMBOX, bm),
        _states(Machine.CLIENT, cl),
        _states(Machine.REFBOX, rb),
    )
    return {
        "marker": marker,
        "states": (bms, cls, rbs),
        "end_s": t_end,
    }


def _compute(run: dict[str, Any], **kw: Any) -> Any:
    bm, cl, rb = run["states"]
    moments = from_states(bm, cl, rb)
    goal = GoalList(WAYPOINTS, source="sim goal")
    return compute(
        goal,
        TRANSFORM,
        run["marker"],
        moments,
        unreached=unreached_reasons(moments, len(WAYPOINTS), rb),
        origin_ns=T0,
        **kw,
    )


# --- frozen ground truth ---------------------------------------------------------------------


def _freeze(marker: PoseStream, at_s: float, before_s: float, after_s: float) -> PoseStream:
    """Motive losing the body: the pose at ``at - before`` repeated until ``at + after``."""
    t = marker.t_ns
    a = int(np.searchsorted(t, T0 + round((at_s - before_s) * S)))
    b = int(np.searchsorted(t, T0 + round((at_s + after_s) * S)))
    xyz, quat = marker.xyz.copy(), marker.quat_xyzw.copy()
    xyz[a:b] = xyz[a]
    quat[a:b] = quat[a]
    return PoseStream(t, xyz, quat, marker.frame_id, marker.child_frame_id, marker.source)


def test_frozen_gt_at_a_reached_moment_is_warned() -> None:
    run = _run(2, "timeout", seed=8)
    # Segment 1 is reached at 10.0 s; the body is lost from 9.4 s to 10.5 s.
    run["marker"] = _freeze(run["marker"], 10.0, 0.6, 0.5)
    # by default no valid GT lies within 0.1 s of the moment: the segment has none (issue 28)
    refused = _compute(run)
    assert refused.segments[1].status == "no_gt"
    assert refused.position_accuracy is None
    assert not [w for w in refused.warnings if "frozen" in w]
    assert refused.unscoreable_reason == (
        "segment 1: no valid ground truth within --gt-tolerance 0.1 s of the reached moment "
        "10.000 s after the log's first message: only repeated poses of a lost marker set "
        "(tracking lost)"
    )
    # the segment's mask: every repeat from the frozen pose on to the reached moment
    t = run["marker"].t_ns
    frozen_from = int(t[np.searchsorted(t, T0 + round(9.4 * S))])
    reached = refused.segments[1].end_ns
    repeats = int(np.sum((t > frozen_from) & (t <= reached)))
    assert repeats == 72  # 0.6 s at 120 Hz
    validity = refused.segments[1].validity
    assert validity is not None and validity.invalid_samples == {"tracking_lost": repeats}
    # where the path plot draws it: from the last measurement to the reached moment (the
    # segment's end: no valid sample after it inside the segment)
    (gap,) = refused.segments[1].gaps
    assert (gap.reason, gap.end_xy, gap.lost) == ("tracking_lost", None, True)
    assert gap.start_s == (frozen_from - T0) / 1e9 and gap.end_s == (reached - T0) / 1e9
    assert gap.start_xy is not None
    assert refused.to_dict()["status"] == "unscoreable"
    assert refused.to_dict()["details"]["segments_details"]["1"]["unscoreable_reason"]
    # as 2015 did, scored from the frozen pose, and warned
    result = _compute(run, unscoreable_2015=True)
    assert result.segments[1].status == "ok"
    assert result.segments[1].unscoreable_reason == refused.segments[1].unscoreable_reason
    assert "status" not in result.to_dict()
    assert any(
        w.startswith("segment 1: 2015 scored this segment from a pose that was not measured")
        for w in result.warnings
    )
    lines = [w for w in result.warnings if "frozen" in w]
    assert len(lines) == 1
    line = lines[0]
    assert line.startswith("segment 1:") and "reached moment 10.000 s" in line
    # 132 identical poses (1.1 s at 120 Hz, both ends included) over 1.092 s.
    assert "identical poses over 1.092 s" in line and "9.400-10.492 s" in line
    # 6 repeated frames (50 ms, below --max-gap 0.1 s) are not worth a warning.
    run["marker"] = _freeze(_run(2, "timeout", seed=8)["marker"], 10.0, 0.03, 0.02)
    assert not [w for w in _compute(run).warnings if "frozen" in w]


# --- frame_id changing in the middle of the log ----------------------------------------------


def _frame_change_bag(path: Path) -> None:
    t_s = np.arange(0.0, 6.0, 1 / HZ)
    rng = np.random.default_rng(9)
    xyz = np.column_stack([0.5 * t_s / 6, np.zeros_like(t_s), np.full_like(t_s, 0.85)])
    xyz += rng.normal(0, 2e-4, xyz.shape)
    quat = np.tile([0.0, 0.0, 0.0, 1.0], (len(t_s), 1))
    t = T0 + np.round(t_s * S).astype(np.int64)
    first = t_s < 3.0
    with BagWriter(path) as w:
        topic = "/fbm2h/robot_at_home/pose"
        w.write_pose_stamped(topic, t[first], t[first], "world", xyz[first], quat[first])
        w.write_pose_stamped(topic, t[~first], t[~first], "optitrack", xyz[~first], quat[~first])


@pytest.mark.slow
def test_frame_id_change_is_warned_in_output_and_report(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    bag = tmp_path / "frames.bag"
    _frame_change_bag(bag)
    poses = read_poses(bag, "/fbm2h/robot_at_home/pose")
    assert [(c.t_ns - T0, c.field, c.old, c.new) for c in poses.frame_changes] == [
        (3 * S, "frame_id", "world", "optitrack")
    ]
    goal = tmp_path / "goal.yaml"
    goal.write_text("goal:\n  waypoints:\n  - [0.1, 0.0, 0.0]\n  - [0.4, 0.0, 0.0]\n")
    timing = tmp_path / "timing.yaml"
    timing.write_text("reached_waypoint_timing:\n- p0: 0.5\n- p1: 1.5\n- p2: 5.0\n")
    report = tmp_path / "report"
    code = main(
        [
            "score",
            "fbm2h",
            str(bag),
            "--goal",
            str(goal),
            "--reached",
            "timing",
            str(timing),
            "--report",
            str(report),
        ]
    )
    err = capsys.readouterr().err
    assert code == 0, err
    line = next(ln for ln in err.splitlines() if "frame names change" in ln)
    assert line.startswith("ertools: warning:")
    assert "frame_id 'world' -> 'optitrack' at 3.000 s" in line
    texts = [p.read_text(errors="replace") for p in report.rglob("*") if p.is_file()]
    assert any("'world' -> 'optitrack'" in t for t in texts)


def test_lost_gt_is_still_a_failure_with_2015() -> None:
    run = _run(2, "timeout", seed=12)
    m = run["marker"]
    # No sample from 9.5 s to 10.5 s: segment 1's reached moment (10.0 s) has no ground truth.
    keep = (m.t_ns < T0 + round(9.5 * S)) | (m.t_ns > T0 + round(10.5 * S))
    run["marker"] = m.take(keep)
    result = _compute(run, orientation_2015=True, unscored_2015=True)
    assert result.segments[1].status == "no_gt"
    assert result.position_accuracy is None and result.orientation_accuracy is None
    assert len(result.failures) == 1 and "segment 1: no ground truth" in result.failures[0]
