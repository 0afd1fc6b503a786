"""A goal's result as an RSBB script read it: the robot's string through ``yaml.load``, a
mapping of the fields its benchmark asks for (HOPF: class, instance and pose; HPPF: the name
and position), and which values the script could take as numbers.
"""

from __future__ import annotations

from typing import Any

import yaml


def is_number(value: Any) -> bool:
    """A value the script took as a number (``float()`` and ``%.2f`` accept it): an int (a
    bool too) or a float, not text, not an int too large for a float."""
    if not isinstance(value, int | float):
        return False
    try:
        float(value)
    except OverflowError:
        return False
    return True


def parse_answer(text: str) -> tuple[Any, str | None]:
    """The result string parsed, and what makes it no mapping of fields (None: it is one).

    The value is None when the text is no YAML at all, else what YAML made of it.
    """
    try:
        data = yaml.safe_load(text)
    except yaml.YAMLError:
        return None, "the result is not YAML"
    if not isinstance(data, dict):
        what = "empty" if data is None else f"a {type(data).__name__}, not a mapping"
        return data, f"the result is {what}"
    return data, None
