"""Safe YAML loading shared by every config format.

Every config and the manifest go through here, so the limits on what a file may hold are set
once: those of :mod:`ertools.yamlin` (nesting no deeper than its ``MAX_DEPTH``, aliases
included; no key given twice), and, in files, numbers that are numbers:
finite, and no larger in size than :data:`MAX_NUMBER` (no metre, second, radian or count in a
config comes near; a 400-digit integer or ``1e300`` would overflow the first conversion to
nanoseconds or to float). Each reader checks its own keys' ranges with :func:`number`.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import yaml

from ertools.errors import ConfigError
from ertools.inputs import read_regular_text, why_not
from ertools.yamlin import DuplicateKey, Tags
from ertools.yamlin import load as load_yaml_text

log = logging.getLogger("ertools.configs")

# int64 nanoseconds hold ~9.2e18; a float beyond this cannot be a time, a length or a count
MAX_NUMBER = 9.2e18


def load_yaml(path: str | Path, what: str = "config", tags: Tags = "safe") -> Any:
    """Parse a YAML file (:func:`parse_yaml`); errors become one-line ``ConfigError``s."""

    p = Path(path)
    try:
        text = read_regular_text(p)  # a named pipe would block open() for ever
    except FileNotFoundError:
        raise ConfigError(f"{what} file not found", path=p) from None
    except OSError as err:
        raise ConfigError(f"cannot read {what} file: {why_not(err)}", path=p) from err
    except UnicodeDecodeError as err:
        raise ConfigError(f"cannot read {what} file: {err}", path=p) from err
    return check_numbers(parse_yaml(text, source=str(p), what=what, tags=tags), str(p))


def parse_yaml(text: str, source: str = "<string>", what: str = "YAML", tags: Tags = "safe") -> Any:
    """Parse a config's YAML text (:func:`ertools.yamlin.load`: safe tags, nesting limited,
    duplicate keys refused); errors become one-line ``ConfigError``s naming the line."""

    try:
        return load_yaml_text(text, tags=tags)
    except RecursionError:  # the loader's depth limit comes first; called from deep, say so
        raise ConfigError(f"malformed {what}: nested too deep", path=source) from None
    except yaml.YAMLError as err:
        raise ConfigError(f"malformed {what}{_where(err)}", path=source) from err


def parse_payload(text: str, source: str, what: str = "payload", tags: Tags = "safe") -> Any:
    """Parse a state payload's YAML as the 2015 nodes did (PyYAML: of a key given twice, the
    last value counts), warning of each duplicate: the bag records what the live system read,
    and a rescore that refused it would drop a run the live score counted
    (docs/fidelity.md, "Payloads with a key given twice")."""

    duplicates: list[DuplicateKey] = []
    try:
        data = load_yaml_text(text, tags=tags, duplicates=duplicates)
    except RecursionError:
        raise ConfigError(f"malformed {what}: nested too deep", path=source) from None
    except yaml.YAMLError as err:
        raise ConfigError(f"malformed {what}{_where(err)}", path=source) from err
    for d in duplicates:
        log.warning(
            "%s: %s of the %s: the last value is used, as the 2015 nodes read it",
            source,
            d.text(),
            what,
        )
    return data


def _where(err: yaml.YAMLError) -> str:
    """`` at line L, column C: problem`` of a PyYAML error, on one line."""
    mark = getattr(err, "problem_mark", None)
    where = f" at line {mark.line + 1}, column {mark.column + 1}" if mark is not None else ""
    problem = getattr(err, "problem", None) or str(err).splitlines()[0]
    return f"{where}: {problem}"


def require(mapping: Any, key: str, source: str, what: str) -> Any:
    """``mapping[key]``, or a ``ConfigError`` saying which key is missing where."""
    if not isinstance(mapping, dict):
        raise ConfigError(f"{what}: expected a mapping, got {type(mapping).__name__}", path=source)
    if key not in mapping:
        raise ConfigError(f"{what}: missing key {key!r}", path=source)
    return mapping[key]


def show(value: Any) -> str:
    """A value for a message, short: a 400-digit integer by its size, not its digits."""
    text = repr(value)
    if len(text) > 40:
        digits = f" ({len(text)} digits)" if isinstance(value, int) else ""
        return f"{text[:20]}...{digits}"
    return text


def _walk(data: Any, where: str) -> Iterator[tuple[str, Any]]:
    # iterative: the depth is limited by the loader, but data may come from elsewhere; each
    # container once: YAML aliases share one object (a "billion laughs" file is 10 lists
    # referring 9 times each to the previous one: a billion paths, ten objects)
    stack = [(where, data)]
    seen: set[int] = set()
    while stack:
        key, value = stack.pop()
        if isinstance(value, dict | list | tuple):
            if id(value) in seen:
                continue
            seen.add(id(value))
        if isinstance(value, dict):
            stack.extend((f"{key}.{k}" if key else str(k), v) for k, v in value.items())
        elif isinstance(value, list | tuple):
            stack.extend((f"{key}[{i}]", v) for i, v in enumerate(value))
        else:
            yield key, value


def check_numbers(data: Any, source: str) -> Any:
    """``data`` unchanged, or a ConfigError naming the first number (key path and value)
    that is not finite or is larger in size than :data:`MAX_NUMBER`."""
    for key, value in _walk(data, ""):
        if isinstance(value, bool) or not isinstance(value, int | float):
            continue
        number(value, key or "the file", source)
    return data


# An angle in radians beyond a full turn either way is no heading but a number in degrees (a
# goal's theta of 180 scored an orientation error of 1.744 rad instead of 0.070); the slack
# admits 2*pi written with fewer digits than the float's.
FULL_TURN = 2.0 * math.pi + 1e-6


def check_radians(
    value: float, key: str, source: str, *, limit: float = FULL_TURN, bound: str = "2 pi"
) -> float:
    """``value`` when it is an angle of at most ``limit`` radians (``bound`` in words) either
    way, else a ConfigError naming the key and what the value would be in degrees."""
    if abs(value) <= limit:
        return value
    raise ConfigError(
        f"{key}: {value:g} is more than {bound} either way: angles are in radians here "
        f"({value:g} degrees would be {math.radians(value):.4f} rad)",
        path=source,
    )


def number(
    value: Any,
    key: str,
    source: str,
    *,
    low: float = -MAX_NUMBER,
    high: float = MAX_NUMBER,
    unit: str = "",
) -> float:
    """``value`` as a float when it is a finite number in [``low``, ``high``]; else a
    ConfigError naming the file (``source``), the key and the value."""
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise ConfigError(f"{key}: expected a number, got {show(value)}", path=source)
    if isinstance(value, int) and not -MAX_NUMBER <= value <= MAX_NUMBER:
        raise ConfigError(f"{key}: {show(value)} is too large a number", path=source)
    f = float(value)
    if not math.isfinite(f):
        raise ConfigError(f"{key}: {show(value)} is not a finite number", path=source)
    if not low <= f <= high:
        raise ConfigError(
            f"{key}: {show(value)}{unit and ' ' + unit} is out of range "
            f"({low:g} to {high:g}{unit and ' ' + unit})",
            path=source,
        )
    return f
