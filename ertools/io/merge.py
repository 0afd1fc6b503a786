"""Time-ordered merges of streams read from several files (a logger's split files)."""

from __future__ import annotations

import itertools
import logging
from collections.abc import Sequence

import numpy as np

from ertools.streams import PoseStream, concatenate_poses
from ertools.timeutil import iso_utc

log = logging.getLogger("ertools.io.merge")


def sort_poses(stream: PoseStream, what: str) -> PoseStream:
    """``stream`` with non-decreasing time; out-of-order samples are sorted and reported.

    The sort is stable, so equal stamps keep their reading order.
    """
    t = stream.t_ns
    if len(t) < 2:
        return stream
    back = np.flatnonzero(t[1:] < t[:-1])
    if back.size == 0:
        return stream
    first = int(back[0]) + 1
    log.warning(
        "%s: %d sample(s) out of time order (first at %s); sorted by time",
        what,
        back.size,
        iso_utc(int(t[first])),
    )
    return stream.take(np.argsort(t, kind="stable"))


def merge_poses(streams: Sequence[PoseStream], what: str) -> PoseStream:
    """One time-ordered stream from per-file streams, each already sorted.

    Files whose time ranges overlap are reported (their samples interleave after the sort);
    frame names come from the first non-empty stream.
    """
    parts = [s for s in streams if len(s)]
    if not parts:
        return streams[0] if streams else PoseStream.empty()
    if len(parts) == 1:
        return parts[0]
    ordered = sorted(parts, key=lambda s: s.start_ns)
    for a, b in itertools.pairwise(ordered):
        if b.start_ns < a.end_ns:
            log.warning(
                "%s: files overlap in time (%s starts at %s before %s ends at %s); "
                "samples merged in time order",
                what,
                b.source,
                iso_utc(b.start_ns),
                a.source,
                iso_utc(a.end_ns),
            )
    joined = concatenate_poses(parts)
    if np.any(joined.t_ns[1:] < joined.t_ns[:-1]):
        if [s.source for s in ordered] != [s.source for s in parts]:
            log.warning("%s: files given out of time order; merged in time order", what)
        joined = joined.take(np.argsort(joined.t_ns, kind="stable"))
    return joined
