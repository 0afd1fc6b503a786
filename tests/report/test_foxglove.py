"""``--foxglove FILE.mcap``: the sample scores written for Foxglove and read back.

Every file is read with the ``mcap`` reader and decoded with the schemas it carries
(:mod:`foxglove_readback`). Expected counts and values come from the score printed on stdout
(JSON), the sample's config files and, for the trajectory's robot stamps, the bag read with
rosbags: not from the writer.

Counts: no stream of these samples reaches the writer's limit (50 000 messages), so every
robot pose, compared pose and kept point has its message; the GT pose stream is the result's
GT path (decimated to about 5000 poses by the scorer), counted from the result object.
"""

from __future__ import annotations

import hashlib
import json
import math
import shutil
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml
from rosbags.highlevel import AnyReader

from ertools.benchmarks import registry
from ertools.benchmarks.scoring import score_execution
from ertools.cli.main import main
from ertools.report.foxglove.write import write_foxglove
from tests.helpers.foxglove_readback import ReadBack, read_back, stamp_ns
from tests.helpers.stderr_text import error_messages

SAMPLES = Path(__file__).resolve().parents[2] / "sample_bags"
FBM3W = SAMPLES / "fbm3w" / "log_fbm3w_mocap_2015-11-20-12-00-00_0.bag"
FBM2H = SAMPLES / "fbm2h" / "log_fbm2h_mocap_2015-11-20-12-00-00_0.bag"
FBM2H_ARGS = [
    "--goal",
    str(SAMPLES / "fbm2h" / "fbm2h_goal.yaml"),
    "--transform",
    str(SAMPLES / "fbm2h" / "transform-simbot.yaml"),
]
FBM1H = SAMPLES / "fbm1h" / "log_fbm1h_2015-11-20-12-00-00_0.bag"
ROBOT = SAMPLES / "robotlog" / "FBM2H_201511201200_homer.bag"
ROBOT_TOPIC = "/rockin/homer/marker_pose"

NS = 1_000_000_000
EXACT = 1e-12  # the same float64 sums, in another order: round-off only


def run_json(argv: list[str], capsys: pytest.CaptureFixture[str]) -> dict[str, Any]:
    assert main([*argv, "--format", "json"]) == 0
    cap = capsys.readouterr()
    assert "wrote " in cap.err and "Traceback" not in cap.err
    data: dict[str, Any] = json.loads(cap.out)
    return data


def check_common(fg: ReadBack, expected: dict[str, str], score: dict[str, Any]) -> None:
    """Topics and schema names as documented, counts as the summary says, times in order."""
    assert {t: x.schema_name for t, x in fg.topics.items()} == expected
    for topic, x in fg.topics.items():
        assert fg.counts[topic] == len(x.messages) > 0, topic
        if x.schema_name.startswith("foxglove."):
            assert (x.schema_encoding, x.message_encoding) == ("protobuf", "protobuf")
        else:  # ertools' own JSON topics: every field of every message is in the schema
            assert (x.schema_encoding, x.message_encoding) == ("jsonschema", "json")
            props = set(x.schema["properties"])
            assert all(set(m) <= props for m in x.messages), topic
    assert fg.file_times == sorted(fg.file_times)  # written in log-time order
    for x in fg.topics.values():  # a message's own stamp is its log time
        for t, m in zip(x.times, x.messages, strict=True):
            if hasattr(m, "timestamp"):
                assert stamp_ns(m) == t
    # The score itself travels in the file's metadata, as printed.
    assert json.loads(fg.metadata["ertools"]["score"]) == score


# --- FBM3W ------------------------------------------------------------------------------------


