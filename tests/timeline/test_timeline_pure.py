"""The pure timeline on hand-made summaries: order, overlaps, sessions, pairing, checks."""

from __future__ import annotations

import json

import pytest

from ertools.io.clock import ClockCheck
from ertools.io.formats import Unreadable
from ertools.timelines.build import (
    benchmark_names,
    build_timeline,
    classify,
    coverage,
    logger_name,
    split_name,
)
from ertools.timelines.model import TimelineConfig
from tests.helpers.summaries import BAG_KEYS, Summary, Topic

S = 1_000_000_000
T0 = 1_448_013_600 * S


GT_TOPICS = (
    Topic("/fbm2h/robot_at_home/pose", "geometry_msgs/PoseStamped"),
    Topic("/fbm2h/robot_at_home/pose2d", "geometry_msgs/Pose2D"),
    Topic("/tf", "tf2_msgs/TFMessage"),
    Topic("/fbm2h/map", "nav_msgs/OccupancyGrid"),
    Topic("/rosout", "rosgraph_msgs/Log"),
)
BENCH_TOPICS = (
    Topic("/fbm2h/bmbox_state", "rockin_scoring/BmBoxState"),
    Topic("/fbm2h/robot_at_home/pose", "geometry_msgs/PoseStamped"),
)
ROBOT_TOPICS = (
    Topic("/rockin/homer/marker_pose", "geometry_msgs/PoseStamped"),
    Topic("/tf", "tf/tfMessage"),
)


def bag(path: str, a: float, b: float, topics: tuple[Topic, ...] = GT_TOPICS) -> Summary:
    return Summary(path, T0 + round(a * S), T0 + round(b * S), topics)


def test_classify() -> None:
    assert classify(GT_TOPICS) == "gt"
    assert classify(BENCH_TOPICS) == "benchmark"
    assert classify(ROBOT_TOPICS) == "robot"
    assert classify([Topic("/camera/image", "sensor_msgs/Image")]) == "other"
    assert classify([Topic("/tf", "tf2_msgs/TFMessage")]) == "gt"  # a tf-only mocap log
    ros2 = [Topic("/fbm3w/robot_at_work/pose", "geometry_msgs/msg/PoseStamped")]
    assert classify(ros2) == "gt"


def test_split_names_and_loggers() -> None:
    assert split_name("a/log_fbm2h_mocap_2015-10-23-16-15-40_0.bag") == (
        "log_fbm2h_mocap_2015-10-23-16-15-40",
        0,
    )
    assert split_name("log_x_12.bag.active") == ("log_x", 12)
    assert split_name("run_3.bag") is None  # not a rosbag split name
    assert split_name("TBMH1_201507240920_adams.bag") is None
    assert logger_name("log_fbm2h_mocap_2015-10-23-16-15-40_3.bag") == "log_fbm2h_mocap"
    assert logger_name("TBMH1_201507240920_adams.bag") == "TBMH1_201507240920_adams"


