"""Safe YAML loading shared by every config format.

Every config and the manifest go through here, so the limits on what a file may hold are set
once: nesting no deeper than :data:`MAX_DEPTH` (PyYAML's composer recurses, and a file of
thousands of ``[`` would end in a RecursionError), and, in files, numbers that are numbers:
finite, and no larger in size than :data:`MAX_NUMBER` (no metre, second, radian or count in a
config comes near; a 400-digit integer or ``1e300`` would overflow the first conversion to
nanoseconds or to float). Each reader checks its own keys' ranges with :func:`number`.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import yaml

from ertools.errors import ConfigError
from ertools.inputs import read_regular_text, why_not

MAX_DEPTH = 64
# int64 nanoseconds hold ~9.2e18; a float beyond this cannot be a time, a length or a count
MAX_NUMBER = 9.2e18
# seconds: epoch seconds (~1.4e9 in 2015) and bag-relative ones; their nanoseconds fit int64
MAX_SECONDS = 4.6e9


class _Loader(yaml.SafeLoader):
    """``yaml.SafeLoader`` that refuses nesting deeper than :data:`MAX_DEPTH`."""

    depth = 0

    def compose_node(self, parent: Any, index: Any) -> Any:
        self.depth += 1
        try:
            if self.depth > MAX_DEPTH:
                mark = self.peek_event().start_mark  # type: ignore[no-untyped-call]
                raise yaml.YAMLError(
                    f"nested more than {MAX_DEPTH} levels deep at line {mark.line + 1}"
                )
            return super().compose_node(parent, index)
        finally:
            self.depth -= 1


def safe_load(text: str) -> Any:
    """``yaml.safe_load`` with the nesting limit."""
    loader = _Loader(text)
    try:
        return loader.get_single_data()
    finally:
        loader.dispose()


def load_yaml(path: str | Path, what: str = "config") -> Any:
    """Parse a YAML file with ``yaml.safe_load``; errors become one-line ``ConfigError``s."""

    p = Path(path)
    try:
        text = read_regular_text(p)  # a named pipe would block open() for ever
    except FileNotFoundError:
        raise ConfigError(f"{what} file not found", path=p) from None
    except OSError as err:
        raise ConfigError(f"cannot read {what} file: {why_not(err)}", path=p) from err
    except UnicodeDecodeError as err:
        raise ConfigError(f"cannot read {what} file: {err}", path=p) from err
    return check_numbers(parse_yaml(text, source=str(p), what=what), str(p))


def parse_yaml(text: str, source: str = "<string>", what: str = "YAML") -> Any:
    """Parse YAML text (a payload, a config) with ``yaml.safe_load`` (nesting limited)."""

    try:
        return safe_load(text)
    except RecursionError:  # pragma: no cover - the depth limit comes first
        raise ConfigError(f"malformed {what}: nested too deep", path=source) from None
    except yaml.YAMLError as err:
        mark = getattr(err, "problem_mark", None)
        where = f" at line {mark.line + 1}, column {mark.column + 1}" if mark is not None else ""
        problem = getattr(err, "problem", None) or str(err).splitlines()[0]
        raise ConfigError(f"malformed {what}{where}: {problem}", path=source) from err


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
