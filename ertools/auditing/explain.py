"""Why a live score value and the recomputed one differ: the known causes by key and benchmark
(the 2015 node's rules, the inputs that move a value) and patterns recognised in the two
numbers themselves (the orientation wrap, different time origins).
"""

from __future__ import annotations

import math
import re
from typing import Any

from ertools.benchmarks import registry
from ertools.benchmarks.base import Audited, Explanation

# Explanations every benchmark shares; a benchmark declares its own
# (``explanations`` of :class:`ertools.benchmarks.base.Audited`), tried first.
_GENERAL: tuple[Explanation, ...] = (
    Explanation(
        r"(time|_time)$",
        "the live node timed with its own wall clock (time.time()) as messages arrived; "
        "ertools uses the record times of the logged state messages (differences of a few "
        "milliseconds up to one 10 Hz heartbeat per transition)",
    ),
)

_WORDS = re.compile(r"[a-z]+")
_STOP_WORDS = frozenset({"error", "errors", "accuracy", "details", "best", "total", "value"})


def explain(
    key: str,
    live: Any,
    recomputed: Any,
    *,
    benchmark: str,
    parameters: tuple[tuple[str, str], ...],
    deviations: tuple[str, ...],
    warnings: tuple[str, ...] = (),
) -> str:
    """Why ``live`` and ``recomputed`` differ at ``key``: rules, recognised patterns,
    matching deviations from 2015, the scorer's warnings about the same parameters (d_min
    below the noise...) and the relevant parameter values."""
    leaf = key.rsplit(".", 1)[-1].lower()
    parts: list[str] = []
    wanted: list[str] = []
    if is_number(live) and is_number(recomputed):
        pattern = _number_pattern(leaf, float(live), float(recomputed))
        if pattern:
            parts.append(pattern)
    bench = registry.get(benchmark) if benchmark in registry.names() else None
    own = bench.explanations if isinstance(bench, Audited) else ()
    for rule in (*own, *_GENERAL):
        if re.search(rule.pattern, leaf):
            parts.append(rule.text)
            wanted.extend(rule.params)
            break
    # Deviations are matched by the key's own words; words every score uses say nothing.
    words = {w for w in _WORDS.findall(leaf.replace("_", " ")) if len(w) > 3} - _STOP_WORDS
    for dev in deviations:
        if words & set(_WORDS.findall(dev.lower())):
            parts.append(f"ertools differs from 2015: {dev}")
    for warning in warnings:
        if any(frag in warning.lower() for frag in wanted if len(frag) > 3):
            parts.append(f"the scorer warned: {warning}")
    shown = [
        f"{name}={value}"
        for name, value in parameters
        if any(frag in name.lower() for frag in wanted)
    ]
    if shown:
        parts.append("recomputed with " + ", ".join(shown))
    if not parts:
        parts.append(
            "no specific cause known for this key: compare the parameters and the "
            "deviations from 2015 listed with the comparison"
        )
    return "; ".join(parts)


def _number_pattern(leaf: str, live: float, rec: float) -> str:
    """Causes recognisable from the two numbers alone."""
    if "orientation" in leaf and live < 0 <= rec and math.isclose(-live, rec, abs_tol=1e-6):
        return (
            "the live value is the negative of the recomputed one: the unwrapped yaw "
            "difference of the 2015 node exceeded pi (orientation wrap), "
            "so atan2(sin, cos) came out negative"
        )
    if "time" in leaf and abs(live - rec) > 1e8:
        return "the two times use different origins (epoch vs seconds from the bag's start)"
    return ""


def is_number(value: Any) -> bool:
    return isinstance(value, int | float) and not isinstance(value, bool)
