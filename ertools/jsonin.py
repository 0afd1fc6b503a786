"""Reading JSON: Python's json module, with a key given twice refused (it keeps the last one
silently, as PyYAML does: :mod:`ertools.yamlin`), naming both lines."""

from __future__ import annotations

import json
import re
from typing import Any


class DuplicateKeyError(ValueError):
    """A JSON object gives a key twice."""


def _unique_keys(pairs: list[tuple[str, Any]]) -> dict[str, Any]:
    out = dict(pairs)
    if len(out) != len(pairs):
        raise DuplicateKeyError
    return out


# a JSON text's tokens: strings (escapes kept), punctuation, anything else up to a delimiter
_TOKEN = re.compile(r'"(?:[^"\\]|\\.)*"|[{}\[\]:,]|[^\s{}\[\]:,"]+')


def _first_duplicate(text: str) -> str:
    """``duplicate key 'k' at line L (first at line F)`` of a valid JSON text holding one,
    found by a scan of its tokens (the json module's hook says that a key repeats, not
    where)."""
    stack: list[dict[str, int] | None] = []  # per open object: key -> line; None: a list
    tokens = list(_TOKEN.finditer(text))
    for k, m in enumerate(tokens):
        token = m.group()
        if token in "{[":
            stack.append({} if token == "{" else None)
        elif token in "}]":
            stack.pop()
        elif (
            token.startswith('"')
            and stack
            and (keys := stack[-1]) is not None
            and k + 1 < len(tokens)
            and tokens[k + 1].group() == ":"
        ):
            key, line = json.loads(token), text.count("\n", 0, m.start()) + 1
            if key in keys:
                return f"duplicate key {key!r} at line {line} (first at line {keys[key]})"
            keys[key] = line
    return "a key given twice"


def loads(text: str) -> Any:
    """The data of a JSON text.

    Raises:
        json.JSONDecodeError: malformed JSON.
        DuplicateKeyError: an object giving a key twice (the message names both lines).
    """
    try:
        return json.loads(text, object_pairs_hook=_unique_keys)
    except DuplicateKeyError:
        raise DuplicateKeyError(_first_duplicate(text)) from None
