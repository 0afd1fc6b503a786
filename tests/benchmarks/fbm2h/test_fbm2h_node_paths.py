"""``score fbm2h --2015`` (and ``--rules 2016``, ``--rules 2017``) against the node's loop as
written, on every path of its state machine; the default mode on the same logs.

``node_fbm2h.py`` ports ``scripts/fbm2h`` at 50b173b statement by statement (the RoCKIn 2015
node; the same file ran the Lisbon 2016 and 2017 competitions, 40ba68b and 89dfa75) and
replays it over the BmBox of each generated log (``tests/helpers/bmbox2015.py``), read back with
rosbags (not ertools.io); the robot pose is tf ``world -> robot_at_home`` read the same way
and interpolated with scipy. Each log is written with the samples' writer: a benchmark of four
waypoints in which one thing happens: a normal end; the RefBox's ``reason: timeout`` or
``reason: stop`` while the robot drives (the node scores that segment where ``WaitResult()``
returned and counts a timeout in ``timeout_segments``); a timeout or stop while the goal is
being sent (the BmBox does not leave TRANSMITTING_GOAL for them); the seed's bare ``timeout``
payload (the BmBox ignored it); the log cut before the first goal, while a goal is sent, while
the robot drives and between two segments.

Tolerance 1e-12 relative: both sides add the same terms in the same order; ertools sums the
segment times in int64 ns before converting (the port adds float seconds), ~1e-16 apart.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml
from rosbags.highlevel import AnyReader
from scipy.spatial.transform import Rotation

from ertools.cli.main import main
from ertools.simulator.statemachine import Transition, publish_states
from ertools.simulator.writer import BagWriter
from ertools.states import BmBoxState as B
from ertools.states import ClientState as C
from ertools.states import Machine
from ertools.states import RefBoxState as R
from tests.benchmarks.fbm2h.node_fbm2h import Score2015, TfPoses, fbm2h_node
from tests.helpers.bmbox2015 import BmBoxReplay

pytestmark = pytest.mark.slow

S = 1_000_000_000
MS = 1_000_000
T0 = 1_448_020_800 * S  # 2015-11-20T12:00:00Z
REL = 1e-12
HZ = 120
TF_AFTER_NS = 5_000  # /tf stamped 5 us after the pose topic (as the samples' mocap)

# Waypoint 1 faces theta = pi and the robot stops at about -pi: 2015's error there is negative.
WAYPOINTS = ((1.0, 0.5, 0.4), (2.0, 1.5, math.pi), (0.5, 2.0, -2.0), (-0.5, 0.5, 1.0))
STOPS = ((1.03, 0.46, 0.45), (2.02, 1.55, -math.pi + 0.04), (0.4, 2.1, -1.9), (-0.5, 0.6, 1.1))
M2R_T = (0.12, -0.05, -0.85)
M2R_Q = tuple(Rotation.from_euler("xyz", [0.02, -0.01, -0.3]).as_quat().tolist())
SEGMENT_S = 6.0  # one goal every 6 s: sent at g, executing at g + 0.2, reached at g + 5.0


def _goal_s(k: int) -> float:
    return 1.5 + SEGMENT_S * k


@dataclass(frozen=True)
class Case:
    """One path: what happens in segment ``at``, and the 2015 numbers to expect by hand."""

    name: str
    event: str  # normal, timeout, stop, timeout_sending, stop_sending, bare_timeout, unknown, cut_*
    at: int = 2  # the segment it happens in


CASES = (
    Case("normal", "normal"),
    Case("timeout while driving", "timeout"),
    Case("stop while driving", "stop"),
    Case("stop in the first segment", "stop", at=0),
    Case("timeout while the goal is sent", "timeout_sending"),
    Case("stop while the goal is sent", "stop_sending"),
    Case("bare 'timeout' payload", "bare_timeout"),
    Case("an END payload no code knew", "unknown"),
    Case("cut before the first goal", "cut_before"),
    Case("cut while the goal is sent", "cut_sending"),
    Case("cut while driving", "cut_driving"),
    Case("cut before WAITING_RESULT", "cut_executing"),
    Case("cut between segments", "cut_between"),
)


def _transitions(case: Case) -> tuple[list[Transition], int | None]:
    """The three machines' transitions (as the 2015 BmBox.py, RefBox.py would make them) and
    the log's end when it is cut."""

    def at(s: float) -> int:
        return T0 + round(s * S)

    tr = [
        Transition(at(0.0), Machine.BMBOX, B.START),
        Transition(at(0.02), Machine.REFBOX, R.START),
        Transition(at(0.04), Machine.CLIENT, C.START),
        Transition(at(0.1), Machine.BMBOX, B.WAITING_CLIENT),
        Transition(at(0.15), Machine.REFBOX, R.WAITING_CLIENT),
        Transition(at(0.16), Machine.CLIENT, C.CONNECTING),
        Transition(at(0.3), Machine.CLIENT, C.READY),
        Transition(at(0.35), Machine.REFBOX, R.READY),
        Transition(at(0.4), Machine.BMBOX, B.READY),
        Transition(at(0.45), Machine.CLIENT, C.WAITING_GOAL),
    ]
    cut: int | None = None
    if case.event == "cut_before":
        return tr, at(1.2)
    t_score = 0.0
    for k in range(len(WAYPOINTS)):
        g = _goal_s(k)
        here = k == case.at
        tr.append(Transition(at(g), Machine.BMBOX, B.TRANSMITTING_GOAL))
        if here and case.event == "cut_sending":
            return tr, at(g + 0.1)
        if here and case.event == "stop_sending":
            # BmBox.py: the stop callback's update(READY) is no transition from
            # TRANSMITTING_GOAL; the Client stops, so the node waits in SendGoal() until the
            # recording is stopped.
            tr += [
                Transition(at(g + 0.05), Machine.REFBOX, R.END, "reason: stop"),
                Transition(at(g + 0.1), Machine.CLIENT, C.END),
            ]
            return tr, at(g + 2.0)
        if here and case.event == "timeout_sending":
            # Timeout moves the BmBox only from EXECUTING_GOAL or WAITING_RESULT: it goes on.
            tr.append(Transition(at(g + 0.05), Machine.REFBOX, R.END, "reason: timeout"))
        else:
            tr.append(Transition(at(g + 0.1), Machine.REFBOX, R.EXECUTING_GOAL))
        tr += [
            Transition(at(g + 0.15), Machine.CLIENT, C.EXECUTING_GOAL),
            Transition(at(g + 0.2), Machine.BMBOX, B.EXECUTING_GOAL),
            Transition(at(g + 0.21), Machine.BMBOX, B.WAITING_RESULT),
        ]
        if here and case.event == "cut_driving":
            return tr, at(g + 3.0)
        if here and case.event == "cut_executing":
            # The log ends at the BmBox's EXECUTING_GOAL, before its WAITING_RESULT.
            return [x for x in tr if x.t_ns < at(g + 0.21)], at(g + 0.205)
        if here and case.event in ("timeout", "stop"):
            tr += [
                Transition(at(g + 3.0), Machine.REFBOX, R.END, f"reason: {case.event}"),
                Transition(at(g + 3.03), Machine.BMBOX, B.READY),
                Transition(at(g + 3.1), Machine.CLIENT, C.END),
            ]
            t_score = g + 3.2
            break
        if here and case.event in ("bare_timeout", "unknown"):
            text = "timeout" if case.event == "bare_timeout" else "reason: finished"
            tr.append(Transition(at(g + 3.0), Machine.REFBOX, R.END, text))
        tr += [
            Transition(at(g + 5.0), Machine.CLIENT, C.COMPLETED_GOAL, f"waypoint: {k}\n"),
            Transition(at(g + 5.06), Machine.BMBOX, B.READY),
            Transition(at(g + 5.2), Machine.CLIENT, C.WAITING_GOAL),
        ]
        ended = case.event in ("timeout_sending", "bare_timeout", "unknown") and k >= case.at
        if not ended:
            tr.append(Transition(at(g + 5.08), Machine.REFBOX, R.READY))
        if here and case.event == "timeout_sending":
            t_score = g + 5.3  # the node saw Timeout() and left its loop
            break
        if k + 1 == case.at and case.event == "cut_between":
            return tr, at(g + 5.6)
        t_score = g + SEGMENT_S
    tr += [
        Transition(at(t_score), Machine.BMBOX, B.TRANSMITTING_SCORE, "score"),
        Transition(at(t_score + 0.3), Machine.BMBOX, B.END),
    ]
    if case.event in ("normal", "cut_between"):
        tr += [
            Transition(at(t_score + 0.1), Machine.REFBOX, R.RECEIVED_SCORE),
            Transition(at(t_score + 0.35), Machine.REFBOX, R.END),
            Transition(at(t_score + 0.4), Machine.CLIENT, C.END),
        ]
    return tr, cut


