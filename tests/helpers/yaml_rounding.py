"""Compare a YAML output with the full-precision data it was written from.

``ertools.serialize.dump_yaml`` rounds floats to 9 decimal places, so a YAML value is at
most half a unit of the 9th decimal (5e-10) from its float64 (plus the float's own rounding of
that decimal, far below 1e-15 for values under 1e3); JSON keeps every bit.
"""

from __future__ import annotations

import math
from typing import Any

YAML_ROUNDING = 5e-10 + 1e-15


def assert_yaml_of(written: Any, full: Any, path: str = "") -> None:
    """``written`` (parsed YAML) is ``full`` with its floats rounded to 9 decimals: same
    nesting, keys, order and non-float values; floats within :data:`YAML_ROUNDING`."""
    if isinstance(full, dict):
        assert isinstance(written, dict) and list(written) == list(full), path
        for key in full:
            assert_yaml_of(written[key], full[key], f"{path}.{key}")
    elif isinstance(full, list | tuple):
        assert isinstance(written, list) and len(written) == len(full), path
        for i, (w, f) in enumerate(zip(written, full, strict=True)):
            assert_yaml_of(w, f, f"{path}[{i}]")
    elif isinstance(full, float) and not isinstance(full, bool):
        assert isinstance(written, float | int), path
        if math.isnan(full):
            assert math.isnan(written), path
        else:
            assert abs(written - full) <= YAML_ROUNDING, (path, written, full)
    else:
        assert written == full, path
