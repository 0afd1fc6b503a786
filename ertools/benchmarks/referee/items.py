"""The referee's items of an RSBB run and what they add up to (docs/rsbb.md, "Referee-scored
benchmarks").

``rsbb_etc/config/benchmarks_description.yaml`` lists, per benchmark, groups of items
(``Achievements``, ``Penalized Behaviors``, ``Disqualifying Behaviors``), each a ``bool`` or a
``uint`` with its description; the RefBox showed them to the referee and logged their values.
No RSBB code adds them up: the ERL rulebook ranks a task benchmark's runs by most achievements,
then fewest penalised behaviours, then least time, and a disqualifying behaviour disqualifies
the run. ertools' reading: an item's value is what it counts (a ``bool`` 0 or 1, a ``uint`` its
count), an achievement group's items add up to the achievements, a penalty group's to the
penalties. Pure, but for :func:`load_descriptions`, which reads the description file.
"""

from __future__ import annotations

import enum
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from typing import Any

from ertools.errors import ConfigError
from ertools.frozen_dataclass import frozen_dataclass
from ertools.rsbb.results import load_rsbb_yaml


class Role(enum.Enum):
    """What an item's group is in the ERL ranking."""

    ACHIEVEMENT = "achievement"
    PENALTY = "penalty"
    DISQUALIFYING = "disqualifying"
    OTHER = "other"  # a group the rulebook does not name: shown, counted nowhere


def group_role(group: str) -> Role:
    """The role of a group by its name (``Achievements``, ``Penalized Behaviors``,
    ``Disqualifying Behaviors``; any case, either spelling of penalised)."""
    name = group.strip().lower()
    if name.startswith("achiev"):
        return Role.ACHIEVEMENT
    if name.startswith(("penali", "penaliz")):
        return Role.PENALTY
    if name.startswith("disqualif"):
        return Role.DISQUALIFYING
    return Role.OTHER


@frozen_dataclass
class ItemSpec:
    """One item as the description file declares it."""

    group: str
    kind: str  # "bool" or "uint"
    desc: str


@frozen_dataclass
class Item:
    """One item with the value the referee gave it."""

    group: str
    kind: str
    desc: str
    value: int

    @property
    def role(self) -> Role:
        return group_role(self.group)


@frozen_dataclass
class Description:
    """One benchmark of ``benchmarks_description.yaml``.

    Attributes:
        code: the benchmark code.
        name: its ``desc``.
        scripted: a BmBox script runs it.
        items: its referee items, in the file's order.
        timeout_s: ``timeout`` (non-scripted) or ``global_timeout`` (scripted), None if absent.
    """

    code: str
    name: str
    scripted: bool
    items: tuple[ItemSpec, ...]
    timeout_s: float | None


def _items(scoring: Any, where: str) -> tuple[ItemSpec, ...]:
    if scoring is None:
        return ()
    if not isinstance(scoring, list):
        raise ConfigError(f"{where}: scoring is not a list of groups")
    out: list[ItemSpec] = []
    for group in scoring:
        if not isinstance(group, dict) or len(group) != 1:
            raise ConfigError(f"{where}: a scoring group is not one `name: [items]` mapping")
        ((name, entries),) = group.items()
        for entry in entries or []:
            if not isinstance(entry, dict) or entry.get("type") not in ("bool", "uint"):
                raise ConfigError(f"{where}: group {name}: an item without type bool or uint")
            out.append(ItemSpec(str(name), str(entry["type"]), str(entry.get("desc", ""))))
    return tuple(out)


