"""Outputs compared with their numbers as floats, each within what its quantity may move
between CPUs (docs/qa.md, "Results on every CPU").

NumPy picks its transcendental functions (sin, cos, arctan2, exp...) by instruction set (its
AVX-512, AVX2 or baseline code, or the C library's) and OpenBLAS its kernels by CPU: the
results agree to an ulp or two, not bit for bit. Basic arithmetic, sums and sorts give the
same bits on every path. Measured on the golden outputs and the sample competition's
rescore (an AVX-512 CPU as users run it, against NumPy's AVX-512 targets off, OpenBLAS's
Haswell kernels, and every SIMD target off with OpenBLAS's oldest kernels): scores and
intervals moved by 4.9e-14 relative at most, a difference of two nearly equal angles by
4.4e-16 absolute, an interval's variance shares by 3.2e-11 relative (1.0e-12 before the
closed forms of issue 39). The tolerances, per quantity:

- :data:`EXACT`: integers, and numbers of a million and more (epoch times, nanosecond
  counts: they come from integers, and 1e-12 of an epoch time is a millisecond);
- :data:`VALUE`: every other number (scores, intervals, poses, times from the start);
- :data:`SHARE`: a source's share of an interval, a ratio of the variances of Monte Carlo
  draws; each draw is a score re-computed (s, moving by its last bits) and the variance of
  draws spread by sigma around it moves by those bits times s / sigma;
- a number that was rounded on output (YAML's 9 decimals, ``ertools.serialize``) may in
  addition move by one unit in its last digit (:data:`YAML_UNIT`): a value within its
  quantity's tolerance of a rounding boundary rounds either way. Numbers written with fewer
  digits inside text (a note's ``1.538 ms``) get no such allowance: a value within 1e-12 of
  a boundary of its 4th digit happens once in 1e8.
"""

from __future__ import annotations

import csv
import io
import json
import math
import re
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import yaml


@dataclass(frozen=True)
class Tolerance:
    """``|a - b| <= rel * max(|a|, |b|) + abs``."""

    rel: float
    abs: float

    def allows(self, a: float, b: float, rounded: float = 0.0) -> bool:
        if math.isnan(a) or math.isnan(b):
            return math.isnan(a) and math.isnan(b)
        if a == b:
            return True  # equal infinities too
        return abs(a - b) <= self.rel * max(abs(a), abs(b)) + self.abs + rounded


# Scores and intervals: 20 times the worst measured (4.9e-14). Absolute 1e-12 (a picometre,
# a picoradian): a difference of two positions within 100 m or two angles within 360
# degrees carries their last bits (ulp 1.4e-14 and 5.7e-14), whatever its own size.
VALUE = Tolerance(rel=1e-12, abs=1e-12)
# Variance shares: 30 times the worst measured (3.2e-11, the closed forms of issue 39: docs/qa.md);
# module doc.
SHARE = Tolerance(rel=1e-9, abs=1e-12)
EXACT = Tolerance(rel=0.0, abs=0.0)
EXACT_FROM = 1e6
YAML_UNIT = 1e-9  # one in the ninth decimal (ertools.serialize)

# The names the old tests import: a value's tolerance.
FLOAT_RTOL = VALUE.rel
FLOAT_ATOL = VALUE.abs

_NUMBER = re.compile(r"([-+]?(?:\d+\.\d*|\.\d+|\d+)(?:[eE][-+]?\d+)?)")
_INTEGER = re.compile(r"[-+]?\d+")

Quantity = Callable[[str], Tolerance]


def quantity(path: str) -> Tolerance:
    """The tolerance of the number at ``path`` (``.uncertainty.shares.rmse.mocap_noise``,
    ``interval_shares.csv:share_mocap_noise``): shares are variance ratios (module doc)."""
    parts = re.split(r"[.:\[\]]", path)
    if "shares" in parts or any(p == "share" or p.startswith("share_") for p in parts):
        return SHARE
    return VALUE


def _number_difference(x: str, y: str, tol: Tolerance, rounded: float) -> bool:
    """Whether two numbers as written are the same within ``tol``."""
    if x == y:
        return True
    if _INTEGER.fullmatch(x) or _INTEGER.fullmatch(y):
        return False  # counts, indexes, nanoseconds: exact
    a, b = float(x), float(y)
    if max(abs(a), abs(b)) >= EXACT_FROM:
        return False  # written from integers: the text is exact
    return tol.allows(a, b, rounded)


