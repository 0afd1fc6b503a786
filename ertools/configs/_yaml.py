"""Safe YAML loading shared by every config format."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import yaml

from ertools.errors import ConfigError


def load_yaml(path: str | Path, what: str = "config") -> Any:
    """Parse a YAML file with ``yaml.safe_load``; errors become one-line ``ConfigError``s."""

    p = Path(path)
    try:
        text = p.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise ConfigError(f"{what} file not found", path=p) from None
    except (OSError, UnicodeDecodeError) as err:
        raise ConfigError(f"cannot read {what} file: {err}", path=p) from err
    return parse_yaml(text, source=str(p), what=what)


def parse_yaml(text: str, source: str = "<string>", what: str = "YAML") -> Any:
    """Parse YAML text (a payload, a config) with ``yaml.safe_load``."""

    try:
        return yaml.safe_load(text)
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
