"""Make a recording cut short (``kill -9``, a laptop closed, power lost) whole again.

A file cut short keeps every chunk the recorder flushed (:mod:`ertools.live.logfile`), but it
has no summary, no index and no footer: mcap's default reader (``make_reader``) and so
Foxglove refuse it. :func:`recover` reads it record by record up to the cut, with mcap's own
stream reader, and writes every complete record again (schemas, channels, messages with their
sequence and both times, metadata, attachments) into a finished MCAP file with its summary and
indexes. Nothing complete is dropped: the messages are counted against ertools' own follower
(:func:`ertools.live.tail.read_complete`), and a metadata record ``ertools_recovery`` says what
was done (bytes kept and lost) for whoever later asks where a number came from.

The cut file's bytes are kept beside it (``FILE.cut``): the recording is evidence.
"""

from __future__ import annotations

import contextlib
import os
import shutil
from pathlib import Path
from typing import Any

from ertools._version import __version__
from ertools.atomic import hold, replacing
from ertools.errors import BagError
from ertools.frozen_dataclass import frozen_dataclass
from ertools.live.tail import is_finished, read_complete

RECOVERY_METADATA = "ertools_recovery"


@frozen_dataclass
class Recovered:
    """What :func:`recover` did."""

    path: Path
    kept: Path | None  # the cut file's bytes (None: the file was whole, nothing done)
    messages: int
    complete_bytes: int
    size_bytes: int


def recover(path: Path) -> Recovered:
    """Rewrite the MCAP file ``path`` cut short as a finished one; the original bytes are kept
    as ``path.cut``.

    Raises:
        BagError: not an MCAP file, or one whose complete part holds no message (nothing to
            recover), or ``path.cut`` exists already (a recovery done before).
    """
    if not path.is_file():
        raise BagError("no such file", path=path, transient=True)
    with open(path, "rb") as held:
        # a recorder holds its file's lock until its last byte: cutting it now would leave
        # the recorder writing into the part cut off
        if not hold(held.fileno()):
            raise BagError(
                "is being recorded (a recorder holds its lock); --recover is for a recording "
                "cut short",
                path=path,
            )
        return _recover(path)


def _recover(path: Path) -> Recovered:
    size = path.stat().st_size
    if is_finished(path):
        return Recovered(path, None, 0, size, size)
    found = read_complete(path)
    if found.problem and "magic" in found.problem:
        raise BagError(f"cannot recover: {found.problem}", path=path)
    kept = path.with_name(path.name + ".cut")
    if kept.exists():
        raise BagError(
            f"{kept.name} exists: a recovery was done before; move it away to recover again",
            path=path,
        )
    count = 0
    with replacing(path) as tmp:
        count = _rewrite(path, tmp, found.complete_bytes, size)
        if count != len(found.messages):
            raise BagError(
                f"cannot recover: mcap's reader found {count} complete messages, ertools' "
                f"{len(found.messages)}; the file is left as it was",
                path=path,
            )
        if count == 0:
            raise BagError("cannot recover: no complete message before the cut", path=path)
        # the cut bytes under a new name before the whole file replaces them
        try:
            os.link(path, kept)
        except OSError:  # a file system without hard links
            shutil.copy2(path, kept)
    return Recovered(path, kept, count, found.complete_bytes, size)


def _rewrite(source: Path, target: Path, complete_bytes: int, size: int) -> int:
    """Every complete record of ``source`` into the finished MCAP file ``target``; the
    number of messages."""
    from mcap import records as r  # lazy: mcap, 20 ms
    from mcap.stream_reader import StreamReader  # lazy: mcap, 20 ms
    from mcap.writer import CompressionType, Writer  # lazy: mcap, 100 ms

    count = 0
    with open(source, "rb") as fin, open(target, "wb") as fout:
        writer: Any = Writer(fout, compression=CompressionType.ZSTD)
        schemas: dict[int, int] = {0: 0}
        channels: dict[int, int] = {}
        started = False
        reader = StreamReader(fin, skip_magic=False, emit_chunks=False, validate_crcs=True)
        records = reader.records
        while True:
            # the cut: a record whose length runs past the end, or garbage lengths after it
            try:
                record = next(records)
            except StopIteration:
                break
            except Exception:  # mcap raises several kinds at a cut (EndOfFile, limits...)
                break
            if isinstance(record, r.Header):
                writer.start(profile=record.profile, library=record.library)
                started = True
            elif not started:
                raise BagError("cannot recover: no MCAP header", path=source)
            elif isinstance(record, r.Schema):
                if record.id not in schemas:
                    schemas[record.id] = writer.register_schema(
                        name=record.name, encoding=record.encoding, data=record.data
                    )
            elif isinstance(record, r.Channel):
                if record.id not in channels and record.schema_id in schemas:
                    channels[record.id] = writer.register_channel(
                        topic=record.topic,
                        message_encoding=record.message_encoding,
                        schema_id=schemas[record.schema_id],
                        metadata=dict(record.metadata),
                    )
            elif isinstance(record, r.Message):
                if record.channel_id in channels:
                    writer.add_message(
                        channel_id=channels[record.channel_id],
                        log_time=record.log_time,
                        data=record.data,
                        publish_time=record.publish_time,
                        sequence=record.sequence,
                    )
                    count += 1
            elif isinstance(record, r.Metadata):
                writer.add_metadata(record.name, dict(record.metadata))
            elif isinstance(record, r.Attachment):
                writer.add_attachment(
                    create_time=record.create_time,
                    log_time=record.log_time,
                    name=record.name,
                    media_type=record.media_type,
                    data=record.data,
                )
            elif isinstance(record, r.Footer):
                break
        if not started:
            raise BagError("cannot recover: no MCAP header", path=source)
        writer.add_metadata(
            RECOVERY_METADATA,
            {
                "recovered_by": f"ertools {__version__} record --recover",
                "original_size_bytes": str(size),
                "complete_bytes": str(complete_bytes),
                "lost_bytes": str(size - complete_bytes),
                "messages": str(count),
            },
        )
        writer.finish()
        with contextlib.suppress(AttributeError):
            fout.flush()
    return count
