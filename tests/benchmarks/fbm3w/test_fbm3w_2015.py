"""``--2015`` against the 2015 node's arithmetic, re-implemented here as plain loops.

The re-implementation follows ``scripts/fbm3w`` of rockin-robot-challenge/
benchmark_and_scoring_fbm at 50b173b (RoCKIn 2015; its statement-by-statement replay over the
BmBox is ``node_fbm3w.py``, on every path in ``test_fbm3w_node_paths.py``) and seed 7.3: per
run the reference is the latest pose when the manual operation completed; the node subscribed
to the pose2d topic from ``SendGoal`` (BmBox EXECUTING_GOAL) until ``WaitResult`` returned
(BmBox leaving WAITING_RESULT) and kept a pose when it lay at least D_MIN from the last kept
one; the run frame has its origin at the first kept pose and its x axis along reference ->
start; Eq. (1) averages the distances to the shape at l_i / L over the N kept poses. ``if
benchmark.Timeout()`` only prints, before ``if not benchmark.Running(): continue``: a run the
RefBox timed out is scored on what it covered and timed, a stopped run neither. Nothing here
calls ertools' scoring code; ertools only reads the bag (the reader is tested elsewhere).
"""

from __future__ import annotations

import itertools
import json
import math
from typing import Any

import numpy as np
import pytest

from ertools.benchmarks.fbm3w.config import Fbm3wOptions, options_2015
from ertools.benchmarks.fbm3w.pipeline import score_paths
from ertools.benchmarks.fbm3w.runs import find_states
from ertools.benchmarks.fbm3w.settings import Fbm3wConfig
from ertools.cli.main import main
from ertools.geometry import quat_from_yaw
from ertools.io.model import BenchmarkStates
from ertools.io.reader import read_benchmark_states, read_poses
from ertools.simulator.writer import BagWriter
from ertools.states import BmBoxState as B
from ertools.states import Machine
from ertools.states import RefBoxState as R
from ertools.streams import PoseStream
from tests.benchmarks.fbm3w.fbm3w_kit import Sample
from tests.benchmarks.fbm3w.fbm3w_synth import place
from tests.benchmarks.fbm3w.test_fbm3w_runs import stream

S = 1_000_000_000
D_MIN = 0.00033  # seed 7.3.4: hard-coded in the 2015 script
TOL = 1e-12  # float rounding of the same formulas summed in another order
# the 2015 node's numbers are the subject here, not the intervals: no Monte Carlo draws
NO_DRAWS = ("score", "fbm3w", "--draws", "0")


# Seed Listing 15 (the Lisbon 2015 shapes), l in [0, 1].
def line_path(u: float) -> tuple[float, float]:
    return 0.15 * u, 0.045 * u


def sine(u: float) -> tuple[float, float]:
    return 0.15 * u, 0.075 * math.sin(12.5 * math.pi * 0.15 * u)


SHAPES = {"line": line_path, "spline": sine}

Transitions = list[tuple[int, int, str]]


def distance_error(
    t: list[int],
    xy: list[tuple[float, float]],
    ref_t: int,
    start_t: int,
    end_t: int,
    spec: str,
) -> float:
    """Eq. (1) of one run: the reference is the latest pose at ``ref_t``; the path the poses
    received in [start_t, end_t] kept by ``mocap_callback`` (D_MIN from the last kept one);
    the run frame at the first kept pose with x along reference -> start; the shape at l/L."""
    ref = [p for tt, p in zip(t, xy, strict=True) if tt <= ref_t][-1]
    path = [p for tt, p in zip(t, xy, strict=True) if start_t <= tt <= end_t]
    kept = [path[0]]
    for p in path[1:]:  # mocap_callback
        if math.sqrt((p[0] - kept[-1][0]) ** 2 + (p[1] - kept[-1][1]) ** 2) >= D_MIN:
            kept.append(p)
    ox, oy = kept[0]
    yaw = math.atan2(oy - ref[1], ox - ref[0])
    c, s = math.cos(yaw), math.sin(yaw)
    frame = [(c * (x - ox) + s * (y - oy), -s * (x - ox) + c * (y - oy)) for x, y in kept]
    lengths = [0.0]
    for a, b in itertools.pairwise(frame):
        lengths.append(lengths[-1] + math.sqrt((b[0] - a[0]) ** 2 + (b[1] - a[1]) ** 2))
    shape = SHAPES[spec]
    err = 0.0
    for p, li in zip(frame, lengths, strict=True):
        tx, ty = shape(li / lengths[-1])
        err += math.sqrt((p[0] - tx) ** 2 + (p[1] - ty) ** 2)
    return err / len(kept)


