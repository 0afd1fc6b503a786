"""``--2015`` against the 2015 node's arithmetic, re-implemented here as a plain loop.

From ``rockin_scoring/scripts/fbm2h`` (RoCKIn repository ``benchmark_and_scoring_fbm``) and
seed 7.2: ``sum_d``, ``sum_sin``, ``sum_cos`` and ``execution_time`` start at 0; per segment,
when the RefBox timed the benchmark out (``benchmark.Timeout()``) the segment's time is added
and nothing else; when it stopped it (``not benchmark.Running()``) nothing is added; otherwise
``d = sqrt(dx^2 + dy^2)``, ``sin|dtheta|`` and ``cos|dtheta|`` of the unwrapped yaw difference
are added with the segment time. At the end ``position_accuracy = sum_d / N`` with N the
number of waypoints, ``orientation_accuracy = atan2(sum_sin, sum_cos)``. The robot pose is the
marker pose interpolated at the reached moment (tf: linear + SLERP), composed with the team's
marker-to-robot transform, yaw from ``euler_from_quaternion`` (static xyz). Only scipy is used
here, not ertools' geometry.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml
from scipy.spatial.transform import Rotation, Slerp

from ertools.benchmarks.fbm2h.benchmark import compute
from ertools.benchmarks.fbm2h.segments import from_states, unreached_reasons
from ertools.cli.main import main
from ertools.configs.goal import GoalList
from ertools.configs.transform import MarkerTransform
from ertools.io import read_benchmark_states, read_poses
from ertools.samples.writer import BagWriter
from ertools.states import BmBoxState as B
from ertools.states import ClientState as C
from ertools.states import Machine
from ertools.states import RefBoxState as R
from ertools.streams import PoseStream, StateStream

S = 1_000_000_000
T0 = 1_448_020_800 * S
TOL = 1e-12

Events = list[tuple[int, int, str]]


def _pose_at(
    t: np.ndarray, xyz: np.ndarray, quat: np.ndarray, at: int
) -> tuple[np.ndarray, Rotation]:
    j = int(np.searchsorted(t, at, side="right")) - 1
    if t[j] == at or j + 1 == len(t):
        return xyz[j], Rotation.from_quat(quat[j])
    f = (at - t[j]) / (t[j + 1] - t[j])
    rot = Slerp([0.0, 1.0], Rotation.from_quat(quat[j : j + 2]))([f])[0]
    return xyz[j] + f * (xyz[j + 1] - xyz[j]), rot


def node_2015(
    marker: tuple[np.ndarray, np.ndarray, np.ndarray],
    t_mr: tuple[list[float], list[float]],
    waypoints: list[list[float]],
    bmbox: Events,
    client: Events,
    refbox: Events,
) -> dict[str, Any]:
    t, xyz, quat = marker
    r_mr = Rotation.from_quat(t_mr[1])
    goals = [
        tt
        for k, (tt, s, _) in enumerate(bmbox)
        if s == B.TRANSMITTING_GOAL and (k == 0 or bmbox[k - 1][1] != s)
    ]
    end_t, end_word = None, ""
    for tt, s, p in refbox:
        if s == R.END and p.strip():
            end_t, end_word = tt, p.lower()
            break
    n = len(waypoints)
    sum_d = sum_sin = sum_cos = execution_time = 0.0
    details: dict[int, dict[str, float]] = {}
    for i, g in enumerate(goals):
        nxt = goals[i + 1] if i + 1 < len(goals) else None
        start = next(tt for tt, s, _ in bmbox if s == B.EXECUTING_GOAL and tt >= g)
        done = [
            tt
            for tt, s, _ in client
            if s == C.COMPLETED_GOAL and tt >= start and (nxt is None or tt < nxt)
        ]
        if not done:
            assert end_t is not None and end_t >= start
            if "timeout" in end_word:
                execution_time += (end_t - start) / 1e9
            break  # the benchmark is over: ``while benchmark.Running() and not Timeout()``
        end = done[0]
        p_m, r_m = _pose_at(t, xyz, quat, end)
        p_r = p_m + r_m.apply(t_mr[0])
        yaw = (r_m * r_mr).as_euler("xyz")[2]
        wx, wy, wth = waypoints[i]
        d = math.sqrt((p_r[0] - wx) ** 2 + (p_r[1] - wy) ** 2)
        dth = abs(yaw - wth)
        sum_d += d
        sum_sin += math.sin(dth)
        sum_cos += math.cos(dth)
        execution_time += (end - start) / 1e9
        details[i] = {"d": d, "o": math.atan2(math.sin(dth), math.cos(dth))}
    return {
        "position_accuracy": sum_d / n,
        "orientation_accuracy": math.atan2(sum_sin, sum_cos),
        "execution_time": execution_time,
        "segments": details,
    }


def _check(out: dict[str, Any], node: dict[str, Any]) -> None:
    for key in ("position_accuracy", "orientation_accuracy", "execution_time"):
        assert out[key] == pytest.approx(node[key], abs=TOL), key
    segs = out["details"]["segments_details"]
    for i, d in node["segments"].items():
        assert segs[str(i)]["dinstance_error"] == pytest.approx(d["d"], abs=TOL)
        assert segs[str(i)]["orientation_error"] == pytest.approx(d["o"], abs=TOL)
    assert out["timeout_segments"] == 0  # Listing 13: "always 0"


def _events(s: StateStream | None) -> Events:
    return [] if s is None else list(zip(s.t_ns.tolist(), s.state.tolist(), s.payload, strict=True))


def test_sample_bag_2015_equals_the_node(
    fbm2h_sample: Any, capsys: pytest.CaptureFixture[str]
) -> None:
    bag = fbm2h_sample.bag
    marker = read_poses(bag, "/fbm2h/robot_at_home/pose")
    states = read_benchmark_states(bag, "fbm2h")
    tf = yaml.safe_load(fbm2h_sample.transform.read_text())["marker_to_robot_transform"]
    goal = yaml.safe_load(fbm2h_sample.goal.read_text())["goal"]["waypoints"]
    node = node_2015(
        (marker.t_ns, marker.xyz, marker.quat_xyzw),
        (tf[0], tf[1]),
        goal,
        _events(states.bmbox),
        _events(states.client),
        _events(states.refbox),
    )
    # Waypoint 2 faces theta = pi and the robot stops at about -pi: 2015's error is negative.
    assert node["segments"][2]["o"] < 0
    folder = str(fbm2h_sample.folder)
    argv = ["score", "fbm2h", str(bag), "--team", "simbot", "--transforms", folder]
    assert main([*argv, "--2015", "--format", "json"]) == 0
    captured = capsys.readouterr()
    _check(json.loads(captured.out), node)
    assert "accuracies: sum over the 5 scored segment(s) / N = 5 (2015)" in captured.err
    assert main([*argv, "--format", "json"]) == 0
    assert "accuracies: mean over all 5 segments" in capsys.readouterr().err
    # --orientation-2015 --unscored-segments 2015 is the same as --2015.
    both = ["--orientation-2015", "--unscored-segments", "2015", "--format", "json"]
    assert main([*argv, *both]) == 0
    _check(json.loads(capsys.readouterr().out), node)


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
        "node": node_2015(
            (marker.t_ns, marker.xyz, marker.quat_xyzw),
            (list(TRANSFORM.translation), list(TRANSFORM.quat_xyzw)),
            [list(w) for w in WAYPOINTS],
            _events(bms),
            _events(cls),
            _events(rbs),
        ),
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


def test_timed_out_and_unreached_segments_as_2015() -> None:
    run = _run(2, "reason: timeout", seed=5)
    node = run["node"]
    # Two of four waypoints scored: the sum of their errors over N = 4.
    assert node["position_accuracy"] == pytest.approx(
        (node["segments"][0]["d"] + node["segments"][1]["d"]) / 4, abs=1e-15
    )
    result = _compute(run, orientation_2015=True, unscored_2015=True)
    _check(result.to_dict(), node)
    # The timed-out segment 2 ran from its EXECUTING_GOAL (11.2 s) to the END (14.3 s).
    seg2 = result.to_dict()["details"]["segments_details"]["2"]
    assert seg2["segment_time"] == pytest.approx(run["end_s"] - 11.2, abs=1e-9)
    assert seg2["refbox_timeout"] is True and seg2["dinstance_error"] is None
    assert result.failures == ()
    assert any(
        "segment 3: waypoint never reached" in w and "counted in N" in w for w in result.warnings
    )
    # The default: no number, exit-1 failures, and a line saying what was (not) averaged.
    default = _compute(run)
    assert default.position_accuracy is None and len(default.failures) == 2
    line = next(w for w in default.warnings if "null" in w)
    assert "segment(s) 2, 3 of 4 not scored" in line and "--unscored-segments 2015" in line
    assert any("--unscored-segments 2015" in d for d in default.deviations)


def test_halted_segment_adds_no_time() -> None:
    run = _run(3, "halt", seed=6)
    node = run["node"]
    result = _compute(run, orientation_2015=True, unscored_2015=True)
    _check(result.to_dict(), node)
    # Three reached segments of 4 s each; the halted one adds nothing.
    assert result.execution_time == pytest.approx(3 * 3.8, abs=1e-9)
    assert result.to_dict()["details"]["segments_details"]["3"]["refbox_timeout"] is False


def test_nothing_reached_scores_zero_as_2015() -> None:
    run = _run(0, "timeout", seed=7)
    result = _compute(run, orientation_2015=True, unscored_2015=True)
    # 2015: 0.0 / N and atan2(0.0, 0.0); said, not hidden.
    assert (result.position_accuracy, result.orientation_accuracy) == (0.0, 0.0)
    assert result.execution_time == pytest.approx(run["node"]["execution_time"], abs=TOL)
    assert len([w for w in result.warnings if "counted in N" in w]) == 4


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
    result = _compute(run)
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
