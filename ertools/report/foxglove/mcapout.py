"""Write collected Foxglove messages as one MCAP file (the IO edge of the Foxglove export)."""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path

from ertools._version import __version__
from ertools.atomic import replacing
from ertools.errors import UsageError
from ertools.views.foxglove import Collected


def refuse_inputs(out: Path, inputs: Sequence[str | Path]) -> None:
    """A UsageError when ``out`` is one of the inputs (ertools never overwrites them).

    The CLI checks the files named on the command line; this also covers the files found
    inside input folders (a GT folder), which only the result's provenance names.
    """
    if not out.exists():
        return
    for p in inputs:
        if Path(p).exists() and os.path.samefile(p, out):
            raise UsageError(
                f"--foxglove {out}: that is an input; ertools never overwrites its inputs"
            )


def write_mcap(out: Collected, path: Path) -> None:
    """Messages in log-time order (ties keep the order added), one channel per topic.

    Written to a temporary file beside ``path`` and renamed, so an interrupted export never
    leaves a half-written file under the name asked for.
    """
    from mcap.writer import Writer  # lazy: mcap, 100 ms

    order = sorted(range(len(out.messages)), key=lambda i: out.messages[i][0])
    path.parent.mkdir(parents=True, exist_ok=True)
    # a temporary of a unique name (ertools.atomic): a name chosen in advance follows a symlink
    # planted there, and two exports at once would write into the same file
    with replacing(path) as tmp, tmp.open("r+b") as f:
        w = Writer(f)
        w.start(profile="", library=f"ertools {__version__}")
        schema_ids: dict[str, int] = {}
        channel_ids: dict[str, int] = {}
        for topic, ch in out.channels.items():
            if ch.schema_name not in schema_ids:
                schema_ids[ch.schema_name] = w.register_schema(
                    ch.schema_name, ch.schema_encoding, ch.schema_data
                )
            channel_ids[topic] = w.register_channel(
                topic, ch.message_encoding, schema_ids[ch.schema_name]
            )
        sequence: dict[str, int] = {}
        for i in order:
            t, topic, data = out.messages[i]
            seq = sequence[topic] = sequence.get(topic, -1) + 1
            w.add_message(channel_ids[topic], t, data, t, seq)
        if out.metadata:
            w.add_metadata("ertools", dict(out.metadata))
        w.finish()  # type: ignore[no-untyped-call]