def node_2015(
    t: list[int],
    xy: list[tuple[float, float]],
    bmbox: Transitions,
    refbox: Transitions,
    specs: list[str],
) -> dict[str, Any]:
    """What the 2015 node would have computed from these messages (plain Python)."""
    # BmBox.py compares the RefBox payload whole: Timeout() is == "reason: timeout" (l. 117),
    # Running() is != "reason: stop" (l. 126); any other END payload changed nothing.
    end_t, end_payload = None, ""
    for tt, state, payload in refbox:
        if state == R.END and payload in ("reason: timeout", "reason: stop"):
            end_t, end_payload = tt, payload
            break
    runs: list[dict[str, Any]] = []
    ref_t = start_t = None
    prev = None
    for tt, state, _ in bmbox:
        if state == prev:
            continue  # the 10 Hz heartbeat repeats the state
        if state == B.COMPLETED_MANUAL_OPERATION:
            ref_t = tt
        elif state == B.EXECUTING_GOAL and start_t is None:
            start_t = tt
        elif prev == B.WAITING_RESULT and start_t is not None:
            runs.append({"ref": ref_t, "start": start_t, "end": tt})
            start_t = None
        prev = state
    details: dict[int, dict[str, Any]] = {}
    total = 0.0
    for k, run in enumerate(runs):
        ended = end_t is not None and run["start"] <= end_t <= run["end"] + S
        if ended and end_payload == "reason: stop":
            break  # ``if not benchmark.Running(): continue``, then the loop ends
        total += (run["end"] - run["start"]) / 1e9
        details[k] = {
            "distance_error": distance_error(t, xy, run["ref"], run["start"], run["end"], specs[k]),
            "execution_time": (run["end"] - run["start"]) / 1e9,
        }
        if ended:
            break  # the benchmark is over after END: ``if not benchmark.Running(): break``
    best = None
    for k, d in details.items():
        if best is None or d["distance_error"] < details[best]["distance_error"]:
            best = k
    return {
        "best_run": best,
        "best_distance_error": None if best is None else details[best]["distance_error"],
        "execution_time": total,
        "runs": details,
    }


def _check(out: dict[str, Any], node: dict[str, Any]) -> None:
    assert out["best_run"] == node["best_run"]
    assert out["best_distance_error"] == pytest.approx(node["best_distance_error"], abs=TOL)
    assert out["execution_time"] == pytest.approx(node["execution_time"], abs=TOL)
    for k, d in node["runs"].items():
        got = out["runs_details"][str(k)]
        assert got["distance_error"] == pytest.approx(d["distance_error"], abs=TOL)
        assert got["execution_time"] == pytest.approx(d["execution_time"], abs=TOL)


@pytest.mark.slow
def test_sample_bag_2015_equals_the_node(
    fbm3w_sample: Sample, capsys: pytest.CaptureFixture[str]
) -> None:
    bag = fbm3w_sample.bag
    poses = read_poses(bag, "/fbm3w/robot_at_work/pose2d", time_source="record")
    states = read_benchmark_states(bag, "fbm3w")
    assert states.bmbox is not None and states.refbox is not None

    def transitions(s: Any) -> Transitions:
        return list(zip(s.t_ns.tolist(), s.state.tolist(), s.payload, strict=True))

    node = node_2015(
        poses.t_ns.tolist(),
        [tuple(p) for p in poses.xyz[:, :2].tolist()],
        transitions(states.bmbox),
        transitions(states.refbox),
        ["line", "spline", "line", "spline", "line"],
    )
    # The sample's RefBox ends run 4 mid-path with the seed's bare "timeout": to the 2015
    # BmBox no timeout, so the node scored and timed run 4 as it scores any run.
    assert 4 in node["runs"]
    assert main([*NO_DRAWS, str(bag), "--2015", "--format", "json"]) == 0
    captured = capsys.readouterr()
    out = json.loads(captured.out)
    _check(out, node)
    assert out["runs_details"]["4"]["status"] == "scored"
    assert "RefBox END with payload 'timeout', which is none of the forms" in captured.err
    # --timeout-runs 2015 alone reads the seed's word as the timeout it names (said), and
    # scores the timed-out run as 2015 did: the same numbers here (d_min already 0.00033).
    assert main([*NO_DRAWS, str(bag), "--timeout-runs", "2015", "--format", "json"]) == 0
    captured = capsys.readouterr()
    out = json.loads(captured.out)
    _check(out, node)
    assert out["runs_details"]["4"]["status"] == "timeout_scored"
    assert "as a timeout" in captured.err and "[all.end-payloads]" in captured.err
    # Default: the timed-out run has no distance_error, and the output says why.
    assert main([*NO_DRAWS, str(bag), "--format", "json"]) == 0
    captured = capsys.readouterr()
    assert json.loads(captured.out)["runs_details"]["4"]["distance_error"] is None
    assert "differs from 2015: a run the RefBox timed out" in captured.err
    # --exact-end-payloads alone: the END is no timeout, run 4 is an ordinary completed run.
    assert main([*NO_DRAWS, str(bag), "--exact-end-payloads", "--format", "json"]) == 0
    captured = capsys.readouterr()
    out = json.loads(captured.out)
    assert out["runs_details"]["4"]["status"] == "scored"
    assert out["runs_details"]["4"]["distance_error"] == pytest.approx(
        node["runs"][4]["distance_error"], abs=TOL
    )
    assert "[all.end-payloads]" not in captured.err


