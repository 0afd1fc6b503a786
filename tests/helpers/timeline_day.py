"""A competition day for the timeline's pictures, built from summaries (no bags needed).

Six sessions over six hours (09:00 to 15:00 UTC), one of 8 s and one of half a second, so a
day-wide axis cannot show them; problems of every kind (a gap between split files, an
uncovered robot log, a log no GT covers, a copy, hostile names and problem texts from files),
and one unreadable file. The expected sessions, bags and problems follow from the layout
below, not from the code: each session's bags are written down as such.
"""

from __future__ import annotations

from ertools.io.formats import Unreadable
from ertools.timelines.build import build_timeline
from ertools.timelines.model import Timeline
from tests.helpers.summaries import Summary, Topic

S = 1_000_000_000
DAY0 = 1_448_010_000 * S  # 2015-11-20 09:00:00 UTC
EVIL = "<script>alert('x')</script>"
EVIL_IMG = '<img src=x onerror="alert(1)">'


def gt(ns: str) -> tuple[Topic, ...]:
    arena = "robot_at_home" if ns.endswith("h") else "robot_at_work"
    return (Topic(f"/{ns}/{arena}/pose", "geometry_msgs/PoseStamped"), Topic("/tf", "tf/tfMessage"))


def bench(ns: str) -> tuple[Topic, ...]:
    return (Topic(f"/{ns}/bmbox_state", "rockin_scoring/BmBoxState"),)


def robot(count: int = 10) -> tuple[Topic, ...]:
    return (Topic("/rockin/robot/marker_pose", "geometry_msgs/PoseStamped", count),)


def at(hours: float, seconds: float = 0.0) -> int:
    return DAY0 + round((hours * 3600 + seconds) * S)


# (session start in hours from 09:00, [(path, start s, end s, topics, problems)])
SESSIONS: list[tuple[float, list[tuple[str, float, float, tuple[Topic, ...], tuple[str, ...]]]]] = [
    (
        0.0,
        [
            ("gt/log_fbm2h_mocap_2015-11-20-09-00-00_0.bag", 0, 300, gt("fbm2h"), ()),
            ("gt/log_fbm2h_mocap_2015-11-20-09-00-00_1.bag", 300.008, 600, gt("fbm2h"), ()),
            ("bm/log_fbm2h_2015-11-20-09-00-10_0.bag", 10, 590, bench("fbm2h"), ()),
            ("robots/FBM2H_201511200900_homer.bag", 20, 400, robot(), ()),
        ],
    ),
    (
        1.5,  # the 8-second session
        [
            ("gt_work/log_fbm3w_mocap_2015-11-20-10-30-00_0.bag", 0, 8, gt("fbm3w"), ()),
            ("robots/FBM3W_201511201030_bitbots.bag", 1, 7, robot(11), ()),
        ],
    ),
    (
        3.0,  # a 5 s gap between split files, bridged by the robot log (one session)
        [
            ("gt/log_fbm2h_mocap_2015-11-20-12-00-00_0.bag", 0, 100, gt("fbm2h"), ()),
            ("gt/log_fbm2h_mocap_2015-11-20-12-00-00_1.bag", 105, 200, gt("fbm2h"), ()),
            ("robots/FBM2H_201511201200_homer.bag", 50, 150, robot(12), ()),
        ],
    ),
    (
        4.5,  # a robot log with a hostile name and problem text, no GT at all
        [(f"robots/FBM2H_{EVIL_IMG}.bag", 0, 60, robot(13), (f"odd header {EVIL}",))],
    ),
    (
        5.25,  # half a second
        [("robots/FBM2H_201511201415_short.bag", 0, 0.5, robot(14), ())],
    ),
    (
        6.0,
        [
            ("gt/log_fbm2h_mocap_2015-11-20-15-00-00_0.bag", 0, 120, gt("fbm2h"), ()),
            ("robots/FBM2H_201511201500_homer.bag", 10, 100, robot(15), ()),
            ("usb/FBM2H_201511201500_homer.bag", 10, 100, robot(15), ()),  # a copy
        ],
    ),
]
UNREADABLE = Unreadable("old/log_fbm2h_mocap_2015-11-19-17-00-00_0.bag", f"truncated {EVIL}")


def summaries() -> list[Summary]:
    return [
        Summary(path, at(h, a), at(h, b), topics, problems=problems)
        for h, bags in SESSIONS
        for path, a, b, topics, problems in bags
    ]


def day_timeline() -> Timeline:
    return build_timeline(summaries(), [UNREADABLE])


def many_bags(n: int = 1000) -> Timeline:
    """``n`` robot logs of 10 s by 20 teams (rockin_logger names: one lane per team), over six
    hours (the page's performance case)."""
    step = 6 * 3600 / n
    return build_timeline(
        [
            Summary(
                f"robots/FBM2H_{201511200000 + i}_team{i % 20:02d}.bag",
                at(0, i * step),
                at(0, i * step + 10),
                robot(i + 1),
            )
            for i in range(n)
        ]
    )
