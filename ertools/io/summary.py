"""``summary(path)``: what a bag holds."""

from __future__ import annotations

from pathlib import Path

from ertools.io.files import open_bag
from ertools.io.model import BagSummary, TopicSummary


def _size(path: Path) -> int:
    if path.is_dir():
        return sum(f.stat().st_size for f in path.rglob("*") if f.is_file())
    return path.stat().st_size


def summary(path: str | Path) -> BagSummary:
    """Format, times, size, compression and per-topic counts of one bag."""
    p = Path(path)
    with open_bag(p) as bag:
        stats: dict[str, list[int]] = {}
        nconn: dict[str, int] = {}
        types: dict[str, str] = {}
        for c in bag.connections:
            nconn[c.topic] = nconn.get(c.topic, 0) + 1
            types.setdefault(c.topic, c.msgtype)
        for c, t, _raw in bag.raw(bag.connections):
            s = stats.setdefault(c.topic, [0, t, t])
            s[0] += 1
            s[1] = min(s[1], t)
            s[2] = max(s[2], t)
        fmt = bag.format
    tops = tuple(
        TopicSummary(
            name,
            types[name],
            stats.get(name, [0])[0],
            stats[name][1] if name in stats else None,
            stats[name][2] if name in stats else None,
            nconn[name],
        )
        for name in sorted(types)
    )
    firsts = [t.first_ns for t in tops if t.first_ns is not None]
    lasts = [t.last_ns for t in tops if t.last_ns is not None]
    start = min(firsts) if firsts else 0
    end = max(lasts) if lasts else 0
    return BagSummary(
        str(p),
        fmt,
        "2.0" if fmt.startswith("ros1") else "",
        start,
        end,
        end - start,
        _size(p),
        "none",
        sum(t.count for t in tops),
        fmt != "ros1-active",
        tops,
        (),
    )