# --- simulated edge cases --------------------------------------------------------------------

HZ = 120


def _track(
    t0_s: float,
    spec: str,
    *,
    reach: float,
    path_s: float,
    offset: float,
    origin: tuple[float, float],
    yaw: float,
    rng: np.random.Generator,
) -> tuple[np.ndarray, np.ndarray]:
    """One run's poses (times s, world xy): still at the reference until t0+2, to the start by
    t0+3, along the shape (shifted ``offset`` sideways) to the fraction ``reach`` in
    ``path_s``, then still until t0+10; 0.05 mm of noise per axis."""
    t = t0_s + np.arange(0, 10 * HZ) / HZ
    tau = t - t0_s
    shape = SHAPES[spec]
    pts = np.empty((len(t), 2))
    for i, a in enumerate(tau.tolist()):
        if a < 2.0:
            pts[i] = (-0.05, 0.0)
        elif a < 3.0:
            pts[i] = (-0.05 * (3.0 - a), 0.0)
        else:
            f = min((a - 3.0) / path_s, 1.0)
            u = reach * (10 * f**3 - 15 * f**4 + 6 * f**5)  # minimum jerk
            x, y = shape(u)
            pts[i] = (x, y + offset * min(u * 20, 1.0))
    pts += rng.normal(0.0, 5e-5, pts.shape)
    return t, place(pts, origin, yaw)


def _scenario(
    runs: list[dict[str, Any]], refbox_end: tuple[float, str] | None, seed: int
) -> tuple[PoseStream, BenchmarkStates, Transitions, Transitions]:
    rng = np.random.default_rng(seed)
    ts, xys = [], []
    items: list[tuple[float, int, str]] = [(0.0, B.READY, "")]
    for k, run in enumerate(runs):
        t0 = 1.0 + 12.0 * k
        t, xy = _track(t0, run["spec"], rng=rng, **run["track"])
        ts.append(t)
        xys.append(xy)
        items += [
            (t0, B.WAITING_MANUAL_OPERATION, ""),
            (t0 + 1.0, B.COMPLETED_MANUAL_OPERATION, ""),
            (t0 + 1.5, B.TRANSMITTING_GOAL, run["spec"]),
            (t0 + 3.0, B.EXECUTING_GOAL, ""),
            (t0 + 3.05, B.WAITING_RESULT, ""),
        ]
        if run.get("end_at") is not None:
            items.append((run["end_at"] + 0.1, B.END, ""))
            break
        items.append((t0 + 9.0, B.READY, ""))
    rb_items: list[tuple[float, int, str]] = [(0.0, R.READY, "")]
    if refbox_end is not None:
        rb_items.append((refbox_end[0], R.END, refbox_end[1]))
    bm = stream(Machine.BMBOX, items)
    rb = stream(Machine.REFBOX, rb_items)
    t_all = np.round(np.concatenate(ts) * S).astype(np.int64)
    xy_all = np.vstack(xys)
    n = len(t_all)
    poses = PoseStream(
        t_all,
        np.column_stack([xy_all, np.full(n, 0.8)]),
        quat_from_yaw(np.zeros(n)),
        "world",
        "robot_at_work",
        "sim",
    )

    def tr(s: Any) -> Transitions:
        return list(zip(s.t_ns.tolist(), s.state.tolist(), s.payload, strict=True))

    return poses, BenchmarkStates(bm, rb, None), tr(bm), tr(rb)


