"""HOPF's items (``items_with_pose.yaml``, key ``items``; November 2017: ``HOPF.yaml``'s
``items``): id, class, instance, description and the item's pose against the positioner.

The values are kept as the script read them: class and instance as YAML gave them (an
unquoted ``1`` stays an integer, and compares unequal to the answer ``"1"``, as in the
script), the quaternion not normalised (tf received it as written).
"""

from __future__ import annotations

import math
import re
from pathlib import Path
from typing import Any

from ertools.configs._yaml import load_yaml
from ertools.errors import ConfigError
from ertools.frozen_dataclass import frozen_dataclass

Scalar = str | int | float | bool


@frozen_dataclass
class HopfItem:
    """One item.

    Attributes:
        id: its number (the manual operation's ``id: N``).
        item_class, instance: as the file gives them.
        description: the text the referee is shown.
        trans: the item in the positioner's frame (m).
        rot: its rotation (x, y, z, w), as written.
    """

    id: int
    item_class: Scalar
    instance: Scalar
    description: str
    trans: tuple[float, float, float]
    rot: tuple[float, float, float, float]


@frozen_dataclass
class HopfItems:
    """An items file."""

    items: tuple[HopfItem, ...]
    source: str

    def by_id(self, item_id: int) -> HopfItem | None:
        return next((i for i in self.items if i.id == item_id), None)


def _scalar(value: Any, what: str, source: str) -> Scalar:
    if not isinstance(value, str | int | float | bool):
        raise ConfigError(f"{what}: expected a name, got {value!r}", path=source)
    return value


def _numbers(value: Any, n: int, what: str, source: str) -> tuple[float, ...]:
    ok = isinstance(value, list) and len(value) == n
    if ok:
        ok = all(isinstance(v, int | float) and not isinstance(v, bool) for v in value)
    if not ok or not all(math.isfinite(float(v)) for v in value):
        raise ConfigError(f"{what}: expected {n} finite numbers, got {value!r}", path=source)
    return tuple(float(v) for v in value)


def parse_items(data: Any, source: str) -> HopfItems:
    """The ``items`` list of a parsed YAML mapping.

    Raises:
        ConfigError: no ``items`` list, an item without its keys, a duplicate id, a zero
            quaternion.
    """
    raw = data.get("items") if isinstance(data, dict) else None
    if not isinstance(raw, list) or not raw:
        raise ConfigError("HOPF items: expected a non-empty list under 'items'", path=source)
    out: list[HopfItem] = []
    for k, entry in enumerate(raw):
        where = f"items[{k}]"
        if not isinstance(entry, dict):
            raise ConfigError(f"{where}: expected a mapping, got {entry!r}", path=source)
        missing = [
            key
            for key in ("id", "class", "instance", "description", "trans", "rot")
            if key not in entry
        ]
        if missing:
            raise ConfigError(f"{where}: missing {', '.join(missing)}", path=source)
        item_id = entry["id"]
        if isinstance(item_id, bool) or not isinstance(item_id, int):
            raise ConfigError(f"{where}: id must be an integer, got {item_id!r}", path=source)
        if any(i.id == item_id for i in out):
            raise ConfigError(f"{where}: id {item_id} given twice", path=source)
        t = _numbers(entry["trans"], 3, f"item {item_id} trans", source)
        r = _numbers(entry["rot"], 4, f"item {item_id} rot", source)
        if math.fsum(c * c for c in r) < 1e-12:
            raise ConfigError(f"item {item_id} rot: zero quaternion", path=source)
        out.append(
            HopfItem(
                item_id,
                _scalar(entry["class"], f"item {item_id} class", source),
                _scalar(entry["instance"], f"item {item_id} instance", source),
                str(_scalar(entry["description"], f"item {item_id} description", source)),
                (t[0], t[1], t[2]),
                (r[0], r[1], r[2], r[3]),
            )
        )
    return HopfItems(tuple(out), source)


def load_items(path: str | Path) -> HopfItems:
    """Read an items file.

    Raises:
        ConfigError: unreadable, not YAML, or not the items layout.
    """
    return parse_items(load_yaml(path, what="HOPF items"), str(path))


def py2_text(value: Scalar) -> str:
    """``'%s' % value`` as Python 2 wrote it (``str``: a float with 12 significant digits)."""
    if isinstance(value, float) and not isinstance(value, bool):
        if math.isnan(value) or math.isinf(value):
            return "nan" if math.isnan(value) else ("inf" if value > 0 else "-inf")
        text = format(value, ".12g")
        return text if any(c in text for c in ".e") else text + ".0"
    return str(value)


def place_text(item: HopfItem) -> str:
    """The first manual operation's request for ``item`` (l. 96)."""
    return (
        f"Place the positioner and the {item.description} (id: {item.id:d}, "
        f"instance: {py2_text(item.instance)}) on the table"
    )


PLACE = re.compile(
    r"^Place the positioner and the (.*) \(id: (-?\d+), instance: (.*)\) on the table$"
)
RETRY_PREFIX = "The position of the positioner could not be acquired!"
REMOVE_TEXT = "Remove the positioner"


def placed_id(request: str) -> int | None:
    """The item id a first manual operation's request names (None: not that request)."""
    m = PLACE.match(request)
    return None if m is None else int(m.group(2))
