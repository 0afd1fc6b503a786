"""A result as ``ertools score NAME --format json`` prints it: one function, shared by the
score commands and ``ertools rescore`` (whose ``results.json`` must hold exactly that object)."""

from __future__ import annotations

from typing import Any

from ertools.benchmarks.base import BenchmarkResult
from ertools.serialize import jsonable


def score_json(result: BenchmarkResult) -> dict[str, Any]:
    """The JSON object of a result (NumPy values as plain numbers, NaN as null)."""
    document: dict[str, Any] = jsonable(result.to_dict())
    return document


def all_failed(result: object) -> bool:
    """True when a result has failures and no honest number at all (every run, segment or
    pose failed: the result's ``nothing_scored``). Such a result is never printed: only its
    failures, one ``ertools: error:`` line each on stderr, nothing on stdout, exit 1. A result
    where some runs scored is printed, failed ones as null with their error on stderr."""
    return bool(getattr(result, "failures", ())) and bool(getattr(result, "nothing_scored", False))