def _ertools(poses: PoseStream, states: BenchmarkStates, options: Fbm3wOptions) -> dict[str, Any]:
    windows = find_states(states, exact_2015=options.exact_end_payloads)
    data: dict[str, Any] = score_paths(poses, windows, Fbm3wConfig(), options=options).to_dict()
    return data


def _node(poses: PoseStream, bm: Transitions, rb: Transitions, specs: list[str]) -> dict[str, Any]:
    return node_2015(
        poses.t_ns.tolist(), [tuple(p) for p in poses.xyz[:, :2].tolist()], bm, rb, specs
    )


# The frame yaws straddle the +-pi seam: reference just right of the start (above / below).
SEAM = (math.pi - 0.01, -math.pi + 0.01)


@pytest.mark.slow_cases("-3.1315926535897933")
@pytest.mark.parametrize("yaw", SEAM)
def test_run_timing_out_midway_is_scored_and_can_be_best(yaw: float) -> None:
    common = {"path_s": 3.0, "origin": (1.2, 0.7), "yaw": yaw}
    runs = [
        # (specs as in Listing 14, which the node read: line, spline, ...)
        # 10 cm off the line all along: about 90 mm of error.
        {"spec": "line", "track": {"reach": 1.0, "offset": 0.1, **common}},
        # Timed out at 60 % of the sine: compared at l/L with the whole sine it is tens of mm
        # off, still the best run for 2015.
        {"spec": "spline", "track": {"reach": 0.6, "offset": 0.0003, **common}, "end_at": 19.0},
    ]
    poses, states, bm, rb = _scenario(runs, (19.0, "reason: timeout"), seed=3)
    node = _node(poses, bm, rb, ["line", "spline"])
    assert node["best_run"] == 1 and set(node["runs"]) == {0, 1}
    assert 0.02 < node["runs"][1]["distance_error"] < 0.08 < node["runs"][0]["distance_error"]
    out = _ertools(poses, states, options_2015(Fbm3wOptions()))
    _check(out, node)
    assert out["runs_details"]["1"]["status"] == "timeout_scored"
    # ertools' default: the timed-out run is unscored, so run 0 is best; its time still counts.
    default = _ertools(poses, states, Fbm3wOptions())
    assert default["best_run"] == 0
    assert default["runs_details"]["1"]["distance_error"] is None
    assert default["execution_time"] == pytest.approx(node["execution_time"], abs=TOL)


@pytest.mark.slow
def test_stopped_run_is_neither_scored_nor_timed() -> None:
    common = {"path_s": 4.0, "origin": (-0.4, 1.1), "yaw": 2.0}
    runs = [
        {"spec": "line", "track": {"reach": 1.0, "offset": 0.001, **common}},
        {"spec": "spline", "track": {"reach": 0.5, "offset": 0.0002, **common}, "end_at": 20.0},
    ]
    poses, states, bm, rb = _scenario(runs, (20.0, "reason: stop"), seed=4)
    node = _node(poses, bm, rb, ["line", "spline"])
    assert set(node["runs"]) == {0}
    out = _ertools(poses, states, options_2015(Fbm3wOptions()))
    _check(out, node)
    assert out["runs_details"]["1"]["status"] == "stopped"
    assert out["runs_details"]["1"]["distance_error"] is None
    # --stopped-runs 2015 alone leaves the stopped run's 7 s out; the default counts them.
    alone = _ertools(poses, states, Fbm3wOptions(stopped_runs="2015"))
    assert alone["execution_time"] == pytest.approx(node["execution_time"], abs=TOL)
    default = _ertools(poses, states, Fbm3wOptions())
    stopped_s = out["runs_details"]["1"]["execution_time"]
    assert stopped_s == pytest.approx(20.1 - 16.0, abs=1e-9)  # EXECUTING_GOAL to BmBox END
    assert default["execution_time"] == pytest.approx(node["execution_time"] + stopped_s, abs=TOL)


