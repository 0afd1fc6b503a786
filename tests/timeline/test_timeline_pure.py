"""The pure timeline on hand-made summaries: order, overlaps, sessions, pairing, checks."""

from __future__ import annotations

from dataclasses import dataclass

import pytest

from ertools.timeline import (
    ClockCheck,
    TimelineConfig,
    Unreadable,
    build_timeline,
    classify,
    coverage,
    logger_name,
    split_name,
)

S = 1_000_000_000
T0 = 1_448_013_600 * S


@dataclass(frozen=True)
class Topic:
    name: str
    msgtype: str
    count: int = 10


@dataclass(frozen=True)
class Summary:
    path: str
    start_ns: int
    end_ns: int
    topics: tuple[Topic, ...]
    format: str = "ros1"
    indexed: bool = True
    problems: tuple[str, ...] = ()
    message_count: int = 10


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
    keys = ["path", "format", "start", "end", "duration", "kind", "overlaps", "problems"]
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