def parse_descriptions(data: Any, where: str) -> dict[str, Description]:
    """The benchmarks of a parsed description file, by code.

    Raises:
        ConfigError: not the file's layout.
    """
    entries = data.get("benchmarks_description") if isinstance(data, dict) else None
    if not isinstance(entries, list):
        raise ConfigError(f"{where}: no benchmarks_description list")
    out: dict[str, Description] = {}
    for k, entry in enumerate(entries):
        if not isinstance(entry, dict) or "code" not in entry:
            raise ConfigError(f"{where}: benchmarks_description[{k}] has no code")
        code = str(entry["code"])
        scripted = bool(entry.get("scripted", False))
        timeout = entry.get("global_timeout" if scripted else "timeout")
        try:
            timeout_s = None if timeout is None else float(timeout)
        except (TypeError, ValueError):
            raise ConfigError(f"{where}: {code}: timeout {timeout!r} is not a number") from None
        out[code] = Description(
            code,
            str(entry.get("desc", "")),
            scripted,
            _items(entry.get("scoring"), f"{where}: {code}"),
            timeout_s,
        )
    return out


def load_descriptions(path: str | Path) -> dict[str, Description]:
    """Read ``benchmarks_description.yaml``.

    Raises:
        ConfigError: unreadable, not YAML, or not the layout.
    """
    p = Path(path)
    try:
        text = p.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as err:
        raise ConfigError(f"{p}: cannot read the benchmarks description ({err})") from err
    return parse_descriptions(load_rsbb_yaml(text, str(p)), str(p))


def items_from_result(referee_score: Sequence[Mapping[str, Any]], where: str) -> tuple[Item, ...]:
    """A result file's ``referee_score`` (``group_name``, ``desc``, ``type``,
    ``current_value`` per item) as items.

    Raises:
        ConfigError: an item without those keys or with a value that is not a whole number.
    """
    out = []
    for k, raw in enumerate(referee_score):
        value = raw.get("current_value")
        if not isinstance(value, int) or isinstance(value, bool) or value < 0:
            raise ConfigError(f"{where}: referee_score[{k}].current_value {value!r} is not a count")
        out.append(
            Item(
                str(raw.get("group_name", "")),
                str(raw.get("type", "")),
                str(raw.get("desc", "")),
                value,
            )
        )
    return tuple(out)


def match_description(
    items: Sequence[Item], spec: Sequence[ItemSpec]
) -> tuple[tuple[Item, ...], tuple[str, ...]]:
    """The logged ``items`` in the description's order and its groups, and one line per
    difference (an item the description lacks, one the log lacks: kept at 0)."""
    notes: list[str] = []
    left = list(items)
    out: list[Item] = []
    for s in spec:
        found = next((i for i in left if i.desc == s.desc and i.group == s.group), None)
        if found is None:
            found = next((i for i in left if i.desc.strip() == s.desc.strip()), None)
        if found is None:
            notes.append(f"item not in the log, counted 0: {s.group}: {s.desc}")
            out.append(Item(s.group, s.kind, s.desc, 0))
            continue
        left.remove(found)
        out.append(Item(s.group, s.kind, s.desc, found.value))
    for extra in left:
        notes.append(f"item not in the description, kept: {extra.group}: {extra.desc}")
        out.append(extra)
    return tuple(out), tuple(notes)


@frozen_dataclass
class Tally:
    """The items added up by role (ertools' reading of the ERL rule).

    Attributes:
        achievements: the achievement items' values added up.
        penalties: the penalty items' values added up.
        disqualified: the descriptions of the disqualifying items with a value above 0.
    """

    achievements: int
    penalties: int
    disqualified: tuple[str, ...]


def tally(items: Iterable[Item]) -> Tally:
    """Add the items up by role (a ``bool`` item counts 0 or 1, capped so)."""
    achievements = penalties = 0
    out: list[str] = []
    for item in items:
        value = min(item.value, 1) if item.kind == "bool" else item.value
        if item.role is Role.ACHIEVEMENT:
            achievements += value
        elif item.role is Role.PENALTY:
            penalties += value
        elif item.role is Role.DISQUALIFYING and value > 0:
            out.append(item.desc)
    return Tally(achievements, penalties, tuple(out))


def erl_order(t: Tally, seconds: float | None) -> tuple[int, int, float]:
    """The ERL order of a run as a sort key, smaller first: most achievements, then fewest
    penalties, then least time (an unknown time last)."""
    return (-t.achievements, t.penalties, float("inf") if seconds is None else seconds)
