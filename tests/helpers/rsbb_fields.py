"""Two RSBB scores compared field for field (the replays' parity tests): mappings with the
same keys, numbers within a tolerance, strings, booleans and nulls exactly (type included)."""

from __future__ import annotations

import math
from typing import Any

#: Both sides read the same log and do the same float operations; what may differ is the
#: order of a few additions in tf's composition (a few ulps of 1 m).
TOL = 1e-12


def same(a: Any, b: Any, where: str = "score", tol: float = TOL) -> None:
    """Assert ``a`` and ``b`` agree field for field; the message names the first field that
    does not."""
    if isinstance(a, dict) or isinstance(b, dict):
        assert isinstance(a, dict) and isinstance(b, dict), f"{where}: {a!r} vs {b!r}"
        assert sorted(a) == sorted(b), f"{where}: keys {sorted(a)} vs {sorted(b)}"
        for k in a:
            same(a[k], b[k], f"{where}.{k}", tol)
        return
    if isinstance(a, list) or isinstance(b, list):
        assert isinstance(a, list) and isinstance(b, list) and len(a) == len(b), where
        for k, (x, y) in enumerate(zip(a, b, strict=True)):
            same(x, y, f"{where}[{k}]", tol)
        return
    if isinstance(a, float) or isinstance(b, float):
        assert type(a) in (int, float) and type(b) in (int, float), f"{where}: {a!r} vs {b!r}"
        if math.isnan(a) or math.isnan(b):
            assert math.isnan(a) and math.isnan(b), where
        else:
            assert abs(a - b) <= tol, f"{where}: {a!r} vs {b!r}"
        return
    assert type(a) is type(b) and a == b, f"{where}: {a!r} vs {b!r}"
