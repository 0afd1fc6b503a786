"""Hour-long FBM logs for the benchmark: a sample benchmark inside an hour of mocap logging.

The 2015 mocap loggers ran all day, so a benchmark's bag holds far more ground truth than the
benchmark itself. Each sample scenario (``python -m ertools.samples``) is written as usual,
then its every message (states, mocap, maps, /tf) is copied into a new bag together with half
an hour of mocap of each of its bodies before the benchmark and half an hour after (120 Hz
PoseStamped + Pose2D + /tf, as the loggers wrote them). The scores of the hour bag must equal
those of the sample: the extra ground truth lies outside every run.

Connections whose messages differ in size (state payloads, maps) are written as several
connections of the same topic, one per message size, as the fast writer needs fixed-size rows;
ROS1 allows several connections per topic (the 2015 bags have them) and readers merge them by
time.
"""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
from bagwrite import Topic, write_ros1
from data import NS, gt_topics

# scenario -> (mocap bodies, score command arguments after the bag, pose topic to extract)
FBM_SCENARIOS: dict[str, tuple[tuple[str, ...], tuple[str, ...], str]] = {
    "fbm3w": (("/fbm3w/robot_at_work",), ("score", "fbm3w"), "/fbm3w/robot_at_work/pose"),
    "fbm2h": (
        ("/fbm2h/robot_at_home",),
        (
            "score",
            "fbm2h",
            "--goal",
            "{dir}/fbm2h_goal.yaml",
            "--transform",
            "{dir}/transform-simbot.yaml",
        ),
        "/fbm2h/robot_at_home/pose",
    ),
    "fbm1h": (
        ("/fbm1h/origin", "/fbm1h/ref_board"),
        ("score", "fbm1h", "--items", "{dir}/fbm1h.yaml"),
        "/fbm1h/ref_board/pose",
    ),
}
HALF_HOUR_S = 1800.0


def sample_topics(bag: Path) -> list[Topic]:
    """Every message of ``bag`` as fixed-size topics (one per connection and message size)."""
    from rosbags.highlevel import AnyReader

    out: list[Topic] = []
    with AnyReader([bag]) as reader:
        for conn in reader.connections:
            rows: dict[int, tuple[list[int], list[bytes]]] = {}
            for _c, t, raw in reader.messages([conn]):
                ts, datas = rows.setdefault(len(raw), ([], []))
                ts.append(t)
                datas.append(bytes(raw))
            ext = conn.ext
            for _size, (ts, datas) in sorted(rows.items()):
                data = np.frombuffer(b"".join(datas), dtype=np.uint8).reshape(len(datas), -1)
                out.append(
                    Topic(
                        conn.topic,
                        conn.msgtype.replace("/msg/", "/"),
                        conn.msgdef.data,
                        conn.digest,
                        np.array(ts, dtype=np.int64),
                        data,
                        getattr(ext, "callerid", None) or "/node",
                        bool(getattr(ext, "latching", 0)),
                    )
                )
    return out


def hour_bag(scenario: str, folder: Path) -> tuple[Path, Path]:
    """(hour bag, sample folder with its configs) of one scenario, written once."""
    from ertools.samples.scenario import load_scenario, seed_of

    sample_dir = folder / scenario
    target = folder / f"{scenario}_hour.bag"
    if target.exists() and sample_dir.is_dir():
        return target, sample_dir
    if sample_dir.exists():
        shutil.rmtree(sample_dir)
    sample_dir.mkdir(parents=True)
    paths = load_scenario(scenario)(sample_dir, seed=seed_of(scenario))
    bag = next(p for p in paths if p.suffix == ".bag")
    topics = sample_topics(bag)
    first = min(int(t.t_ns.min()) for t in topics)
    last = max(int(t.t_ns.max()) for t in topics)
    bodies = FBM_SCENARIOS[scenario][0]
    for k, body in enumerate(bodies):
        before = gt_topics(first - int(HALF_HOUR_S * NS), HALF_HOUR_S - 1.0, seed=10 + k, body=body)
        after = gt_topics(last + NS, HALF_HOUR_S, seed=20 + k, body=body)
        topics += before + after
    write_ros1(target, topics)
    return target, sample_dir
