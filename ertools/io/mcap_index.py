"""MCAP files read through their summary section: chunk indexes and message indexes."""

from __future__ import annotations

from collections.abc import Iterator, Sequence

import numpy as np
import numpy.typing as npt

from ertools.io.files import BagFile
from ertools.io.model import Conn

I64 = npt.NDArray[np.int64]
U8 = npt.NDArray[np.uint8]


class McapIndex:
    """Placeholder until the MCAP bulk reader lands."""

    @staticmethod
    def of(bag: BagFile) -> McapIndex | None:
        return None

    def message_runs(
        self, conns: Sequence[Conn], lo: int | None, hi: int | None
    ) -> Iterator[tuple[I64, U8, I64, I64, I64]]:
        return iter(())