def _robot(t_ns: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The robot: still at the start, then for each segment a straight drive from g + 0.8 s to
    g + 4.0 s to its stop pose (yaw by the short way), still until the next goal."""
    t_s = (t_ns - T0) / S
    keys_t = [0.0]
    keys = [(0.0, 0.0, 0.0)]
    for k, stop in enumerate(STOPS):
        g = _goal_s(k)
        keys_t += [g + 0.8, g + 4.0]
        keys += [keys[-1], stop]
    kt = np.asarray(keys_t)
    kx = np.asarray(keys)
    yaw = np.unwrap(kx[:, 2])
    pose = np.column_stack(
        [np.interp(t_s, kt, kx[:, i]) for i in (0, 1)] + [np.interp(t_s, kt, yaw)]
    )
    return pose[:, :2], pose[:, 2]


def _write(case: Case, folder: Path) -> tuple[Path, Path, Path]:
    """The log, the goal list (Listing 10) and the transform (Listing 11) of ``case``."""
    trs, cut = _transitions(case)
    last = max(t.t_ns for t in trs)
    end = cut if cut is not None else last + S
    frames = np.arange(T0 + S // 2, end, round(S / HZ), dtype=np.int64)
    xy, yaw = _robot(frames)
    rng = np.random.default_rng(len(case.name))
    xy = xy + rng.normal(0, 2e-4, xy.shape)
    yaw = yaw + rng.normal(0, 5e-4, yaw.shape)
    # T_world_marker = T_world_robot * inv(T_marker_robot).
    r_robot = Rotation.from_euler("z", yaw[:, None])
    r_mr = Rotation.from_quat(list(M2R_Q))
    r_marker = r_robot * r_mr.inv()
    p_marker = np.column_stack([xy, np.zeros(len(xy))]) - r_marker.apply(list(M2R_T))
    bag = folder / "log_fbm2h_mocap_2015-11-20-12-00-00_0.bag"
    with BagWriter(bag) as w:
        q = r_marker.as_quat()
        w.write_pose_stamped(
            "/fbm2h/robot_at_home/pose", frames + 300_000, frames, "world", p_marker, q
        )
        w.write_tf(frames + 310_000, frames + TF_AFTER_NS, "world", "robot_at_home", p_marker, q)
        publish_states(w, "fbm2h", trs, end_ns=cut)
    goal = folder / "goal.yaml"
    rows = "\n".join(f"  - [{x!r}, {y!r}, {t!r}]" for x, y, t in WAYPOINTS)
    goal.write_text(f"goal:\n  waypoints:\n{rows}\n")
    transform = folder / "transform-sim.yaml"
    transform.write_text(
        "robot_info: sim\ntransform_timestamp: 0\nmarker_to_robot_transform:\n"
        f"- {list(M2R_T)}\n- {list(M2R_Q)}\n"
    )
    return bag, goal, transform


Message = tuple[int, Machine, int, str]  # (record time ns, machine, state, payload)


def replay(msgs: list[Message]) -> BmBoxReplay:
    """The BmBox of the node over the three machines' logged messages."""
    by = {
        m: [(t, st, p) for t, mm, st, p in sorted(msgs, key=lambda x: x[0]) if mm is m]
        for m in Machine
    }
    return BmBoxReplay(by[Machine.BMBOX], by[Machine.REFBOX], by[Machine.CLIENT])


def _read_back(bag: Path) -> tuple[list[Message], TfPoses]:
    """State messages and the /tf marker poses, through rosbags (not ertools.io)."""
    machines = {f"/fbm2h/{m.value}_state": m for m in Machine}
    msgs: list[Message] = []
    t: list[int] = []
    xyz: list[list[float]] = []
    quat: list[list[float]] = []
    with AnyReader([bag]) as reader:
        for conn, stamp, raw in reader.messages():
            msg = reader.deserialize(raw, conn.msgtype)
            if conn.topic in machines:
                msgs.append((stamp, machines[conn.topic], int(msg.state), str(msg.payload)))
            elif conn.topic == "/tf":
                for tr in msg.transforms:
                    if (tr.header.frame_id, tr.child_frame_id) == ("world", "robot_at_home"):
                        st = tr.header.stamp
                        t.append(st.sec * S + st.nanosec)
                        p, r = tr.transform.translation, tr.transform.rotation
                        xyz.append([p.x, p.y, p.z])
                        quat.append([r.x, r.y, r.z, r.w])
    order = np.argsort(t, kind="stable")
    return msgs, TfPoses(np.asarray(t)[order], np.asarray(xyz)[order], np.asarray(quat)[order])


def _score(args: list[str], capsys: pytest.CaptureFixture[str]) -> tuple[int, Any, str]:
    # the 2015 node's numbers are the subject, not the intervals: no Monte Carlo draws
    code = main(["score", "fbm2h", *args, "--format", "json", "--draws", "0"])
    cap = capsys.readouterr()
    return code, json.loads(cap.out) if cap.out.strip() else None, cap.err


def _close(ours: float | None, theirs: float, what: str) -> None:
    assert ours is not None, what
    assert ours == pytest.approx(theirs, rel=REL, abs=1e-15), what


def assert_same(out: dict[str, Any], node: Score2015) -> None:
    """Every number the node computed, field for field."""
    _close(out["position_accuracy"], node.position_accuracy, "position_accuracy")
    _close(out["orientation_accuracy"], node.orientation_accuracy, "orientation_accuracy")
    _close(out["execution_time"], node.execution_time, "execution_time")
    assert out["timeout_segments"] == node.timeout_segments
    segs = out["details"]["segments_details"]
    for i, d in node.details.items():
        ours = segs[str(i)]
        _close(ours["start_segment_time"], d["start_segment_time"] / 1e9, f"{i} start")
        _close(ours["end_segment_time"], d["end_segment_time"] / 1e9, f"{i} end")
        _close(ours["segment_time"], d["segment_time"], f"{i} segment_time")
        assert ours["refbox_timeout"] is d["refbox_timeout"], i
        assert ours["timeout"] is d["timeout"], i
        _close(ours["dinstance_error"], d["dinstance_error"], f"{i} distance")
        _close(ours["orientation_error"], d["orientation_error"], f"{i} orientation")
        rp = ours["robot_pose"]
        for key, v in zip(("x", "y", "theta"), d["robot_pose"], strict=True):
            _close(rp[key], v, f"{i} robot {key}")
    for i in range(len(WAYPOINTS)):
        if i not in node.details:
            assert segs[str(i)]["dinstance_error"] is None and segs[str(i)]["segment_time"] is None


@pytest.fixture(scope="module", params=CASES, ids=[c.name for c in CASES])
def logged(request: pytest.FixtureRequest, tmp_path_factory: pytest.TempPathFactory) -> Any:
    case: Case = request.param
    folder = tmp_path_factory.mktemp(case.event)
    bag, goal, transform = _write(case, folder)
    msgs, tf = _read_back(bag)
    node = fbm2h_node(replay(msgs), tf, WAYPOINTS, (M2R_T, M2R_Q))
    args = [str(bag), "--goal", str(goal), "--transform", str(transform)]
    return case, node, args


# What the node scored on each path, by hand from its loop: the segments scored, the one it
# counted as timed out, whether the log's end stopped it.
BY_HAND = {
    "normal": ([0, 1, 2, 3], None, False),
    "timeout": ([0, 1, 2], 2, False),
    "stop": ([0, 1, 2], None, False),
    "timeout_sending": ([0, 1, 2], 2, False),
    "stop_sending": ([0, 1], None, True),
    "bare_timeout": ([0, 1, 2, 3], None, False),
    "unknown": ([0, 1, 2, 3], None, False),
    "cut_before": ([], None, True),
    "cut_sending": ([0, 1], None, True),
    "cut_driving": ([0, 1, 2], None, True),
    "cut_executing": ([0, 1, 2], None, True),
    "cut_between": ([0, 1], None, True),
}


def test_the_port_follows_the_loop(logged: Any) -> None:
    """The port's outcome on each path is the one read from the source by hand."""
    case, node, _ = logged
    scored, timed_out, cut = BY_HAND[case.event]
    if case.event == "stop" and case.at == 0:
        scored = [0]
    assert [i for i, d in node.details.items() if "dinstance_error" in d] == scored
    assert [i for i, d in node.details.items() if d["timeout"]] == (
        [] if timed_out is None else [timed_out]
    )
    assert not any(d["refbox_timeout"] for d in node.details.values())  # l. 158: dead
    assert node.timeout_segments == (0 if timed_out is None else 1)
    assert node.cut is cut
    # sum_d over N = 4 whatever was scored (l. 225).
    d = [node.details[i]["dinstance_error"] for i in scored]
    assert node.position_accuracy == pytest.approx(sum(d) / 4, rel=1e-15, abs=0)


@pytest.mark.parametrize("rules", [["--2015"], ["--rules", "2016"], ["--rules", "2017"]])
def test_rules_equal_the_node(
    logged: Any, rules: list[str], capsys: pytest.CaptureFixture[str]
) -> None:
    case, node, args = logged
    code, out, err = _score([*args, *rules], capsys)
    assert code == 0, err
    assert_same(out, node)
    if len(node.details) < len(WAYPOINTS):
        assert "counted in N with no error, as 2015 did" in err
    if case.event in ("bare_timeout", "unknown"):
        text = "timeout" if case.event == "bare_timeout" else "reason: finished"
        said = f"RefBox END with payload '{text}', which is none of the forms the 2015 BmBox knows"
        assert said in err and "neither a timeout nor a stop" in err
    assert ("the log ends inside the benchmark" in err) is node.cut


# What the default scores on each path: the segments the Client completed; a segment a RefBox
# timeout or stop (or the log's end) cut short is not scored (rule fbm2h.unscored-segments).
BY_DEFAULT = {
    "normal": [0, 1, 2, 3],
    "timeout": [0, 1],
    "stop": [0, 1],
    "timeout_sending": [0, 1],
    "stop_sending": [0, 1],
    "bare_timeout": [0, 1],  # the seed's 'timeout' read as the timeout it names, said
    "unknown": [0, 1, 2, 3],  # no known form: neither, warned
    "cut_before": [],
    "cut_sending": [0, 1],
    "cut_driving": [0, 1],
    "cut_executing": [0, 1],
    "cut_between": [0, 1],
}


def test_default_scores_the_completed_segments_and_names_the_rest(
    logged: Any, capsys: pytest.CaptureFixture[str]
) -> None:
    case, node, args = logged
    code, out, err = _score(args, capsys)
    scored = [] if case.event == "stop" and case.at == 0 else BY_DEFAULT[case.event]
    if case.event == "bare_timeout":
        assert "as a timeout" in err and "[all.end-payloads]" in err
    segs = out["details"]["segments_details"]
    assert [int(i) for i, s in segs.items() if s["dinstance_error"] is not None] == scored
    if len(scored) == len(WAYPOINTS):
        assert code == 0, err
        assert out["position_accuracy"] is not None
        return
    # Unscored segments: null, named in the errors and the warning, exit 1 with the numbers.
    assert code == 1
    assert out["position_accuracy"] is None and out["orientation_accuracy"] is None
    timed = [i for i, s in segs.items() if s["dinstance_error"] is None and s["timeout"]]
    assert out["execution_time"] == pytest.approx(
        sum(segs[str(i)]["segment_time"] for i in scored)
        + sum(segs[i]["segment_time"] or 0.0 for i in timed),
        rel=REL,
    )
    assert "--unscored-segments 2015 divides the sum" in err
    missing = [i for i in range(len(WAYPOINTS)) if i not in scored]
    assert f"segment(s) {', '.join(map(str, missing))} of 4 not scored" in err
    for i in missing:
        assert f"segment {i}:" in err
    # Where the node scored a segment the default leaves null, the output says so.
    if set(node.details) - set(scored):
        assert "[fbm2h.unscored-segments]" in err


def test_sample_2015_is_the_node_on_its_own_clock(
    fbm2h_sample: Any, capsys: pytest.CaptureFixture[str]
) -> None:
    """The sample log: BmBox messages at both ends (41.50 s, 60 ms per segment more than the
    Client's reports) and /tf as the pose source."""
    msgs, tf = _read_back(fbm2h_sample.bag)
    answers = fbm2h_sample.answers
    waypoints = [tuple(s["target_pose"]) for s in answers["expected"]["segments"]]
    tr = yaml.safe_load(fbm2h_sample.transform.read_text())["marker_to_robot_transform"]
    node = fbm2h_node(replay(msgs), tf, waypoints, (tr[0], tr[1]))
    folder = str(fbm2h_sample.folder)
    args = [str(fbm2h_sample.bag), "--team", "simbot", "--transforms", folder]
    code, out, err = _score([*args, "--2015"], capsys)
    assert code == 0, err
    assert_same(out, node)
    assert node.execution_time == pytest.approx(41.5, abs=1e-9)
    assert node.details[2]["orientation_error"] < 0  # the +-pi seam, unwrapped
    # The default: the Client's reports and the pose topic, said.
    code, out, err = _score(args, capsys)
    assert code == 0 and out["execution_time"] == pytest.approx(41.2, abs=1e-9)
    assert "--segment-clock bmbox restores 2015 [fbm2h.segment-clock]" in err
    assert "--tf world:robot_at_home restores 2015 [fbm2h.pose-source]" in err


def test_2015_without_the_node_s_tf_frame_scores_the_topic_and_says_so(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A log whose /tf lacks world -> robot_at_home: --2015 reads the pose topic, warned."""
    t = T0 + np.arange(0, 6 * S, S // HZ, dtype=np.int64)
    xyz = np.column_stack([np.linspace(0.0, 0.5, len(t)), np.zeros(len(t)), np.full(len(t), 0.85)])
    quat = np.tile([0.0, 0.0, 0.0, 1.0], (len(t), 1))
    bag = tmp_path / "log.bag"
    with BagWriter(bag) as w:
        w.write_pose_stamped("/fbm2h/robot_at_home/pose", t, t, "world", xyz, quat)
        w.write_tf(t[:5], t[:5], "world", "map", xyz[:5], quat[:5])
    goal = tmp_path / "goal.yaml"
    goal.write_text("goal:\n  waypoints:\n  - [0.1, 0.0, 0.0]\n  - [0.4, 0.0, 0.0]\n")
    timing = tmp_path / "timing.yaml"
    timing.write_text("reached_waypoint_timing:\n- p0: 0.5\n- p1: 1.5\n- p2: 5.0\n")
    args = [str(bag), "--goal", str(goal), "--reached", "timing", str(timing), "--2015"]
    code, out, err = _score(args, capsys)
    assert code == 0, err
    assert "--2015: the 2015 node read the marker set from /tf world -> robot_at_home" in err
    # x at 1.5 s and 5.0 s of the 6 s ramp to 0.5 m: 0.125 and 0.41667 m; errors 0.025, 0.0167.
    assert out["position_accuracy"] == pytest.approx((0.025 + 0.5 * 5 / 6 - 0.4) / 2, abs=1e-6)
