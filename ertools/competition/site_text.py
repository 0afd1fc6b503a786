"""How the results page words what ``results.json`` holds: numbers in one unit per quantity at
the data's resolution, paths relative to the organiser's folder, options as manifest keys,
and warnings said once per benchmark.

``results.json`` keeps the seed's units (metres, radians, seconds) at full float precision and
absolute paths; a referee reads the page, where ``0.0006389302989094458`` (metres, 0.1 nm) is
noise and ``give --robot-topic`` is advice for a command nobody typed. Pure: strings in,
strings out.
"""

from __future__ import annotations

import math
import os
import re
from collections.abc import Iterable, Mapping, Sequence
from typing import Any

from ertools.benchmarks import registry
from ertools.frozen_dataclass import frozen_dataclass
from ertools.views import units

# What an execution no log and no manifest entry names a team for is called, on the page and
# in results.json: scored, left out of the leaderboards until named.
TEAM_UNKNOWN = "team unknown (name it in the manifest)"
# Decimals per quantity: one table for the site and the reports (ertools.views.units).
DECIMALS = units.DECIMALS
# The rule texts of the registry name the stored unit; the page states the display unit.
_UNIT_WORDS = {"metres": "mm", "meters": "mm", "radians": "degrees", "seconds": "s"}
_FLAG = re.compile(r"(?<![\w-])--[a-z0-9][a-z0-9-]*")
_DIFFERENCE = re.compile(
    r"^(?P<key>[^:]+): live (?P<live>.*?) vs recomputed (?P<rec>.*?)(?:; why: (?P<why>.*))?$"
)
_ROBOT_LOG = re.compile(r"robot log [^\s:()]+")
_LOG_FILE = re.compile(r"[^\s:()]+\.(?:bag(?:\.active)?|mcap|db3)\b")
_RULE_KEY = re.compile(r"\[([a-z0-9_]+\.[a-z0-9_.-]+)\]")


def number(value: Any) -> float | None:
    if isinstance(value, bool) or not isinstance(value, int | float):
        return None
    return None if math.isnan(value) or math.isinf(value) else float(value)


def shown(key: str | None, value: Any) -> str:
    """``value`` (stored unit) as the page shows it: in the display unit of ``key``'s quantity
    at :data:`DECIMALS`; other numbers with 6 significant digits; None as an em dash."""
    x = number(value)
    if x is None:
        if value is None:
            return "\u2014"
        if isinstance(value, bool):
            return "yes" if value else "no"
        numbers = registry.live_numbers(str(value))
        if numbers is not None:  # a benchmark's live value logged as text
            return ", ".join(f"{k.rpartition('.')[2]} {with_unit(k, v)}" for k, v in numbers)
        return str(value)
    spec = units.quantity_of(key) if key else None
    if spec is None:  # counts, ratios, scores: 6 significant digits, at most 6 decimals
        return str(int(x)) if isinstance(value, int) else f"{round(x, 6):.6g}"
    return f"{x * units.factor(*spec):.{DECIMALS[spec[0]]}f}"


def unit_of(key: str | None) -> str:
    spec = units.quantity_of(key) if key else None
    return units.unit(spec[0]) if spec else ""


def with_unit(key: str | None, value: Any) -> str:
    """``0.64 mm``: :func:`shown` and the unit, where the quantity has one."""
    text = shown(key, value)
    unit = unit_of(key)
    return f"{text} {unit}" if unit and number(value) is not None else text


def rule_text(text: str) -> str:
    """A registry rule in the page's units (``position_accuracy (mm, ...)``)."""
    for word, unit in _UNIT_WORDS.items():
        text = re.sub(rf"\b{word}\b", unit, text)
    return text


_PROSE = re.compile(r"(?<![\w.])(-?\d+(?:\.\d+)?(?:e-?\d+)?) (m|rad)\b(?!/)")


def prose_units(text: str) -> str:
    """Lengths and angles inside a sentence (a deviation, a warning) in the page's units:
    ``clipped at 1 m`` -> ``clipped at 1000.00 mm``, ``0.0900 rad`` -> ``5.16 deg``."""

    def convert(match: re.Match[str]) -> str:
        key = "distance_error" if match.group(2) == "m" else "orientation_error"
        return with_unit(key, float(match.group(1)))

    return _PROSE.sub(convert, text)


class Paths:
    """Absolute paths under the organiser's folder shown relative to it."""

    def __init__(self, root: str, others: Iterable[str] = ()) -> None:
        # The folder scanned first, then any other folder the document's files lie in (a
        # manifest kept beside the logs' folder): the longest match wins.
        bases = [b.rstrip("/") for b in (root, *others) if b and len(b.rstrip("/")) > 1]
        self.root = root.rstrip("/") if root else ""
        self.bases = sorted(set(bases), key=len, reverse=True)
        self._pattern = (
            re.compile(
                "(?:" + "|".join(re.escape(b) for b in self.bases) + r")(?:/[^\s,;:()'\"\[\]]*)?"
            )
            if self.bases
            else None
        )

    def path(self, path: Any) -> str:
        """One path, relative to the folder (``../competition.yaml`` beside it)."""
        text = str(path or "")
        if not text.startswith("/") or not self.root:
            return text
        return os.path.relpath(text, self.root)

    def text(self, text: Any) -> str:
        """Every absolute path inside ``text`` made relative."""
        value = str(text or "")
        if self._pattern is None:
            return value
        return self._pattern.sub(lambda m: self.path(m.group(0)), value)


