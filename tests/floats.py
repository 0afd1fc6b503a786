"""Text outputs compared with their numbers as floats, to within float rounding.

NumPy picks its sin/cos/exp code by CPU (AVX2, AVX-512, ...): results agree to a few ulp
(~1e-15 relative), not bit for bit, so an output recorded on one machine differs in its last
digits on another (``2.4975740711248`` against ``2.49757407112479``). Any real change of an
output is far larger than 1e-9 relative: a score moving by a micrometre, a window edge by a
millisecond. Numbers of a million and more (epoch times, nanosecond counts) must match
digit for digit: they come from integers, not from NumPy's maths, and 1e-9 of an epoch time
is over a second.
"""

from __future__ import annotations

import math
import re

FLOAT_RTOL = 1e-9
FLOAT_ATOL = 1e-12
EXACT_FROM = 1e6

_NUMBER = re.compile(r"([-+]?(?:\d+\.\d*|\.\d+|\d+)(?:[eE][-+]?\d+)?)")


def text_difference(a: str, b: str) -> str | None:
    """None when ``a`` and ``b`` are the same text with the same numbers (floats within
    :data:`FLOAT_RTOL`), else where they first differ."""
    pa, pb = _NUMBER.split(a), _NUMBER.split(b)
    if len(pa) != len(pb):
        return "the texts differ in their words or in how many numbers they hold"
    for i, (x, y) in enumerate(zip(pa, pb, strict=True)):
        if i % 2 == 0 and x != y:
            return f"text {x[:60]!r} != {y[:60]!r}"
        if i % 2 and x != y and not _close(x, y):
            return f"number {x} != {y}"
    return None


def _close(x: str, y: str) -> bool:
    a, b = float(x), float(y)
    if max(abs(a), abs(b)) >= EXACT_FROM:
        return False  # written from integers: the text is exact
    return math.isclose(a, b, rel_tol=FLOAT_RTOL, abs_tol=FLOAT_ATOL)


def same_text(a: str, b: str) -> bool:
    """Equal text, numbers written in it compared as floats (see :func:`text_difference`)."""
    return text_difference(a, b) is None