@pytest.mark.slow
def test_2015_and_arc_length_contradict(
    fbm3w_sample: Sample, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["score", "fbm3w", str(fbm3w_sample.bag), "--2015", "--arc-length"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("ertools: error:") and "--arc-length" in err


def test_frozen_reference_pose_is_warned() -> None:
    common = {"path_s": 3.0, "origin": (0.3, 0.2), "yaw": 0.5}
    runs = [{"spec": "line", "track": {"reach": 1.0, "offset": 0.0, **common}}]
    poses, states, _, _ = _scenario(runs, None, seed=11)
    windows = find_states(states)
    assert windows[0].ref_ns == 2 * S  # COMPLETED_MANUAL_OPERATION at 2.0 s
    # The marker set is lost from 1.5 s to 2.5 s: Motive repeats the pose of 1.5 s.
    a, b = np.searchsorted(poses.t_ns, [round(1.5 * S), round(2.5 * S)])
    xyz = poses.xyz.copy()
    xyz[a:b] = xyz[a]
    frozen = PoseStream(poses.t_ns, xyz, poses.quat_xyzw, "world", "robot_at_work", "sim")
    result = score_paths(frozen, windows, Fbm3wConfig(), bag_start_ns=0)
    lines = [w for w in result.warnings if "frozen" in w]
    assert len(lines) == 1
    assert lines[0].startswith("run 0: the pose at its reference time 2.000 s is frozen")
    assert f"{b - a} identical poses" in lines[0] and "(1.500-2.492 s" in lines[0]
    # Unfrozen, nothing is said.
    plain = score_paths(poses, windows, Fbm3wConfig(), bag_start_ns=0)
    assert not [w for w in plain.warnings if "frozen" in w]


@pytest.mark.slow
def test_2015_uses_the_script_d_min_over_the_config(
    fbm3w_sample: Sample, tmp_path: Any, capsys: pytest.CaptureFixture[str]
) -> None:
    config = tmp_path / "fbm3w.yaml"
    config.write_text("runs_specifications: [line, spline, line, spline, line]\nd_min: 0.001\n")
    argv = [*NO_DRAWS, str(fbm3w_sample.bag), "--config", str(config), "--format", "json"]
    assert main(argv) == 0
    assert json.loads(capsys.readouterr().out)["runs_details"]["0"]["d_min"] == 0.001
    assert main([*argv, "--2015"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert {r["d_min"] for r in out["runs_details"].values()} == {D_MIN}
    # --d-min still wins, and is then a deviation.
    assert main([*argv, "--2015", "--d-min", "0.0005"]) == 0
    captured = capsys.readouterr()
    assert json.loads(captured.out)["runs_details"]["0"]["d_min"] == 0.0005
    assert "differs from 2015: d_min = 0.0005 m" in captured.err


def test_stopped_run_from_a_bag_with_the_cli(
    tmp_path: Any, capsys: pytest.CaptureFixture[str]
) -> None:
    common = {"path_s": 4.0, "origin": (0.9, -0.3), "yaw": -1.2}
    runs = [
        {"spec": "line", "track": {"reach": 1.0, "offset": 0.002, **common}},
        {"spec": "spline", "track": {"reach": 0.4, "offset": 0.0, **common}, "end_at": 19.5},
    ]
    poses, states, bm, rb = _scenario(runs, (19.5, "reason: stop"), seed=13)
    assert states.bmbox is not None and states.refbox is not None
    bag = tmp_path / "stopped.bag"
    epoch = 1_448_020_800 * S  # the log's clock: the scenario's seconds from this epoch
    with BagWriter(bag) as w:
        w.write_pose2d(
            "/fbm3w/robot_at_work/pose2d",
            poses.t_ns + epoch,
            poses.xyz[:, 0],
            poses.xyz[:, 1],
            np.zeros(len(poses)),
        )
        for s, topic in ((states.bmbox, "bmbox_state"), (states.refbox, "refbox_state")):
            w.write_state(
                s.machine, f"/fbm3w/{topic}", s.t_ns + epoch, list(s.state), list(s.payload)
            )
    node = _node(poses, bm, rb, ["line", "spline"])
    argv = [*NO_DRAWS, str(bag), "--format", "json"]
    assert main([*argv, "--stopped-runs", "2015"]) == 0
    captured = capsys.readouterr()
    _check(json.loads(captured.out), node)
    assert "fbm3w.stopped-runs" not in captured.err
    assert main(argv) == 0
    captured = capsys.readouterr()
    out = json.loads(captured.out)
    assert out["execution_time"] == pytest.approx(node["execution_time"] + (19.6 - 16.0), abs=1e-9)
    assert "[fbm3w.stopped-runs]" in captured.err and "--stopped-runs 2015 restores" in captured.err
