"""FBM1 item lists (seed Listing 9): id, class, instance and the item's pose on the board.

A full list gives, per item, ``trans`` (metres) and ``rot`` (quaternion x, y, z, w): the pose of
the item frame in the ``ref_board`` frame, T_board_item. A *vanilla* list (the 2015
``fbm1h-vanilla.yaml``) names the items only, or carries the placeholders ``trans: [0, 0, 0]``
and ``rot: [0, 0, 0, 1]``; ``ertools acquire items`` fills it in.

The 2015 files were ``rosparam dump`` output: a mapping with ``items:`` beside other keys
(``mocap:``...), which are ignored here. A bare list of items is accepted too.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import yaml

from ertools.configs._yaml import load_yaml, number
from ertools.errors import ConfigError
from ertools.frozen_dataclass import frozen_dataclass
from ertools.serialize import dump_yaml

Vec3 = tuple[float, float, float]
Quat = tuple[float, float, float, float]

IDENTITY_TRANS: Vec3 = (0.0, 0.0, 0.0)
IDENTITY_ROT: Quat = (0.0, 0.0, 0.0, 1.0)


@frozen_dataclass
class ItemSpread:
    """How much a measured item transform varied over its acquisition window.

    Attributes:
        position_m: RMS distance of the samples from the mean translation, metres.
        angle_deg: RMS rotation angle of the samples from the mean rotation, degrees.
        samples: number of mocap samples averaged.
        start_s: window start, seconds from the bag's first message.
        end_s: window end, seconds from the bag's first message.
    """

    position_m: float
    angle_deg: float
    samples: int
    start_s: float
    end_s: float


@frozen_dataclass
class Item:
    """One FBM1 item.

    Attributes:
        id: unique key (the 2015 lists start at 1).
        item_class: class name as the robot must answer it.
        instance: instance name as the robot must answer it.
        trans: T_board_item translation in metres, None in a vanilla list.
        rot: T_board_item rotation (x, y, z, w), None in a vanilla list.
        spread: measurement spread, present in lists written by ``acquire items``.
    """

    id: int
    item_class: str
    instance: str
    trans: Vec3 | None = None
    rot: Quat | None = None
    spread: ItemSpread | None = None

    @property
    def has_transform(self) -> bool:
        return self.trans is not None and self.rot is not None


@frozen_dataclass
class ItemList:
    """An item list and where it came from."""

    items: tuple[Item, ...]
    source: str = ""

    def __len__(self) -> int:
        return len(self.items)

    def by_id(self, item_id: int) -> Item | None:
        """The item with this id, None when absent."""
        for item in self.items:
            if item.id == item_id:
                return item
        return None

    def by_instance(self, instance: str) -> Item | None:
        """The item with this instance name (compared without surrounding blanks)."""
        wanted = instance.strip()
        for item in self.items:
            if item.instance.strip() == wanted:
                return item
        return None

    @property
    def is_vanilla(self) -> bool:
        """True when no item carries a measured transform."""
        return all(not _measured(item) for item in self.items)


def _measured(item: Item) -> bool:
    return item.has_transform and (item.trans, item.rot) != (IDENTITY_TRANS, IDENTITY_ROT)


def _numbers(value: Any, n: int, what: str, source: str) -> tuple[float, ...]:
    """A list of ``n`` finite numbers, or a ConfigError saying what is wrong."""
    if not isinstance(value, list | tuple) or len(value) != n:
        raise ConfigError(f"{what}: expected a list of {n} numbers, got {value!r}", path=source)
    out = []
    for v in value:
        out.append(number(v, what, source))
    return tuple(out)


def _name(value: Any, what: str, source: str) -> str:
    # YAML turns an unquoted instance like ``1`` into an int; the robot answers text.
    if isinstance(value, bool) or not isinstance(value, str | int | float):
        raise ConfigError(f"{what}: expected a name, got {value!r}", path=source)
    return str(value)


def _parse_spread(value: Any, what: str, source: str) -> ItemSpread | None:
    if value is None:
        return None
    if not isinstance(value, dict):
        raise ConfigError(f"{what}: expected a mapping", path=source)
    try:
        window = value.get("window_s", [math.nan, math.nan])
        return ItemSpread(
            float(value["position_m"]),
            float(value["angle_deg"]),
            int(value["samples"]),
            float(window[0]),
            float(window[1]),
        )
    except (KeyError, TypeError, ValueError, IndexError, OverflowError) as err:
        raise ConfigError(f"{what}: malformed spread ({err})", path=source) from None


def parse_items(data: Any, source: str = "<items>", *, require_transforms: bool = True) -> ItemList:
    """Validate a Listing 9 structure (already parsed YAML).

    Args:
        data: ``{"items": [...]}`` or a bare list of item mappings.
        source: file name for messages.
        require_transforms: demand ``trans`` and ``rot`` on every item (scoring); False for
            vanilla lists (acquisition).

    Raises:
        ConfigError: a missing or malformed field, a duplicate id, a zero quaternion.
    """
    raw = data.get("items") if isinstance(data, dict) else data
    if isinstance(data, dict) and "items" not in data:
        raise ConfigError("item list: missing key 'items' (seed Listing 9)", path=source)
    if not isinstance(raw, list) or not raw:
        raise ConfigError("item list: 'items' must be a non-empty list", path=source)
    items: list[Item] = []
    seen: set[int] = set()
    for k, entry in enumerate(raw):
        where = f"items[{k}]"
        if not isinstance(entry, dict):
            raise ConfigError(f"{where}: expected a mapping, got {entry!r}", path=source)
        for key in ("id", "class", "instance"):
            if key not in entry:
                raise ConfigError(f"{where}: missing key {key!r}", path=source)
        item_id = entry["id"]
        if isinstance(item_id, bool) or not isinstance(item_id, int):
            raise ConfigError(f"{where}: id must be an integer, got {item_id!r}", path=source)
        if item_id in seen:
            raise ConfigError(f"{where}: duplicate id {item_id}", path=source)
        seen.add(item_id)
        where = f"item {item_id}"
        trans: Vec3 | None = None
        rot: Quat | None = None
        if "trans" in entry:
            t = _numbers(entry["trans"], 3, f"{where} trans", source)
            trans = (t[0], t[1], t[2])
        if "rot" in entry:
            r = _numbers(entry["rot"], 4, f"{where} rot", source)
            norm = math.sqrt(sum(c * c for c in r))
            if norm < 1e-9:
                raise ConfigError(f"{where} rot: zero quaternion", path=source)
            # Hand-edited lists carry rounded quaternions; scoring needs unit ones.
            rot = (r[0] / norm, r[1] / norm, r[2] / norm, r[3] / norm)
        if require_transforms and (trans is None or rot is None):
            missing = "trans" if trans is None else "rot"
            raise ConfigError(
                f"{where}: missing {missing!r} (a vanilla list? run `ertools acquire items` first)",
                path=source,
            )
        items.append(
            Item(
                item_id,
                _name(entry["class"], f"{where} class", source),
                _name(entry["instance"], f"{where} instance", source),
                trans,
                rot,
                _parse_spread(entry.get("spread"), f"{where} spread", source),
            )
        )
    return ItemList(tuple(items), source)


def load_items(path: str | Path, *, require_transforms: bool = True) -> ItemList:
    """Read and validate a Listing 9 file (``fbm1h.yaml``) or a vanilla list."""
    data = load_yaml(path, what="item list")
    return parse_items(data, str(path), require_transforms=require_transforms)


def items_to_data(items: Sequence[Item], *, with_spread: bool = True) -> dict[str, Any]:
    """The Listing 9 structure: keys in the order rosparam dumped them (alphabetical).

    Items without a transform are written with the 2015 placeholders (identity).
    """
    out: list[dict[str, Any]] = []
    for item in items:
        entry: dict[str, Any] = {
            "class": item.item_class,
            "id": item.id,
            "instance": item.instance,
            "rot": list(item.rot if item.rot is not None else IDENTITY_ROT),
        }
        if with_spread and item.spread is not None:
            s = item.spread
            # Extra key: the 2015 node read items by key, so it ignored this one.
            entry["spread"] = {
                "angle_deg": s.angle_deg,
                "position_m": s.position_m,
                "samples": s.samples,
                "window_s": [s.start_s, s.end_s],
            }
        entry["trans"] = list(item.trans if item.trans is not None else IDENTITY_TRANS)
        out.append(entry)
    return {"items": out}


def items_to_yaml(items: Sequence[Item], *, with_spread: bool = True) -> str:
    """Listing 9 text: block style, quaternion and translation as flow lists as in 2015."""

    def _flow_list(dumper: yaml.SafeDumper, data: list[Any]) -> yaml.Node:
        flow = all(isinstance(v, int | float) for v in data)
        return dumper.represent_sequence("tag:yaml.org,2002:seq", data, flow_style=flow)

    # floats to 9 decimals (ertools.serialize), number lists in flow style
    data = items_to_data(items, with_spread=with_spread)
    return dump_yaml(data, representers={list: _flow_list})
