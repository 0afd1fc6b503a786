"""How far a bag's header stamps lie from its record times: the clock check of one bag.

A pose's header stamp is the mocap machine's clock; its record time is the logger's. The median
of their difference over the first messages of one pose topic tells whether the two machines
agreed (NTP) when the bag was written. The timeline reports it per recording; every benchmark
refuses header-timed poses against record-timed states when it is too large
(:func:`check_header_clock`).
"""

from __future__ import annotations

import logging
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from ertools.errors import ClockError, ErtoolsError
from ertools.frozen_dataclass import frozen_dataclass
from ertools.io.files import open_bag
from ertools.io.model import BagSummary
from ertools.io.reader import load_pose_batch
from ertools.io.summary import summary
from ertools.streams import PoseStream
from ertools.timeutil import NS_PER_S

log = logging.getLogger("ertools.io.clock")


@frozen_dataclass
class ClockCheck:
    """Record time minus header stamp (median over a few messages) of one pose topic."""

    path: str
    topic: str
    offset_ns: int
    samples: int
    error: str = ""  # the first messages could not be read (damaged data)


# Types whose header stamp the clock check compares with the record time, best first: the
# mocap node's own poses, then tf (whose static transforms may be stamped in the future).
CLOCK_TYPES = (
    "geometry_msgs/PoseStamped",
    "geometry_msgs/TransformStamped",
    "geometry_msgs/PoseWithCovarianceStamped",
    "nav_msgs/Odometry",
    "tf2_msgs/TFMessage",
    "tf/tfMessage",
)
CLOCK_WINDOW_NS = NS_PER_S  # the first second of the topic: ~120 mocap messages
CLOCK_MAX_SAMPLES = 50


def clock_check(
    s: BagSummary, window_ns: int = CLOCK_WINDOW_NS, topic_name: str | None = None
) -> ClockCheck | None:
    """Median record time minus header stamp over the first messages of one pose topic.

    The topic is ``topic_name``, else the best header-stamped pose topic of the bag. None when
    there is none. When the data cannot be read (a damaged chunk the index does not reveal),
    the check carries the reader's message in ``error``.
    """
    rank = {t: i for i, t in enumerate(CLOCK_TYPES)}
    cands = sorted(
        (t for t in s.topics if t.msgtype in rank and t.count and t.first_ns is not None),
        key=lambda t: (rank[t.msgtype], t.name == "/tf_static", t.name),
    )
    cands = [
        t
        for t in cands
        if (t.name == topic_name if topic_name is not None else t.name != "/tf_static")
    ]
    if not cands:
        return None
    topic = cands[0]
    assert topic.first_ns is not None and topic.last_ns is not None
    try:
        with open_bag(s.path) as bag:
            conns = bag.topic_conns(topic.name)
            # The summary's first time is the start of the topic's first chunk, which may hold
            # seconds of other topics first: widen the window until messages come.
            window = window_ns
            while True:
                batch = load_pose_batch(bag, conns, topic.first_ns, topic.first_ns + window)
                if len(batch) or topic.first_ns + window >= topic.last_ns:
                    break
                window *= 8
    except Exception as err:  # damaged data the index did not show: report it, go on
        text = err.message if isinstance(err, ErtoolsError) else f"{type(err).__name__}: {err}"
        log.debug("clock check of %s failed: %s", s.path, text)
        return ClockCheck(str(s.path), topic.name, 0, 0, error=text)
    if len(batch) == 0:
        return None
    diff = (batch.t_record - batch.t_header)[:CLOCK_MAX_SAMPLES]
    return ClockCheck(str(s.path), topic.name, int(np.median(diff)), len(diff))


# Record time minus header stamp of mocap poses is a few ms on one machine (0.3 ms in the real
# 2015 log); a quarter second means two clocks disagree, enough to move a robot at 0.5 m/s by
# 12 cm between the moment the states name and the pose taken for it.
HEADER_CLOCK_TOLERANCE_NS = NS_PER_S // 4


def check_header_clock(
    paths: Sequence[str | Path],
    poses: PoseStream,
    states_what: str | None,
    tolerance_ns: int = HEADER_CLOCK_TOLERANCE_NS,
    *,
    time_source: str = "header",
) -> None:
    """Refuse poses timed by header stamps that disagree with the bag's record times.

    Benchmark states (and timing files) are timed by record time; poses by default by their
    header stamp. When the two clocks differ by more than ``tolerance_ns``, every pose taken
    "at" a state moment is another moment's pose: a wrong score that looks right.

    The one guard of every benchmark: nothing to check when the poses are timed by record
    time (``time_source`` "record") or when the moments come from the poses themselves
    (``states_what`` None: runs found from motion are in the poses' own time).

    Raises:
        ClockError: naming the file, the topic, the offset and the way out.
    """
    if time_source != "header" or states_what is None:
        return
    cut = poses.source.rfind(":/")
    topic = poses.source[cut + 1 :] if cut >= 0 else ""
    if not topic or topic in ("/tf", "/tf_static"):
        return  # tf mixes publishers (static transforms are stamped otherwise): not checked
    for path in paths:
        check = clock_check(summary(path), topic_name=topic)
        if check is None or check.error or not check.samples:
            continue
        if abs(check.offset_ns) > tolerance_ns:
            ahead = -check.offset_ns / NS_PER_S
            raise ClockError(
                f"{path}:{topic}: header stamps are {ahead:+.3f} s off the record times "
                f"(median of {check.samples} messages), but the {states_what} are timed by "
                "record time: the mocap and logger clocks disagree; re-run with "
                "--time-source record"
            )
