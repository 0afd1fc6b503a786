"""The results site of ``ertools rescore``: one ``index.html`` from the results document.

:func:`write_site` renders ``DIR/index.html`` from the ``results.json`` document (the dict as
loaded, schema in docs/rescore.md), so the page can be rebuilt from that file alone: per
benchmark a leaderboard by the benchmark's own rule (the rule's text is on the page), the live
2015 score next to the recomputed one with differences flagged, the timeline figure, every
problem, every deviation from 2015 in force, the provenance (manifest, ertools version, every
input's SHA-256) and a row per execution linking its report folder.

The page is the report pages' kind (``ertools.report.html``: the same base template, style
sheet and table cells): no script, nothing fetched, so it opens offline from ``file://``.
Links point only at files inside ``DIR`` that exist when the page is written; a report folder
that is missing is shown as text and said to be missing, never as a dead link.

Pure: :func:`site_context` turns the document into what the template shows;
:func:`write_site` is the IO edge.
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ertools import atomic
from ertools.errors import ConfigError
from ertools.report import html as h
from ertools.report import units

SCHEMA_VERSION = 1
TEMPLATE = "rescore_index.html.j2"
# Figures the page shows as an image; anything else (the interactive timeline page) is framed.
_IMAGE_SUFFIXES = frozenset({".png", ".svg", ".jpg", ".jpeg", ".gif", ".webp"})
STATUS_LEVEL = {"scored": "ok", "unscoreable": "warn", "failed": "bad"}


@dataclass(frozen=True)
class Link:
    """A relative link inside the site's folder; ``href`` None when the target is missing."""

    text: str
    href: str | None


@dataclass(frozen=True)
class Standing:
    """One row of a leaderboard as shown."""

    rank: int | None  # None: not ranked (no value)
    team: str
    value: str  # in the display unit of the column
    live: str  # the live 2015 value of the same key, or an em dash
    differs: bool  # the live 2015 score differs from the recomputed one
    execution: Link


@dataclass(frozen=True)
class Board:
    anchor: str
    title: str
    rule: str
    direction: str
    column: str  # the value's header with its unit
    rows: tuple[Standing, ...]


def _anchor(prefix: str, name: str) -> str:
    return f"{prefix}-{re.sub(r'[^A-Za-z0-9_-]+', '_', name)}"


def _number(value: Any) -> float | None:
    if isinstance(value, bool) or not isinstance(value, int | float):
        return None
    return None if math.isnan(value) else float(value)


def ranked(
    rows: Sequence[dict[str, Any]], lower_is_better: bool
) -> list[tuple[int | None, dict[str, Any]]]:
    """Leaderboard rows ordered by their ``value`` with competition ranks (1, 2, 2, 4).

    Equal values share a rank, in team order; rows without a value come last, unranked. The
    order is computed here from the values rather than trusted from the document, so a page
    rebuilt from a hand-edited ``results.json`` still ranks by the rule it states.
    """
    valued = [r for r in rows if _number(r.get("value")) is not None]
    unvalued = [r for r in rows if _number(r.get("value")) is None]
    sign = 1.0 if lower_is_better else -1.0

    def key(r: dict[str, Any]) -> tuple[float, str, str]:
        value = _number(r.get("value"))
        assert value is not None
        return sign * value, str(r.get("team", "")), str(r.get("execution", ""))

    out: list[tuple[int | None, dict[str, Any]]] = []
    previous: float | None = None
    rank = 0
    for i, row in enumerate(sorted(valued, key=key), start=1):
        value = _number(row.get("value"))
        if value != previous:
            rank, previous = i, value
        out.append((rank, row))
    out += [(None, r) for r in sorted(unvalued, key=lambda r: str(r.get("team", "")))]
    return out


def _value_key(score: dict[str, Any] | None, value: float | None) -> str | None:
    """The score's top-level key whose value the leaderboard ranks by (for its unit)."""
    if not isinstance(score, dict) or value is None:
        return None
    return next((k for k, v in score.items() if _number(v) == value), None)


def _shown(key: str | None, value: Any) -> str:
    return h.fmt(units.display(key, value) if key else value)


def _with_unit(score: Any, value: float | None) -> str:
    """``12.3 mm``: a ranked value in its display unit (the executions' table mixes them)."""
    key = _value_key(score, value)
    spec = units.quantity_of(key) if key else None
    text = _shown(key, value)
    return f"{text} {units.unit(spec[0])}" if spec and value is not None else text


