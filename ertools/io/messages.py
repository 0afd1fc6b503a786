"""Every message of a topic deserialized by rosbags, one Python object each: the general
fallback for any type (notes, the RSBB's strings, state messages message by message). Pose and
state streams, decoded to arrays, are :mod:`ertools.io.reader`'s.
"""

from __future__ import annotations

import logging
from typing import Any

import numpy as np

from ertools.frozen_dataclass import frozen_dataclass
from ertools.io.decode.typestore import Deserializer
from ertools.io.files import open_bag
from ertools.io.reader import PathsLike, path_list, topic_error

log = logging.getLogger("ertools.io.messages")


@frozen_dataclass
class RawMessage:
    """One deserialized message (rosbags' message object) with its record time."""

    t_ns: int
    msg: Any
    topic: str = ""
    msgtype: str = ""


def read_messages(
    paths: PathsLike, topic: str, *, start_ns: int | None = None, end_ns: int | None = None
) -> list[RawMessage]:
    """Every message of ``topic`` deserialized by rosbags, with record times, time-ordered.

    The general fallback for any type (one Python object per message: not for long pose
    streams; use :func:`ertools.io.reader.read_poses` there).
    """
    plist = path_list(paths)
    out: list[RawMessage] = []
    found = False
    for p in plist:
        with open_bag(p) as bag:
            conns = bag.topic_conns(topic)
            if not conns:
                continue
            found = True
            deser = Deserializer(conns, p)
            out.extend(
                RawMessage(t, deser(raw, c), topic, c.msgtype)
                for c, t, raw in bag.raw(conns, start_ns, end_ns)
            )
    if not found:
        raise topic_error(plist, topic, "topic")
    times = np.array([m.t_ns for m in out], dtype=np.int64)
    if len(times) > 1 and np.any(times[1:] < times[:-1]):
        log.warning("%s: messages from several files out of time order; sorted", topic)
        out = [out[i] for i in np.argsort(times, kind="stable")]
    return out
