"""Time conversions. Inside ertools time is int64 nanoseconds since the Unix epoch."""

from __future__ import annotations

from datetime import UTC, datetime
from typing import TYPE_CHECKING

if TYPE_CHECKING:  # annotations only: the command line's parsers import this module
    import numpy as np
    import numpy.typing as npt

NS_PER_S = 1_000_000_000

# The largest magnitude of a number of seconds ertools takes (an option, a config value, an
# offset): epoch seconds and bag-relative ones up to it still fit int64 nanoseconds twice
# over; no metre, radian or rate input comes near it.
MAX_SECONDS = 4.6e9

# Times below this many seconds are read as "seconds from the start of the bag", above it as
# epoch seconds (1e9 s is 2001-09-09: no benchmark log is older, no run is longer).
EPOCH_THRESHOLD_S = 1e9


def s_to_ns(seconds: float) -> int:
    """Seconds (float) to integer nanoseconds, rounded to the nearest nanosecond."""
    return round(seconds * NS_PER_S)


def ns_to_s(ns: int | np.integer) -> float:
    """Integer nanoseconds to float seconds (for reports only: float loses sub-us precision)."""
    return int(ns) / NS_PER_S


def ns_array_to_s(ns: npt.NDArray[np.int64]) -> npt.NDArray[np.float64]:
    """Vectorised :func:`ns_to_s`."""
    return ns.astype("float64") / NS_PER_S


def resolve_time(seconds: float, bag_start_ns: int) -> int:
    """A user-given time: relative to the bag's first message, or epoch if larger than 1e9."""
    if seconds > EPOCH_THRESHOLD_S:
        return s_to_ns(seconds)
    return bag_start_ns + s_to_ns(seconds)


def iso_utc(ns: int) -> str:
    """ISO 8601 UTC text of a nanosecond timestamp, with microseconds."""
    return datetime.fromtimestamp(ns / NS_PER_S, tz=UTC).isoformat(timespec="microseconds")