def _when(iso: Any) -> str:
    """``2015-11-20 09:00:00.000`` of an ISO UTC time (the header says UTC)."""
    text = str(iso or "")
    return text.replace("+00:00", "").replace("T", " ")[:23]


def _differing_fields(lines: Sequence[str]) -> set[str]:
    """Field names of ``field: live 0.012 vs recomputed 0.013`` lines."""
    return {line.split(":", 1)[0].strip() for line in lines if ":" in line}


def _scalars(score: Any) -> dict[str, Any]:
    if not isinstance(score, dict):
        return {}
    return {k: v for k, v in score.items() if v is None or isinstance(v, bool | int | float | str)}


def site_context(results: dict[str, Any], exists: Callable[[str], bool]) -> dict[str, Any]:
    """What the template shows, from the results document.

    Args:
        results: the ``results.json`` document (schema_version 1).
        exists: whether a path relative to the site's folder is a file (links only to those).

    Raises:
        ConfigError: not a results document of a schema this version reads.
    """
    if not isinstance(results, dict) or results.get("schema_version") != SCHEMA_VERSION:
        found = results.get("schema_version") if isinstance(results, dict) else type(results)
        raise ConfigError(
            f"not an ertools rescore results document of schema_version {SCHEMA_VERSION} "
            f"(found {found!r})"
        )
    executions: list[dict[str, Any]] = [
        e for e in results.get("executions") or [] if isinstance(e, dict)
    ]
    by_id = {str(e.get("id")): e for e in executions}

    def report_link(ex: dict[str, Any] | None, text: str) -> Link:
        target = ex.get("report") if ex else None
        ok = target and exists(str(target))
        return Link(text, h.relative_href(str(target)) if ok else None)

    boards = []
    for lb in results.get("leaderboards") or []:
        lower = bool(lb.get("lower_is_better", True))
        standings = []
        keys = set()
        for rank, row in ranked(lb.get("rows") or [], lower):
            ex = by_id.get(str(row.get("execution")))
            value = _number(row.get("value"))
            key = _value_key(ex.get("score") if ex else None, value)
            keys.add(key)
            live = _scalars(ex.get("live_score") if ex else None)
            # Flagged when the ranked value itself differs from the live one (a difference in
            # another field, e.g. a rounded execution_time, is in the live section).
            lines = (ex.get("live_differences") or []) if ex else []
            differs = key in _differing_fields(lines) if key else bool(lines)
            standings.append(
                Standing(
                    rank=rank,
                    team=str(row.get("team") or "(unknown)"),
                    value=_shown(key, value),
                    live=_shown(key, live.get(key)) if key in live else h.fmt(None),
                    differs=differs,
                    execution=report_link(ex, str(row.get("execution"))),
                )
            )
        # One header for the column: the ranked key's name and unit when every row agrees.
        (only,) = keys if len(keys) == 1 else (None,)
        column = f"{units.header(only)}" if only else "value"
        boards.append(
            Board(
                anchor=_anchor("lb", str(lb.get("benchmark"))),
                title=str(lb.get("title") or lb.get("benchmark")),
                rule=str(lb.get("rule") or ""),
                # Said once: the registry's rule texts may already end with the direction.
                direction=""
                if "better" in str(lb.get("rule") or "")
                else ("lower is better" if lower else "higher is better"),
                column=column,
                rows=tuple(standings),
            )
        )

    live_rows: list[dict[str, Any]] = []
    for ex in executions:
        live = _scalars(ex.get("live_score"))
        if not live:
            continue
        score = _scalars(ex.get("score"))
        flagged = _differing_fields(ex.get("live_differences") or [])
        for key, value in live.items():
            live_rows.append(
                {
                    "execution": ex.get("id"),
                    "team": ex.get("team"),
                    "field": key,
                    "live 2015": _shown(key, value),
                    "recomputed": _shown(key, score.get(key)),
                    "unit": units.unit(q[0]) if (q := units.quantity_of(key)) else "",
                    "differs": (
                        "DIFFERS"
                        if key in flagged
                        else "not recomputed"
                        if score.get(key) is None and value is not None
                        else "same"
                    ),
                }
            )
    live_table = h.table(live_rows, row_class="differs") if live_rows else None
    # Per execution (collapsed on the page: nested fields make dozens of lines per execution).
    differences = [
        (str(ex.get("id")), [str(line) for line in ex.get("live_differences") or []])
        for ex in executions
        if ex.get("live_differences")
    ]

    rows = []
    for ex in executions:
        status = str(ex.get("status"))
        rows.append(
            {
                "id": str(ex.get("id")),
                "benchmark": str(ex.get("title") or ex.get("benchmark")),
                "team": str(ex.get("team") or "(unknown)"),
                "start": _when(ex.get("start")),
                "end": _when(ex.get("end")),
                "status": status,
                "level": STATUS_LEVEL.get(status, "bad"),
                "reason": str(ex.get("reason") or ""),
                "value": _with_unit(ex.get("score"), _number(ex.get("rank_value"))),
                "warnings": list(ex.get("warnings") or []),
                "cached": bool(ex.get("cached")),
                "seconds": h.fmt(_number(ex.get("seconds"))),
                "report": report_link(ex, str(ex.get("report") or "")),
            }
        )
    counts = {s: sum(r["status"] == s for r in rows) for s in ("scored", "unscoreable", "failed")}

    timeline = results.get("timeline") or {}
    figure = str(timeline.get("figure") or "") if isinstance(timeline, dict) else ""
    figure_kind = ""
    if figure and exists(figure):
        figure_kind = "image" if Path(figure).suffix.lower() in _IMAGE_SUFFIXES else "frame"

    problems = [
        {"kind": p.get("kind"), "path": p.get("path"), "message": p.get("message")}
        for p in results.get("problems") or []
        if isinstance(p, dict)
    ]
    manifest = results.get("manifest") or {}
    provenance = [
        ("ertools version", results.get("ertools_version", "")),
        ("generated", results.get("generated", "")),
        ("command", " ".join(str(t) for t in results.get("command") or [])),
        ("manifest", manifest.get("path", "")),
        ("manifest SHA-256", manifest.get("sha256", "")),
        ("options", ", ".join(f"{k} {v}" for k, v in (results.get("options") or {}).items())),
    ]
    inputs = [
        {"path": i.get("path"), "size": i.get("size"), "sha256": i.get("sha256")}
        for i in results.get("inputs") or []
        if isinstance(i, dict)
    ]
    nav = [(b.anchor, b.title) for b in boards] + [
        ("live", "Live 2015"),
        ("timeline", "Timeline"),
        ("problems", f"Problems ({len(problems)})"),
        ("deviations", "Deviations"),
        ("executions", "Executions"),
        ("provenance", "Provenance"),
    ]
    downloads = [Link(name, name) for name in ("results.json", "results.csv") if exists(name)]
    return {
        "title": str(manifest.get("title") or "Competition results"),
        "subtitle": (
            f"{len(rows)} execution(s): {counts['scored']} scored, {counts['unscoreable']} "
            f"unscoreable, {counts['failed']} failed; rescored by ertools "
            f"{results.get('ertools_version', '')} on {results.get('generated', '')}"
        ),
        "nav": nav,
        "boards": boards,
        "live_table": live_table,
        "differences": differences,
        "figure": h.relative_href(figure),
        "figure_kind": figure_kind,
        "sessions": timeline.get("sessions") if isinstance(timeline, dict) else None,
        "problems": h.table(problems, columns=["kind", "path", "message"]) if problems else None,
        "deviations": [str(d) for d in results.get("deviations_in_force") or []],
        "executions": rows,
        "counts": counts,
        "provenance": provenance,
        "inputs": h.table(inputs, columns=["path", "size", "sha256"]) if inputs else None,
        "downloads": downloads,
    }


def write_site(results: dict[str, Any], out: Path) -> Path:
    """Write ``out/index.html`` from the results document; returns its path.

    Raises:
        ConfigError: not a results document, or ``out`` cannot be written.
    """

    def exists(rel: str) -> bool:
        # Only files inside ``out``: a link the page shows must open from the folder alone.
        target = (out / rel).resolve()
        return target.is_file() and target.is_relative_to(out.resolve())

    context = site_context(results, exists)
    index = out / "index.html"
    try:
        out.mkdir(parents=True, exist_ok=True)
        atomic.write_text(index, h.render(TEMPLATE, **context))
    except OSError as err:
        raise ConfigError(
            f"cannot write the results site ({err.strerror or err})", path=out
        ) from err
    return index