def test_coverage_by_hand() -> None:
    # Log 0-10 s, covers 2-4 and 3-6 (merged 2-6): 40 %, holes 0-2 and 6-10.
    pct, holes = coverage(0, 10 * S, [(3 * S, 6 * S), (2 * S, 4 * S)])
    assert pct == pytest.approx(40.0)
    assert holes == [(0, 2 * S), (6 * S, 10 * S)]
    # Covers 0.05 s apart join with join_ns = 0.1 s.
    pct, holes = coverage(0, 10 * S, [(0, 5 * S), (5 * S + S // 20, 10 * S)], S // 10)
    assert (pct, holes) == (100.0, [])


def test_order_overlaps_sessions_and_pairing() -> None:
    files = [
        bag("gt/log_m_2015-11-20-10-00-00_1.bag", 10.01, 20.0),
        bag("gt/log_m_2015-11-20-10-00-00_0.bag", 0.0, 10.0),
        bag("bench.bag", 5.0, 12.0, BENCH_TOPICS),
        bag("robot.bag", 18.0, 25.0, ROBOT_TOPICS),
        bag("gt/log_m_2015-11-20-10-00-00_3.bag", 100.0, 110.0),  # _2 is missing
    ]
    tl = build_timeline(files)
    assert [b.path for b in tl.bags] == [
        "gt/log_m_2015-11-20-10-00-00_0.bag",
        "bench.bag",
        "gt/log_m_2015-11-20-10-00-00_1.bag",
        "robot.bag",
        "gt/log_m_2015-11-20-10-00-00_3.bag",
    ]
    over = {b.path: set(b.overlaps) for b in tl.bags}
    assert over["bench.bag"] == {
        "gt/log_m_2015-11-20-10-00-00_0.bag",
        "gt/log_m_2015-11-20-10-00-00_1.bag",
    }
    assert over["gt/log_m_2015-11-20-10-00-00_0.bag"] == {"bench.bag"}
    assert over["gt/log_m_2015-11-20-10-00-00_3.bag"] == set()
    assert [len(s.paths) for s in tl.sessions] == [4, 1]
    pairs = {p.path: p for p in tl.pairings}
    # bench: 5-12 covered by 0-10 and 10.01-20 joined (10 ms < 0.1 s): 100 %.
    assert pairs["bench.bag"].coverage == pytest.approx(100.0)
    # robot: 18-25, GT up to 20: 2/7 covered, 20-25 uncovered.
    assert pairs["robot.bag"].coverage == pytest.approx(200 / 7)
    assert pairs["robot.bag"].uncovered == ((T0 + 20 * S, T0 + 25 * S),)
    problems = {(p.path, p.problem.split(" ")[0]) for p in tl.problems}
    assert ("gt/log_m_2015-11-20-10-00-00_3.bag", "split") in problems  # _2 missing
    gap = [p for p in tl.problems if "gap of" in p.problem]
    assert len(gap) == 1 and "gap of 80.000 s" in gap[0].problem


def test_clock_duplicates_unreadable_and_json_layout() -> None:
    files = [bag("a/x.bag", 0, 5), bag("b/x.bag", 1, 6), bag("c.bag", 10, 11)]
    checks = [
        ClockCheck("c.bag", "/p", 3_200_000_000, 50),
        ClockCheck("a/x.bag", "/p", 400_000_000, 50),  # under the 0.5 s default
    ]
    tl = build_timeline(files, [Unreadable("bad.bag", "truncated")], checks, TimelineConfig())
    d = tl.to_dict()
    assert list(d) == ["bags", "sessions", "problems"]
    keys = BAG_KEYS
    assert all(list(b) == keys for b in d["bags"])
    last = d["bags"][-1]
    assert (last["path"], last["start"], last["end"], last["kind"]) == (
        "bad.bag",
        None,
        None,
        "unreadable",
    )
    assert {"path": "bad.bag", "problem": "truncated"} in d["problems"]
    by = {b["path"]: b for b in d["bags"]}
    assert by["a/x.bag"]["start"] == pytest.approx(T0 / S)
    assert by["a/x.bag"]["duration"] == pytest.approx(5.0)
    assert any("duplicated file name (also b/x.bag)" in p for p in by["a/x.bag"]["problems"])
    assert any("+3.200 s" in p for p in by["c.bag"]["problems"])
    assert not any("header" in p for p in by["a/x.bag"]["problems"])


def test_empty_bag_is_listed_as_unreadable() -> None:
    empty = Summary("e.bag", 0, 0, (), message_count=0)
    tl = build_timeline([empty, bag("g.bag", 0, 1)])
    assert tl.readable_count == 1
    assert tl.bags[-1].path == "e.bag" and tl.bags[-1].start_ns is None


WORK_GT = (
    Topic("/fbm3w/robot_at_work/pose", "geometry_msgs/PoseStamped"),
    Topic("/tf", "tf2_msgs/TFMessage"),
)
WORK_BENCH = (
    Topic("/fbm3w/bmbox_state", "rockin_scoring/BmBoxState"),
    Topic("/fbm3w/refbox_state", "rockin_scoring/RefBoxState"),
)


def test_logs_pair_with_the_gt_of_their_own_benchmark() -> None:
    """Two arenas record at once: the @Work benchmark log overlaps both mocap loggers in time
    but its ground truth is the fbm3w one; the @Home robot log (rockin_logger names it
    ${BENCHMARK}_${DATE}_${TEAM}.bag, BENCHMARK as FBM2H or FBMH2) goes with fbm2h."""
    home_gt = bag("home/log_fbm2h_mocap_2015-11-20-10-00-00_0.bag", 0, 100)
    work_gt = bag("work/log_fbm3w_mocap_2015-11-20-10-00-00_0.bag", 0, 100, WORK_GT)
    tf_only = bag(
        "other/log_mocap_2015-11-20-10-00-00_0.bag", 0, 100, (Topic("/tf", "tf/tfMessage"),)
    )
    files = [
        home_gt,
        work_gt,
        bag("bm/log_fbm3w_2015-11-20-10-00-10_0.bag", 10, 20, WORK_BENCH),
        bag("usb/FBM2H_201511201000_homer.bag", 30, 40, ROBOT_TOPICS),
        bag("usb/FBMH2_201511201000_lurch.bag", 50, 60, ROBOT_TOPICS),
    ]
    pairs = {p.path: p for p in build_timeline(files).pairings}
    bench = pairs["bm/log_fbm3w_2015-11-20-10-00-10_0.bag"]
    assert (bench.gt, bench.other_benchmark, bench.basis) == (
        (work_gt.path,),
        (home_gt.path,),
        "content",
    )
    for robot in ("usb/FBM2H_201511201000_homer.bag", "usb/FBMH2_201511201000_lurch.bag"):
        assert (pairs[robot].gt, pairs[robot].other_benchmark) == ((home_gt.path,), (work_gt.path,))
        assert pairs[robot].basis == "content" and pairs[robot].coverage == pytest.approx(100.0)
    # A mocap logger naming no benchmark (only /tf) can only be paired by time, and says so.
    pairs = {p.path: p for p in build_timeline([*files, tf_only]).pairings}
    assert pairs["usb/FBM2H_201511201000_homer.bag"].gt == (home_gt.path, tf_only.path)
    assert pairs["usb/FBM2H_201511201000_homer.bag"].basis == "time"
    # A robot log whose name and topics name no benchmark: time is all there is.
    alone = build_timeline([home_gt, bag("robot.bag", 5, 6, ROBOT_TOPICS)]).pairings[0]
    assert (alone.gt, alone.basis) == ((home_gt.path,), "time")


def test_benchmark_names_from_topics_and_robot_log_names() -> None:
    assert benchmark_names(GT_TOPICS) == ("fbm2h",)
    assert benchmark_names(WORK_BENCH + GT_TOPICS) == ("fbm2h", "fbm3w")
    assert benchmark_names(ROBOT_TOPICS, "x/TBMH1_201511201000_adams.bag") == ("tbm1h",)
    assert benchmark_names(ROBOT_TOPICS, "x/fbm1w_201511201000_b-it-bots.bag") == ("fbm1w",)
    # /rosout, /tf and names that only look alike name no benchmark.
    assert benchmark_names(ROBOT_TOPICS, "FBM2H.bag") == ()
    assert benchmark_names((Topic("/fbm2hx/pose", "geometry_msgs/PoseStamped"),)) == ()


def _copies(n: int) -> list[Summary]:
    """One 28 s recording in n places: ROS 1 copies, and an MCAP copy whose ROS 2 type names
    spell the same types (``geometry_msgs/msg/PoseStamped``)."""
    ros2 = tuple(Topic(t.name, t.msgtype.replace("/", "/msg/"), t.count) for t in GT_TOPICS)
    return [
        bag(f"copy{i:04d}/log_fbm2h_mocap_2015-11-20-10-00-00_0.bag", 0, 28) for i in range(n - 1)
    ] + [Summary("mcap/rec.mcap", T0, T0 + 28 * S, ros2, format="mcap")]


def test_copies_of_one_recording_are_one_recording() -> None:
    tl = build_timeline(_copies(1000))
    (original,) = [b for b in tl.bags if b.copy_of is None]
    assert original.path == "copy0000/log_fbm2h_mocap_2015-11-20-10-00-00_0.bag"
    assert len(original.copies) == 999 and "mcap/rec.mcap" in original.copies
    assert all(b.overlaps == () for b in tl.bags)
    assert [s.paths for s in tl.sessions] == [(original.path,)]
    copy = next(b for b in tl.bags if b.path == "mcap/rec.mcap")
    assert copy.copy_of == original.path and copy.session == 1
    assert any(p.startswith(f"same recording as {original.path}") for p in copy.problems)
    # Copies are said once as copies, not also as 999 duplicated file names each.
    assert not any("duplicated file name" in p.problem for p in tl.problems)


def test_timeline_output_grows_linearly_with_copies() -> None:
    sizes = [len(json.dumps(build_timeline(_copies(n)).to_dict())) for n in (500, 1000)]
    # 500 more bags add about as much as the first 500 did (each entry names its original):
    # quadratic overlap lists would quadruple it.
    assert sizes[1] < 2.1 * sizes[0]
    # About 1 KB a copy (its entry and its problem line name it and its original), against
    # 40 MB when every copy listed the other 999 as overlaps.
    assert sizes[1] < 1000 * 1000


def test_same_name_different_recordings_are_still_flagged() -> None:
    tl = build_timeline([bag("a/x.bag", 0, 5), bag("b/x.bag", 0, 5, WORK_GT)])
    assert all(b.copy_of is None for b in tl.bags)
    assert sum("duplicated file name" in p.problem for p in tl.problems) == 2
