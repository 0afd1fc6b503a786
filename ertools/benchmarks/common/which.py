"""Which benchmark a log is: ``ertools score fbm3w`` given an FBM2@Home log says so and names
the command, rather than failing later on a pose topic it cannot find.

A benchmark's logs have their topics under its namespace (``/fbm2h/...``, the robot's own log
``/rockin/...``: ``log_namespace``, :class:`~ertools.benchmarks.base.Discovered`). A log with none
under the benchmark asked for, and some under another registered one, is that one's log.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from ertools.benchmarks import registry
from ertools.benchmarks.base import Described, Discovered
from ertools.errors import ConfigError, ErtoolsError
from ertools.io.reader import topics

GT_USE = "ertools score trajectory ROBOT_BAG MOCAP..."


def _namespaces(names: Sequence[str]) -> dict[str, int]:
    """Topic count by first part (``/fbm2h/robot_at_home/pose`` -> ``fbm2h``)."""
    counts: dict[str, int] = {}
    for topic in names:
        first = topic.strip("/").split("/")[0]
        if first and "/" in topic.strip("/"):
            counts[first] = counts.get(first, 0) + 1
    return counts


def other_benchmark(name: str, bag: Path, values: Mapping[str, Any]) -> str | None:
    """The message when ``bag`` is plainly another benchmark's log, else None.

    None too when the user named the log's topics or frames (the benchmark's
    :attr:`~ertools.benchmarks.base.Discovered.source_inputs`: they know the log), or when
    the log cannot be read (the scorer then says why, as it would have).
    """
    bench = registry.get(name)
    if not isinstance(bench, Discovered):  # it has no logs of its own to recognise
        return None
    if any(values.get(i) not in (None, False, ()) for i in bench.source_inputs):
        return None
    try:
        spaces = _namespaces(list(topics([bag])))
    except ErtoolsError:
        return None
    if not bench.log_namespace or bench.log_namespace in spaces:
        return None
    candidates = []
    for other in registry.names():
        found = registry.get(other)
        ns = found.log_namespace if isinstance(found, Discovered) else ""
        if other != name and ns in spaces:
            candidates.append((-spaces[ns], other, ns))
    if not candidates:
        return None
    if len(candidates) > 1:
        # a mocap logger recording every arena (the 2015 GT logger's own files): no one
        # benchmark's log, but the poses that go with one
        listed = ", ".join(f"/{ns}/..." for _, _, ns in sorted(candidates, key=lambda c: c[2]))
        what = f"this log holds the poses of several benchmarks ({listed}), as a mocap logger's"
        metavar = bench.bags_metavar if isinstance(bench, Described) else "BAG"
        if not isinstance(metavar, str):
            # a command of a robot log and its GT (ROBOT_BAG GT_PATH): the file is a GT_PATH
            robot, gt = metavar
            return f"{what} file does; give it as {gt} after the {robot}: {GT_USE}"
        return (
            f"{what} file does; give it after the benchmark's own log (ertools score {name} "
            f"LOG MOCAP...), or as the GT of {GT_USE}"
        )
    _, other, ns = min(candidates)
    title = registry.get(other).title
    return f"this looks like an {title} log (topics /{ns}/...): ertools score {other}"


def log_benchmark(bag: Path) -> str | None:
    """The registered benchmark whose namespace holds ``bag``'s topics (None when none does,
    when several do, as in a mocap logger's file of every arena, or the log cannot be read)."""
    try:
        spaces = _namespaces(list(topics([bag])))
    except ErtoolsError:
        return None
    found = [
        (-spaces[bench.log_namespace], name)
        for name in registry.names()
        if isinstance(bench := registry.get(name), Discovered) and bench.log_namespace in spaces
    ]
    return found[0][1] if len(found) == 1 else None


def refuse_other_benchmark(name: str, bags: Sequence[Path], values: Mapping[str, Any]) -> None:
    """A :class:`ConfigError` when the first bag is plainly another benchmark's log: exit 1, as
    for an RSBB run bag of another benchmark (the file is wrong, not the command line)."""
    if not bags:
        return
    message = other_benchmark(name, bags[0], values)
    if message is not None:
        raise ConfigError(message, path=bags[0])