def manifest_terms(text: str, benchmark: str) -> str:
    """``give --robot-topic`` -> ``give benchmarks.trajectory.inputs.robot_topic``: the
    options a warning names, as the manifest keys that set them (a rescore has no command
    line per execution)."""
    # the execution's benchmark, and one the text names (``... by trajectory``: its robot log)
    named = [n for n in registry.names() if re.search(rf"\bby {re.escape(n)}\b", text)]
    options: dict[str, str] = {}
    for name in [*named, benchmark]:
        if name not in registry.names():
            continue
        for declared in registry.get(name).inputs:
            where = "teams.TEAM" if declared.per_team else "inputs"
            formers = [f.option for f in declared.former]
            for flag in (declared.option, *declared.old_flags, *formers):
                options[flag] = f"benchmarks.{name}.{where}.{declared.name}"
    return _FLAG.sub(lambda m: options.get(m.group(0), m.group(0)), text)


def deviation_terms(text: str) -> str:
    """A deviation's options as manifest keys: its rule key (``[fbm3w.timeout-runs]``) names
    the benchmark (``fbm1.`` the FBM1 benchmarks: the first declaring the option)."""
    keys = _RULE_KEY.findall(text)
    prefix = keys[-1].split(".", 1)[0] if keys else ""
    for name in registry.names():
        if name.startswith(prefix) and prefix:
            translated = manifest_terms(text, name)
            if translated != text:
                return translated
    return text


@frozen_dataclass
class Difference:
    """One ``live_differences`` line as shown: numbers in display units, and why."""

    key: str
    live: str
    recomputed: str
    difference: str
    why: str
    rules: tuple[str, ...]


def _value(text: str) -> Any:
    try:
        return float(text)
    except ValueError:
        return text


def difference(line: str) -> Difference:
    """``key: live X vs recomputed Y; why: ...`` (jobs.py writes them) as shown."""
    match = _DIFFERENCE.match(line.strip())
    if match is None:
        return Difference(line.split(":", 1)[0], "", "", "", line, ())
    key = match.group("key").strip()
    live, rec = _value(match.group("live")), _value(match.group("rec"))
    delta = ""
    a, b = number(live), number(rec)
    if a is not None and b is not None:
        delta = ("+" if b >= a else "") + with_unit(key, b - a)
        if delta.lstrip("+-").split(" ")[0].strip("0.") == "":
            delta = f"below the shown resolution ({with_unit(key, b - a)})"
    why = match.group("why") or ""
    return Difference(
        key,
        with_unit(key, live),
        with_unit(key, rec),
        delta,
        why,
        tuple(dict.fromkeys(_RULE_KEY.findall(why))),
    )


@frozen_dataclass
class Grouped:
    """A warning said once for a benchmark, with the executions it concerns."""

    benchmark: str
    text: str
    executions: tuple[str, ...]
    of: int  # the benchmark's executions


def group_warnings(
    rows: Sequence[Mapping[str, Any]], paths: Paths, *, skip: Iterable[str] = ()
) -> tuple[list[Grouped], dict[str, list[str]]]:
    """Warnings worded for the page (relative paths, manifest keys) and said once per
    benchmark when several of its executions carry the same one; the others stay with their
    execution (returned by id)."""
    skipped = set(skip)
    by_benchmark: dict[str, dict[str, list[tuple[str, str]]]] = {}
    counts: dict[str, int] = {}
    own: dict[str, list[str]] = {}
    for row in rows:
        bench = str(row.get("benchmark"))
        ident = str(row.get("id"))
        counts[bench] = counts.get(bench, 0) + 1
        own[ident] = []
        for warning in row.get("warnings") or []:
            if warning in skipped:
                continue
            text = prose_units(manifest_terms(paths.text(warning), bench))
            # the same advice about each execution's own log is one warning of the benchmark
            key = _LOG_FILE.sub("its log", _ROBOT_LOG.sub("its robot log", text))
            by_benchmark.setdefault(bench, {}).setdefault(key, []).append((ident, text))
    grouped: list[Grouped] = []
    for bench, texts in by_benchmark.items():
        for key, said in texts.items():
            unique = tuple(dict.fromkeys(ident for ident, _ in said))
            if len(unique) > 1:
                same = len({t for _, t in said}) == 1
                grouped.append(Grouped(bench, said[0][1] if same else key, unique, counts[bench]))
            else:
                own[unique[0]] += list(dict.fromkeys(t for _, t in said))
    return grouped, own


__all__ = [
    "DECIMALS",
    "TEAM_UNKNOWN",
    "Difference",
    "Grouped",
    "Paths",
    "deviation_terms",
    "difference",
    "group_warnings",
    "manifest_terms",
    "number",
    "prose_units",
    "rule_text",
    "shown",
    "unit_of",
    "with_unit",
]
