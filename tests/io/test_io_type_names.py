"""Type names as the official readers give them: rosbag2 service events keep their ``srv``.

ROS 2 Jazzy records service calls on ``<service>/_service_event`` topics of type
``pkg/srv/Name_Event``; ``pkg/Name_Event`` would be another (message) type. Only the ``msg``
part of ``pkg/msg/Name`` is dropped (ertools' ``pkg/Name`` spelling of message types).
"""

from __future__ import annotations

from pathlib import Path

import pytest
from rosbags.rosbag2 import Reader, StoragePlugin, Writer
from rosbags.typesys import Stores, get_types_from_msg, get_typestore

from ertools.io.messages import read_messages
from ertools.io.model import long_msgtype, short_msgtype
from ertools.io.reader import topics as bag_topics
from ertools.io.summary import summary as bag_summary

EVENT = "example_interfaces/srv/AddTwoInts_Event"
TOPIC = "/add_two_ints/_service_event"
DEFINITION = "int64 a\nint64 b\n"


def write_event_bag(path: Path, plugin: str) -> Path:
    """A rosbag2 bag with a service-event topic of 3 messages (a, b) = (i, 10 i)."""

    ts = get_typestore(Stores.EMPTY)
    # Same fields under a message name: the serialized bytes are those of the event.
    ts.register(get_types_from_msg(DEFINITION, "test_msgs/msg/Pair"))
    pair = ts.types["test_msgs/msg/Pair"]
    with Writer(path, version=9, storage_plugin=StoragePlugin[plugin]) as w:
        conn = w.add_connection(TOPIC, EVENT, msgdef=DEFINITION, rihs01="RIHS01_" + "0" * 64)
        for i in range(3):
            raw = ts.serialize_cdr(pair(a=i, b=10 * i), "test_msgs/msg/Pair")
            w.write(conn, 1_000 + i, raw)
    return path


@pytest.mark.parametrize("plugin", ["SQLITE3", "MCAP"])
def test_service_event_types_keep_srv(tmp_path: Path, plugin: str) -> None:
    bag = write_event_bag(tmp_path / f"events_{plugin.lower()}", plugin)
    with Reader(bag) as reader:
        official = {c.topic: c.msgtype for c in reader.connections}
    assert official == {TOPIC: EVENT}
    assert bag_topics(bag) == official
    assert bag_summary(bag).topic(TOPIC).msgtype == EVENT  # type: ignore[union-attr]
    msgs = read_messages(bag, TOPIC)
    assert [(m.t_ns, m.msg.a, m.msg.b) for m in msgs] == [
        (1000, 0, 0),
        (1001, 1, 10),
        (1002, 2, 20),
    ]
    assert {m.msgtype for m in msgs} == {EVENT}
    if plugin == "MCAP":
        mcap = next(bag.glob("*.mcap"))
        assert bag_topics(mcap) == official  # the MCAP file alone, through its schema name


def test_short_and_long_names() -> None:
    assert short_msgtype("geometry_msgs/msg/PoseStamped") == "geometry_msgs/PoseStamped"
    assert short_msgtype(EVENT) == EVENT
    action = "example_interfaces/action/Fibonacci_FeedbackMessage"
    assert short_msgtype(action) == action
    assert long_msgtype("geometry_msgs/PoseStamped") == "geometry_msgs/msg/PoseStamped"
    assert long_msgtype(EVENT) == EVENT
