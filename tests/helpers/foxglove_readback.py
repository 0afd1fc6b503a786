"""Read an MCAP file back the way a viewer does: the ``mcap`` reader and the schemas in the file.

Protobuf messages are decoded with classes built from the FileDescriptorSet stored in the file
(each schema in its own descriptor pool), not with ertools' or Foxglove's generated classes:
so a schema the file does not carry completely fails here as it would in Foxglove.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from google.protobuf import descriptor_pb2, descriptor_pool, message_factory
from mcap.reader import make_reader


@dataclass
class Topic:
    schema_name: str
    schema_encoding: str
    message_encoding: str
    schema: Any  # the decoded JSON schema (jsonschema) or None
    times: list[int] = field(default_factory=list)
    messages: list[Any] = field(default_factory=list)


@dataclass
class ReadBack:
    topics: dict[str, Topic]
    file_times: list[int]  # log times in file order
    counts: dict[str, int]  # from the summary's statistics
    metadata: dict[str, dict[str, str]]


def read_back(path: Path) -> ReadBack:
    classes: dict[int, Any] = {}
    topics: dict[str, Topic] = {}
    file_times: list[int] = []
    with path.open("rb") as f:
        reader = make_reader(f)
        summary = reader.get_summary()
        assert summary is not None and summary.statistics is not None
        counts = {
            summary.channels[cid].topic: n
            for cid, n in summary.statistics.channel_message_counts.items()
        }
        metadata = {m.name: dict(m.metadata) for m in reader.iter_metadata()}
        for schema, channel, message in reader.iter_messages(log_time_order=False):
            assert schema is not None
            file_times.append(message.log_time)
            topic = topics.get(channel.topic)
            if topic is None:
                js = json.loads(schema.data) if schema.encoding == "jsonschema" else None
                topic = topics[channel.topic] = Topic(
                    schema.name, schema.encoding, channel.message_encoding, js
                )
            assert topic.schema_name == schema.name
            if channel.message_encoding == "protobuf":
                if schema.id not in classes:
                    pool = descriptor_pool.DescriptorPool()
                    fds = descriptor_pb2.FileDescriptorSet.FromString(schema.data)
                    for fd in fds.file:
                        pool.Add(fd)
                    classes[schema.id] = message_factory.GetMessageClass(
                        pool.FindMessageTypeByName(schema.name)
                    )
                msg = classes[schema.id].FromString(message.data)
            else:
                assert channel.message_encoding == "json"
                msg = json.loads(message.data)
            topic.times.append(message.log_time)
            topic.messages.append(msg)
    return ReadBack(topics, file_times, counts, metadata)


def stamp_ns(msg: Any) -> int:
    """A protobuf ``timestamp`` field in nanoseconds."""
    return int(msg.timestamp.seconds) * 1_000_000_000 + int(msg.timestamp.nanos)
