"""Are the results of a season the same in every configuration? (issue 29: "identical results
in every configuration")

Two ``results.json`` documents of the same competition are compared on what they say about
the competition: every execution's status, reason, score (intervals and uncertainty
included), rank value, warnings, deviations and live-score comparison, the leaderboards, the
problems, the ledger of files and the inputs' hashes. Left out, because they describe the run
and not the results: when it ran (``generated``), how (``command``, ``options``), the
manifest's own path, and per execution where its report folder is (``report``: none with
``--no-reports``), whether it came from the cache (``cached``) and how long it took
(``seconds``). Numbers are compared exactly: the same code on the same logs with the same
seeds gives the same bits, whatever the workers.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

RUN_ONLY = ("generated", "command", "options", "manifest")
ROW_RUN_ONLY = ("report", "cached", "seconds")


def comparable(doc: Mapping[str, Any], ids: set[str] | None = None) -> dict[str, Any]:
    """What ``doc`` says about the competition (see the module's docstring); ``ids``: only
    those executions, and none of the document-wide parts (a day within a season)."""
    rows = {
        str(row["id"]): {k: v for k, v in row.items() if k not in ROW_RUN_ONLY}
        for row in doc.get("executions") or []
        if ids is None or row["id"] in ids
    }
    if ids is not None:
        return {"executions": rows}
    out = {k: v for k, v in doc.items() if k not in RUN_ONLY and k != "executions"}
    out["executions"] = rows
    return out


def differences(a: Any, b: Any, path: str = "", limit: int = 5) -> list[str]:
    """Where ``a`` and ``b`` differ (dotted paths with both values), at most ``limit``."""
    out: list[str] = []
    _diff(a, b, path, out, limit)
    return out


def _diff(a: Any, b: Any, path: str, out: list[str], limit: int) -> None:
    if len(out) >= limit:
        return
    if isinstance(a, Mapping) and isinstance(b, Mapping):
        for key in sorted(set(a) | set(b), key=str):
            where = f"{path}.{key}" if path else str(key)
            if key not in a or key not in b:
                out.append(f"{where}: only in {'the first' if key in a else 'the second'}")
            else:
                _diff(a[key], b[key], where, out, limit)
            if len(out) >= limit:
                return
        return
    if isinstance(a, list) and isinstance(b, list):
        if len(a) != len(b):
            out.append(f"{path}: {len(a)} items against {len(b)}")
            return
        for i, (x, y) in enumerate(zip(a, b, strict=True)):
            _diff(x, y, f"{path}[{i}]", out, limit)
        return
    # exact, and type-strict (1 and 1.0 and True are three answers); NaN is never written
    if type(a) is not type(b) or a != b:
        out.append(f"{path}: {a!r} against {b!r}")


def compare(
    runs: Sequence[tuple[str, Mapping[str, Any]]], limit: int = 5
) -> tuple[bool, dict[str, list[str]]]:
    """Every run's comparable results against the first one's: (all identical, the
    differences of each run that differs, by its label)."""
    if not runs:
        return True, {}
    _, first = runs[0]
    found = {}
    for label, doc in runs[1:]:
        diff = differences(first, doc, limit=limit)
        if diff:
            found[label] = diff
    return not found, found