def text_difference(a: str, b: str, tol: Tolerance = VALUE, rounded: float = 0.0) -> str | None:
    """None when ``a`` and ``b`` are the same text with the same numbers (within ``tol``,
    plus ``rounded`` where they were rounded on output), else where they first differ."""
    pa, pb = _NUMBER.split(a), _NUMBER.split(b)
    if len(pa) != len(pb):
        return "the texts differ in their words or in how many numbers they hold"
    for i, (x, y) in enumerate(zip(pa, pb, strict=True)):
        if i % 2 == 0 and x != y:
            return f"text {x[:60]!r} != {y[:60]!r}"
        if i % 2 and not _number_difference(x, y, tol, rounded):
            return f"number {x} != {y}"
    return None


def same_text(a: str, b: str) -> bool:
    """Equal text, numbers written in it compared as values (see :func:`text_difference`)."""
    return text_difference(a, b) is None


def tree_difference(a: Any, b: Any, path: str = "", rounded: float = 0.0) -> str | None:
    """Where two parsed documents (JSON or YAML) first differ: same keys in the same order,
    same types, strings by :func:`text_difference`, floats by their :func:`quantity`."""
    if isinstance(a, dict) and isinstance(b, dict):
        if list(a) != list(b):
            return f"{path}: keys {list(a)} != {list(b)}"
        for key in a:
            found = tree_difference(a[key], b[key], f"{path}.{key}", rounded)
            if found is not None:
                return found
        return None
    if isinstance(a, list) and isinstance(b, list):
        if len(a) != len(b):
            return f"{path}: {len(a)} items != {len(b)}"
        for i, (x, y) in enumerate(zip(a, b, strict=True)):
            found = tree_difference(x, y, f"{path}[{i}]", rounded)
            if found is not None:
                return found
        return None
    if isinstance(a, str) and isinstance(b, str):
        where = text_difference(a, b)
        return None if where is None else f"{path}: {where}"
    if {type(a), type(b)} in ({float}, {float, int}):
        if a == b or (max(abs(a), abs(b)) < EXACT_FROM and quantity(path).allows(a, b, rounded)):
            return None
        return f"{path}: {a!r} != {b!r}"
    return None if type(a) is type(b) and a == b else f"{path}: {a!r} != {b!r}"


def csv_difference(a: str, b: str, name: str = "") -> str | None:
    """Where two CSV texts first differ: cells that are numbers by their column's
    :func:`quantity` (``name:column``), the others as text."""
    ra, rb = list(csv.reader(io.StringIO(a))), list(csv.reader(io.StringIO(b)))
    if len(ra) != len(rb) or not ra:
        return None if ra == rb else f"{len(ra)} rows != {len(rb)}"
    header = ra[0]
    for r, (x, y) in enumerate(zip(ra, rb, strict=True)):
        if len(x) != len(y):
            return f"row {r}: {len(x)} cells != {len(y)}"
        for c, (u, v) in enumerate(zip(x, y, strict=True)):
            column = header[c] if c < len(header) else str(c)
            where = f"row {r}, {column}"
            if _NUMBER.fullmatch(u) and _NUMBER.fullmatch(v):
                if not _number_difference(u, v, quantity(f"{name}:{column}"), 0.0):
                    return f"{where}: number {u} != {v}"
            elif (found := text_difference(u, v)) is not None:
                return f"{where}: {found}"
    return None


def output_difference(a: str, b: str, fmt: str, name: str = "") -> str | None:
    """Where output ``a`` differs from ``b`` (format ``json``, ``yaml``, ``csv`` or ``text``).

    First the text itself, numbers left out (layout, words and key order exactly; numbers
    within their quantity's tolerance, which the structure tells where it has one).
    """
    rounded = YAML_UNIT if fmt == "yaml" else 0.0
    found = text_difference(a, b, Tolerance(math.inf, math.inf))
    if found is not None:
        return found
    if fmt == "json":
        return tree_difference(json.loads(a), json.loads(b))
    if fmt == "yaml":
        return tree_difference(yaml.safe_load(a), yaml.safe_load(b), rounded=rounded)
    if fmt == "csv":
        return csv_difference(a, b, name)
    return text_difference(a, b)