@pytest.mark.slow
def test_fbm3w(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "deep" / "fbm3w.mcap"  # parent folders are created
    score = run_json(["score", "fbm3w", str(FBM3W), "--foxglove", str(out)], capsys)
    fg = read_back(out)
    check_common(
        fg,
        {
            "/fbm3w/runs": "foxglove.SceneUpdate",
            "/fbm3w/errors": "ertools.Fbm3wPointError",
            "/fbm3w/scores": "ertools.Fbm3wRun",
            "/ertools/log": "foxglove.Log",
        },
        score,
    )
    runs = score["runs_details"]
    scored = {int(k): v for k, v in runs.items() if v["status"] == "scored"}
    assert len(scored) == 4 and len(runs) == 5  # the sample: one run times out
    scenes = fg.topics["/fbm3w/runs"]
    errors = fg.topics["/fbm3w/errors"]
    scores = fg.topics["/fbm3w/scores"]
    assert len(scenes.messages) == len(scored)
    assert len(scores.messages) == len(runs)
    assert len(errors.messages) == sum(v["kept_samples"] for v in scored.values())
    starts = dict(zip([m.entities[0].id for m in scenes.messages], scenes.times, strict=True))
    ends = {m["run"]: t for m, t in zip(scores.messages, scores.times, strict=True)}
    for i, d in scored.items():
        pts = [(m, t) for m, t in zip(errors.messages, errors.times, strict=True) if m["run"] == i]
        e = [m["error"] for m, _ in pts]
        assert len(e) == d["kept_samples"]
        # Eq. (1): the mean over the N kept points, the start counting with error 0.
        assert e[0] == 0.0 and math.fsum(e) / len(e) == pytest.approx(
            d["distance_error"], abs=EXACT
        )
        assert pts[-1][0]["l_norm"] == pytest.approx(1.0, abs=EXACT)
        # The points lie in the run's path window: from its scene (start) to its score (end).
        start, end = starts[f"run {i}"], ends[i]
        assert (end - start) / NS == pytest.approx(d["execution_time"], abs=1e-9)
        assert all(start <= t <= end for _, t in pts)
        assert [t for _, t in pts] == sorted(t for _, t in pts)
    for m in scores.messages:
        assert m["distance_error"] == runs[str(m["run"])]["distance_error"]
    # The scene: the red pairs start at the starting position (the start is compared with the
    # target's start, error 0), the label gives the score, a run lasts until the next starts.
    ordered = sorted(scored)
    for k, m in enumerate(scenes.messages):
        i = ordered[k]
        (ent,) = m.entities
        assert ent.frame_id == "world" and ent.id == f"run {i}"
        _target, path, pairs = ent.lines
        p0, q0 = pairs.points[0], pairs.points[1]
        sx, sy = scored[i]["starting_position"]
        assert (p0.x, p0.y) == pytest.approx((sx, sy), abs=EXACT)
        assert (q0.x, q0.y) == pytest.approx((sx, sy), abs=EXACT)
        assert len(pairs.points) == 2 * scored[i]["kept_samples"]
        assert len(path.points) == scored[i]["samples"]
        # Each pair's length is that point's error.
        pp = np.array([(p.x, p.y) for p in pairs.points])
        lengths = np.hypot(*(pp[0::2] - pp[1::2]).T)
        mine = [x["error"] for x in errors.messages if x["run"] == i]
        assert lengths == pytest.approx(mine, abs=1e-12)
        assert f"{scored[i]['distance_error'] * 1000:.3f} mm" in ent.texts[0].text
        # It lasts until the next run's path starts (scored or not; start_time in us).
        later = [v["start_time"] for j, v in runs.items() if int(j) > i and v["start_time"]]
        life = ent.lifetime.seconds * NS + ent.lifetime.nanos
        want = (later[0] - scored[i]["start_time"]) if later else 0.0
        assert life / NS == pytest.approx(want, abs=1e-6)
    logs = [m.message for m in fg.topics["/ertools/log"].messages]
    assert any(f"best run {score['best_run']}" in x for x in logs)


# --- FBM2H ------------------------------------------------------------------------------------


@pytest.mark.slow
def test_fbm2h(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "fbm2h.mcap"
    score = run_json(["score", "fbm2h", str(FBM2H), *FBM2H_ARGS, "--foxglove", str(out)], capsys)
    fg = read_back(out)
    check_common(
        fg,
        {
            "/fbm2h/robot": "foxglove.PoseInFrame",
            "/fbm2h/robot_path": "foxglove.PosesInFrame",
            "/fbm2h/waypoints": "foxglove.SceneUpdate",
            "/fbm2h/reached": "foxglove.SceneUpdate",
            "/fbm2h/segments": "ertools.Fbm2hSegment",
            "/ertools/log": "foxglove.Log",
        },
        score,
    )
    goal = yaml.safe_load((SAMPLES / "fbm2h" / "fbm2h_goal.yaml").read_text())["goal"]
    (wp,) = fg.topics["/fbm2h/waypoints"].messages
    assert len(wp.entities) == len(goal["waypoints"]) == 5
    for ent, (x, y, th) in zip(wp.entities, goal["waypoints"], strict=True):
        a = ent.arrows[0].pose
        assert (a.position.x, a.position.y) == (x, y)
        assert 2 * math.atan2(a.orientation.z, a.orientation.w) == pytest.approx(th, abs=EXACT)
    # The robot path: as many poses as the result's (decimated) path holds.
    values = {"goal": Path(FBM2H_ARGS[1]), "transform": Path(FBM2H_ARGS[3])}
    result = score_execution(registry.get("fbm2h"), [FBM2H], values).result
    robot = fg.topics["/fbm2h/robot"]
    assert robot.times == result.path_t_ns.tolist()
    assert len(fg.topics["/fbm2h/robot_path"].messages[0].poses) == len(result.path_t_ns)
    segs = score["details"]["segments_details"]
    reached = fg.topics["/fbm2h/reached"]
    ok = [s for s in segs.values() if s["dinstance_error"] is not None]
    assert len(reached.messages) == len(ok) == 5
    for m, t, s in zip(reached.messages, reached.times, ok, strict=True):
        (ent,) = m.entities
        a = ent.arrows[0].pose.position
        rp, tp = s["robot_pose"], s["target_pose"]
        assert (a.x, a.y) == (rp["x"], rp["y"])
        p, q = ent.lines[0].points
        assert math.hypot(p.x - q.x, p.y - q.y) == pytest.approx(s["dinstance_error"], abs=EXACT)
        assert (q.x, q.y) == (tp["x"], tp["y"])
        assert t / NS == pytest.approx(s["end_segment_time"], abs=1e-6)
    rows = fg.topics["/fbm2h/segments"].messages
    assert [r["distance_error"] for r in rows] == [s["dinstance_error"] for s in segs.values()]
    mean = math.fsum(r["distance_error"] for r in rows) / len(rows)
    assert mean == pytest.approx(score["position_accuracy"], abs=EXACT)


# --- FBM1 -------------------------------------------------------------------------------------


def test_fbm1h(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "fbm1h.mcap"
    items = str(SAMPLES / "fbm1h" / "fbm1h.yaml")
    score = run_json(
        ["score", "fbm1h", str(FBM1H), "--items", items, "--foxglove", str(out)], capsys
    )
    fg = read_back(out)
    check_common(
        fg,
        {
            "/fbm1h/items": "foxglove.SceneUpdate",
            "/fbm1h/runs": "ertools.Fbm1Run",
            "/ertools/log": "foxglove.Log",
        },
        score,
    )
    runs = score["runs"]
    shown = [r for r in runs.values() if "ground_truth" in r or "answer" in r]
    scenes = fg.topics["/fbm1h/items"].messages
    assert len(scenes) == len(shown) and len(fg.topics["/fbm1h/runs"].messages) == len(runs) == 10
    for m, r in zip(scenes, shown, strict=True):
        (ent,) = m.entities
        assert ent.frame_id == "table"
        arrows = list(ent.arrows)
        if "ground_truth" in r:
            g = arrows.pop(0).pose.position
            gt = r["ground_truth"]
            assert (g.x, g.y, g.z) == (gt["x"], gt["y"], gt["z"])
        if "answer" in r:
            a = arrows.pop(0).pose
            ans = r["answer"]
            assert (a.position.x, a.position.y) == (ans["x"], ans["y"])
            yaw = 2 * math.atan2(a.orientation.z, a.orientation.w)
            assert math.degrees(yaw) == pytest.approx(ans["theta"], abs=1e-9)
    rows = fg.topics["/fbm1h/runs"].messages
    for row in rows:
        r = runs[str(row["run"])]
        assert row["pose_score"] == r.get("pose_score")
        assert row["translation_error"] == r.get("error", {}).get("translation")
    # The 2015 pose score: the mean over the counted runs (a run without answer scores 0).
    counted = [row["pose_score"] for row in rows if row["pose_score"] is not None]
    assert len(counted) == score["counted_runs"]["pose"]
    assert math.fsum(counted) / len(counted) == pytest.approx(score["pose_score"], abs=EXACT)


# --- trajectory -------------------------------------------------------------------------------


def _stamps(path: Path, topic: str) -> list[int]:
    out = []
    with AnyReader([path]) as reader:
        conns = [c for c in reader.connections if c.topic == topic]
        for conn, _t, raw in reader.messages(connections=conns):
            s = reader.deserialize(raw, conn.msgtype).header.stamp
            out.append(s.sec * NS + s.nanosec)
    return out


@pytest.mark.slow
def test_trajectory(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "trajectory.mcap"
    argv = ["score", "trajectory", str(ROBOT), str(ROBOT.parent), "--offset", "auto"]
    score = run_json([*argv, "--apply-offset", "--foxglove", str(out)], capsys)
    fg = read_back(out)
    check_common(
        fg,
        {
            "/trajectory/gt": "foxglove.PoseInFrame",
            "/trajectory/robot": "foxglove.PoseInFrame",
            "/trajectory/gt_path": "foxglove.PosesInFrame",
            "/trajectory/robot_path": "foxglove.PosesInFrame",
            "/trajectory/pairs": "foxglove.SceneUpdate",
            "/trajectory/errors": "ertools.TrajectoryError",
            "/ertools/log": "foxglove.Log",
        },
        score,
    )
    robot = fg.topics["/trajectory/robot"]
    errors = fg.topics["/trajectory/errors"]
    # Every robot pose, at its stamp (read with rosbags) plus the offset the score applied.
    stamps = _stamps(ROBOT, ROBOT_TOPIC)
    assert len(robot.messages) == score["robot_poses"] == len(stamps)
    shift = {t - s for t, s in zip(robot.times, stamps, strict=True)}
    assert shift == {round(score["offset"] * NS)}
    assert all(m.frame_id == "world" for m in robot.messages)
    # Every compared pose has its error; their mean is the score.
    assert len(errors.messages) == score["compared"] == 363
    pe = [m["position_error"] for m in errors.messages]
    assert math.fsum(pe) / len(pe) == pytest.approx(score["position_error"], abs=EXACT)
    ye = np.array([m["yaw_error"] for m in errors.messages])
    orient = math.atan2(math.fsum(np.sin(ye)), math.fsum(np.cos(ye)))
    assert orient == pytest.approx(score["orientation_error"], abs=EXACT)
    assert set(errors.times) <= set(robot.times)
    # The pairs: one line per compared pose, as long as its error.
    (scene,) = fg.topics["/trajectory/pairs"].messages
    pts = np.array([(p.x, p.y, p.z) for p in scene.entities[0].lines[0].points])
    assert len(pts) == 2 * score["compared"]
    assert np.linalg.norm(pts[0::2] - pts[1::2], axis=1) == pytest.approx(pe, abs=1e-12)
    # The GT poses: the result's GT path (the scorer's decimation), same config as the CLI.
    values = {"offset": "auto", "apply_offset": True}
    result = score_execution(registry.get("trajectory"), [ROBOT, ROBOT.parent], values).result
    gt = fg.topics["/trajectory/gt"]
    assert gt.times == result.gt_path.t_ns.tolist()
    assert len(fg.topics["/trajectory/gt_path"].messages[0].poses) == len(result.gt_path)
    assert len(fg.topics["/trajectory/robot_path"].messages[0].poses) == len(stamps)
    assert [m.pose.position.x for m in gt.messages] == result.gt_path.xyz[:, 0].tolist()


@pytest.mark.slow
def test_trajectory_streams_over_the_limit_are_decimated(tmp_path: Path) -> None:
    result = score_execution(registry.get("trajectory"), [ROBOT, ROBOT.parent], {}).result
    n, compared = len(result.matched.t_ns), result.compared
    written = write_foxglove(result, tmp_path / "t.mcap", limit=100)
    fg = read_back(tmp_path / "t.mcap")
    # Every k-th, k = ceil(n / 100): 381 robot poses -> k = 4 -> 96 messages.
    k = math.ceil(n / 100)
    assert len(fg.topics["/trajectory/robot"].messages) == len(range(0, n, k)) <= 100
    assert len(fg.topics["/trajectory/errors"].messages) == len(
        range(0, compared, math.ceil(compared / 100))
    )
    assert written.counts == fg.counts
    logs = [m.message for m in fg.topics["/ertools/log"].messages]
    assert any("decimated" in x and "not the score exactly" in x for x in logs)


# --- audit ------------------------------------------------------------------------------------


@pytest.mark.slow
def test_audit_of_fbm2h(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "audit.mcap"
    data = run_json(["audit", str(FBM2H), *FBM2H_ARGS, "--foxglove", str(out)], capsys)
    fg = read_back(out)
    assert fg.topics["/audit/states"].schema_name == "foxglove.Log"
    assert fg.topics["/audit/runs"].schema_name == "ertools.AuditRun"
    # The recomputed FBM2H score's own topics are there too.
    for topic in ("/fbm2h/robot", "/fbm2h/waypoints", "/fbm2h/reached", "/fbm2h/segments"):
        assert topic in fg.topics
    states = fg.topics["/audit/states"]
    assert len(states.messages) == len(data["timeline"]) == 51
    t0 = min(states.times)
    for m, t, e in zip(states.messages, states.times, data["timeline"], strict=True):
        assert m.name == e["machine"] and m.message.split(":")[0] == e["state"]
        assert (t - t0) / NS == pytest.approx(e["start"], abs=1e-6)
    assert len(fg.topics["/audit/runs"].messages) == len(data["runs"]) == 5
    assert fg.file_times == sorted(fg.file_times)
    # The default text output writes the same file.
    text = tmp_path / "audit_text.mcap"
    assert main(["audit", str(FBM2H), *FBM2H_ARGS, "--foxglove", str(text)]) == 0
    assert f"wrote {text}" in capsys.readouterr().err
    assert read_back(text).counts == fg.counts


# --- bad input --------------------------------------------------------------------------------


def _one_error(argv: list[str], code: int, capsys: pytest.CaptureFixture[str]) -> str:
    assert main(argv) == code
    err = capsys.readouterr().err
    lines = error_messages(err)
    assert len(lines) == 1 and "Traceback" not in err, err
    return lines[0]


@pytest.mark.slow
def test_unwritable_path(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    blocker = tmp_path / "file"
    blocker.write_text("not a folder")
    out = blocker / "fbm3w.mcap"
    line = _one_error(["score", "fbm3w", str(FBM3W), "--foxglove", str(out)], 1, capsys)
    assert str(blocker) in line


def _digest(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def test_output_equal_to_an_input_is_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    bag = tmp_path / FBM3W.name
    shutil.copy(FBM3W, bag)
    before = _digest(bag)
    line = _one_error(["score", "fbm3w", str(bag), "--foxglove", str(bag)], 2, capsys)
    assert "--foxglove" in line and "that is an input" in line
    assert _digest(bag) == before


def test_output_equal_to_a_file_inside_an_input_folder_is_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # The GT folder is the input; the GT file chosen inside it is named only by the result.
    gt_dir = tmp_path / "robotlog"
    shutil.copytree(SAMPLES / "robotlog", gt_dir)
    robot = gt_dir / ROBOT.name
    gt_file = sorted(gt_dir.glob("log_fbm2h_mocap_*_0.bag"))[0]
    before = _digest(gt_file)
    argv = ["score", "trajectory", str(robot), str(gt_dir), "--foxglove", str(gt_file)]
    line = _one_error(argv, 2, capsys)
    assert str(gt_file) in line and "that is an input" in line
    assert _digest(gt_file) == before
