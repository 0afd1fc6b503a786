"""Bulk NumPy decoding of fixed-layout pose messages (filled in by the fast path)."""

from __future__ import annotations

from collections.abc import Sequence

from ertools.io.files import BagFile
from ertools.io.model import Conn
from ertools.io.posebatch import PoseBatch


def try_fast_batch(
    bag: BagFile, conns: Sequence[Conn], start_ns: int | None, end_ns: int | None
) -> PoseBatch | None:
    """The pose rows of ``conns`` decoded in bulk, or None when the fast path does not apply."""
    return None
