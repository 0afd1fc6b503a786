"""What every open bag is: :class:`BagFile`, its connections and raw messages in record order.

The readers of each format (:mod:`ertools.io.ros1.index`, :mod:`ertools.io.files`) subclass it;
:func:`ertools.io.files.open_bag` picks one by the file's format.
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from contextlib import AbstractContextManager
from pathlib import Path
from types import TracebackType

from ertools.io.model import Conn

RawRecord = tuple[Conn, int, bytes]


class BagFile(AbstractContextManager["BagFile"]):
    """An open bag: ``connections`` and :meth:`raw` messages. Use as a context manager."""

    path: Path
    format: str
    connections: tuple[Conn, ...]

    def raw(
        self, conns: Sequence[Conn], start_ns: int | None = None, end_ns: int | None = None
    ) -> Iterator[RawRecord]:
        """(conn, record time ns, raw bytes) of ``conns`` in [start_ns, end_ns], time-ordered."""
        raise NotImplementedError

    def close(self) -> None:
        """Release the file."""

    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        tb: TracebackType | None,
    ) -> None:
        self.close()

    def topic_conns(self, topic: str) -> list[Conn]:
        """The connections of one topic, in file order."""
        return [c for c in self.connections if c.topic == topic]
