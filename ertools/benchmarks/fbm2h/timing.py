"""Reached-waypoint timing files, as shipped with the 2015 FBM2@Home test logs.

Format::

    reached_waypoint_timing:
    - p0: 0.0          # the run starts
    - p1: 15.968182    # waypoint 0 reached (closes segment 0)
    - p2: 30.744414    # waypoint 1 reached ...

Times are seconds from the bag's first message (values above 1e9 are read as epoch seconds,
as everywhere in ertools). ``p(k+1)`` closes segment ``k`` and opens segment ``k+1``.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from ertools.configs._yaml import load_yaml, number
from ertools.errors import ConfigError
from ertools.frozen_dataclass import frozen_dataclass
from ertools.timeutil import MAX_SECONDS, resolve_time

KEY = "reached_waypoint_timing"


@frozen_dataclass
class ReachedTiming:
    """The moments of a timing file, in file order.

    Attributes:
        labels: ``p0``, ``p1``... as written.
        seconds: the times as written (bag-relative or epoch seconds), strictly increasing.
        source: the file.
    """

    labels: tuple[str, ...]
    seconds: tuple[float, ...]
    source: str = ""

    def __len__(self) -> int:
        return len(self.seconds)

    def resolve(self, bag_start_ns: int, bag_end_ns: int) -> npt.NDArray[np.int64]:
        """Epoch nanoseconds of every moment; each must lie inside [bag start, bag end]."""
        t = np.array([resolve_time(s, bag_start_ns) for s in self.seconds], dtype=np.int64)
        for label, s, t_ns in zip(self.labels, self.seconds, t, strict=True):
            if t_ns < bag_start_ns or t_ns > bag_end_ns:
                span = (bag_end_ns - bag_start_ns) / 1e9
                raise ConfigError(
                    f"{label}: {s} s lies outside the bag (0 to {span:.3f} s from its first "
                    "message); is this the timing file of another bag?",
                    path=self.source,
                )
        return t


def parse_timing(data: Any, source: str = "<timing>") -> ReachedTiming:
    """Validate a parsed timing file: single-key entries, finite, strictly increasing times."""
    if not isinstance(data, dict) or KEY not in data:
        raise ConfigError(f"timing file: missing key {KEY!r}", path=source)
    entries = data[KEY]
    if not isinstance(entries, list) or len(entries) < 2:
        raise ConfigError(
            f"{KEY}: expected a list of at least two entries like '- p0: 0.0'", path=source
        )
    labels: list[str] = []
    seconds: list[float] = []
    for i, entry in enumerate(entries):
        if not isinstance(entry, dict) or len(entry) != 1:
            raise ConfigError(
                f"{KEY}[{i}]: expected one 'pK: seconds' entry, got {entry!r}", path=source
            )
        ((label, value),) = entry.items()
        if str(label) != f"p{i}":
            # p(k+1) closes segment k: a label out of its place means an edited or merged
            # file whose moments would close the wrong segments.
            raise ConfigError(
                f"{KEY}[{i}]: labelled {label!r}, expected 'p{i}' (entries are p0, p1, ... in "
                "order: p0 starts, p(k+1) closes segment k)",
                path=source,
            )
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise ConfigError(f"{KEY}[{i}] {label}: {value!r} is not a number", path=source)
        # seconds from the bag's start, or epoch seconds: either way their ns fit int64
        number(value, f"{KEY}[{i}] {label}", source, low=-MAX_SECONDS, high=MAX_SECONDS, unit="s")
        if seconds and float(value) <= seconds[-1]:
            raise ConfigError(
                f"{KEY}[{i}] {label}: {value} s does not come after {labels[-1]} "
                f"({seconds[-1]} s); times must increase",
                path=source,
            )
        labels.append(str(label))
        seconds.append(float(value))
    return ReachedTiming(tuple(labels), tuple(seconds), source)


def load_timing(path: str | Path) -> ReachedTiming:
    """Read and validate a reached-waypoint timing file."""
    return parse_timing(load_yaml(path, "timing"), source=str(path))
