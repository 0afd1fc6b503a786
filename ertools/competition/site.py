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
import os
import re
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

from ertools.atomic import write_text
from ertools.competition import site_text as text
from ertools.competition.site_text import TEAM_UNKNOWN
from ertools.errors import ConfigError
from ertools.frozen_dataclass import frozen_dataclass
from ertools.report import html as h
from ertools.report import ranks
from ertools.report.rank_plot import interval_plot
from ertools.rsbb.score import flatten
from ertools.views import units

SCHEMA_VERSION = 1
TEMPLATE = "rescore_index.html.j2"
# Figures the page shows as an image; anything else (the interactive timeline page) is framed.
_IMAGE_SUFFIXES = frozenset({".png", ".svg", ".jpg", ".jpeg", ".gif", ".webp"})
STATUS_LEVEL = {"scored": "ok", "unscoreable": "warn", "failed": "bad"}


@frozen_dataclass
class Link:
    """A relative link inside the site's folder; ``href`` None when the target is missing."""

    text: str
    href: str | None


@frozen_dataclass
class Standing:
    """One row of a leaderboard as shown."""

    rank: int | None  # None: not ranked (no value)
    team: str
    value: str  # in the display unit of the column
    live: str  # the live 2015 value of the same key, or an em dash
    differs: bool  # the live 2015 score differs from the recomputed one
    execution: Link
    marker: str = ""  # ``=2`` in a group of teams the data cannot order, else the rank
    interval: str = "\u2014"  # the value's confidence interval, in the column's unit
    p_swap: str = "\u2014"  # P(swap with the team below), or why there is none
    tie: str = ""  # CSS: ``tied``, ``tied first``, ``tied last`` (the bracket's ends)
    cells: tuple[str, ...] = ()  # the board's own columns (Ranking.columns), as shown


@frozen_dataclass
class Board:
    anchor: str
    title: str
    rule: str
    direction: str
    column: str  # the value's header with its unit
    rows: tuple[Standing, ...]
    unranked: tuple[Standing, ...] = ()  # scored, no team named: out of the ranking
    warnings: tuple[text.Grouped, ...] = ()  # said once for the benchmark
    explanation: str = ""  # rank stability in words, above the table
    summary: str = ""  # ``1 of 3 adjacent order(s) supported by the data; tied: ...``
    plot: str = ""  # SVG text (ertools.report.rank_plot; every text in it escaped there)
    interval_column: str = ""  # ``95 % interval (mm)``; "" when no row has an interval
    extra: tuple[tuple[str, str], ...] = ()  # its own columns: (header, what it means)


def _cells(row: dict[str, Any], headers: Sequence[str]) -> tuple[str, ...]:
    """A row's own columns (a referee's items) as shown: counts as they are, times to 0.1 s,
    an em dash where the row has none."""
    given = row.get("columns")
    own: dict[str, Any] = given if isinstance(given, dict) else {}
    out = []
    for header in headers:
        value = own.get(header)
        if isinstance(value, bool):
            out.append("yes" if value else "no")
        elif isinstance(value, float):
            out.append(f"{value:.1f}")
        elif value is None:
            out.append("\u2014")
        else:
            out.append(str(value))
    return tuple(out)


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


def _value_key(score: dict[str, Any] | None, value: float | None, rule: str = "") -> str | None:
    """The score's top-level key whose value the leaderboard ranks by (for its unit): the one
    the rule names when several keys hold the value."""
    return ranks.ranked_key(score, value, rule)


def _stability(
    placed: Sequence[tuple[int | None, dict[str, Any]]],
    by_id: dict[str, dict[str, Any]],
    rule: str,
    lower: bool,
    said: Any,
) -> tuple[dict[int, ranks.Standing], float]:
    """Rank stability of the ranked rows (by their index in ``placed``): each row's interval
    as the document gives it, else as its execution's score does (a document written before
    leaderboards carried them), at the leaderboard's confidence (the document's, else its
    results' own); and that confidence."""
    contenders = []
    confidences = []
    for i, (rank, row) in enumerate(placed):
        value = _number(row.get("value"))
        if rank is None or value is None:
            continue
        ex = by_id.get(str(row.get("execution")))
        score = ex.get("score") if ex else None
        interval = ranks.interval_of({"v_interval": row.get("interval")}, "v")
        if interval is None:
            interval = ranks.interval_of(score, ranks.ranked_key(score, value, rule))
        confidence = ranks.confidence_of(score)
        confidences.append(confidence)
        contenders.append(
            ranks.Contender(
                str(row.get("team") or TEAM_UNKNOWN),
                value,
                interval,
                confidence or ranks.DEFAULT_CONFIDENCE,
                str(i),
            )
        )
    stated = _number(said)
    level = (
        stated if stated is not None and 0.0 < stated < 1.0 else ranks.board_confidence(confidences)
    )
    standings = ranks.stability(contenders, lower_is_better=lower, confidence=level)
    return {int(s.ident): s for s in standings}, level


def _interval_text(key: str | None, interval: tuple[float, float] | None) -> str:
    if interval is None:
        return text.shown(None, None)
    return f"{text.shown(key, interval[0])} to {text.shown(key, interval[1])}"


def _p_text(place: ranks.Standing | None) -> str:
    return ranks.p_text(place) if place is not None else text.shown(None, None)


def _tie_class(
    placed: Sequence[tuple[int | None, dict[str, Any]]], board: dict[int, ranks.Standing], i: int
) -> str:
    """``tied first``/``tied``/``tied last``: the row's place in a bracket of tied teams."""
    place = board.get(i)
    if place is None or not place.tied:
        return ""
    above = board.get(i - 1)
    below = board.get(i + 1)
    first = above is None or above.group != place.group
    last = below is None or below.group != place.group
    return " ".join(["tied", *(["first"] if first else []), *(["last"] if last else [])])


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


@frozen_dataclass
class LiveRow:
    """One field of a live 2015 score beside the recomputed one (``status``: ``differs``,
    ``not-recomputed`` or ``same``: the row's CSS class)."""

    execution: str
    team: str
    field: str
    live: str
    recomputed: str
    difference: str
    why: str
    rules: tuple[str, ...]
    status: str


_LIVE_ORDER = {"differs": 0, "not-recomputed": 1, "same": 2}


def _live_rows(executions: Sequence[dict[str, Any]], paths: text.Paths) -> list[LiveRow]:
    """Every live field beside the recomputed one, the differing ones first."""
    rows: list[LiveRow] = []
    for ex in executions:
        live = _scalars(ex.get("live_score"))
        if not live:
            continue
        # an RSBB live score's fields are dotted paths into the nested score (goal_1.pose_score)
        recomputed = ex.get("score")
        score = _scalars(flatten(recomputed) if isinstance(recomputed, dict) else None)
        why = {
            d.key: d
            for d in (text.difference(str(line)) for line in ex.get("live_differences") or [])
        }
        for key, value in live.items():
            d = why.get(key)
            status = (
                "differs"
                if d is not None
                else "not-recomputed"
                if score.get(key) is None and value is not None
                else "same"
            )
            rows.append(
                LiveRow(
                    execution=str(ex.get("id")),
                    team=_team(ex),
                    field=units.without_unit(key),
                    live=text.with_unit(key, value),
                    recomputed=text.with_unit(key, score.get(key)),
                    difference=d.difference if d is not None else "",
                    why=(
                        text.prose_units(
                            text.manifest_terms(paths.text(d.why), str(ex.get("benchmark")))
                        )
                        if d is not None
                        else ""
                    ),
                    rules=d.rules if d is not None else (),
                    status=status,
                )
            )
    rows.sort(key=lambda r: _LIVE_ORDER[r.status])  # stable: time order within each
    return rows


def _team(ex: dict[str, Any] | None) -> str:
    team = ex.get("team") if ex else None
    return str(team) if team else TEAM_UNKNOWN


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
    manifest = results.get("manifest") or {}
    manifest_path = str(manifest.get("path") or "")
    # Paths relative to the organiser's folder (results.json's ``root``; without one, the
    # manifest's folder), also those of files kept beside it.
    root = str(results.get("root") or (os.path.dirname(manifest_path) if manifest_path else ""))
    folders = {os.path.dirname(str(b)) for e in executions for b in e.get("bags") or []}
    paths = text.Paths(root, [os.path.dirname(manifest_path), *sorted(folders)])

    def report_link(ex: dict[str, Any] | None, label: str) -> Link:
        target = ex.get("report") if ex else None
        ok = target and exists(str(target))
        return Link(label, h.relative_href(str(target)) if ok else None)

    grouped, own_warnings = text.group_warnings(executions, paths, skip=(TEAM_UNKNOWN,))
    boards = []
    for lb in results.get("leaderboards") or []:
        lower = bool(lb.get("lower_is_better", True))
        rule = str(lb.get("rule") or "")
        placed = ranked(lb.get("rows") or [], lower)
        board, confidence = _stability(placed, by_id, rule, lower, lb.get("confidence"))
        standings = []
        keys = set()
        extra = tuple(
            (str(c.get("header")), str(c.get("description")))
            for c in lb.get("columns") or []
            if isinstance(c, dict)
        )
        headers = [h for h, _ in extra]
        for i, (rank, row) in enumerate(placed):
            ex = by_id.get(str(row.get("execution")))
            value = _number(row.get("value"))
            key = _value_key(ex.get("score") if ex else None, value, rule)
            keys.add(key)
            live = _scalars(ex.get("live_score") if ex else None)
            # Flagged when the ranked value itself differs from the live one (a difference in
            # another field, e.g. a rounded execution_time, is in the live section).
            lines = (ex.get("live_differences") or []) if ex else []
            differs = key in _differing_fields(lines) if key else bool(lines)
            place = board.get(i)
            standings.append(
                Standing(
                    rank=rank,
                    team=str(row.get("team") or TEAM_UNKNOWN),
                    value=text.shown(key, value),
                    live=text.shown(key, live.get(key)) if key in live else text.shown(None, None),
                    differs=differs,
                    execution=report_link(ex, str(row.get("execution"))),
                    marker=place.marker if place else "",
                    interval=_interval_text(key, place.interval if place else None),
                    p_swap=_p_text(place),
                    tie=_tie_class(placed, board, i),
                    cells=_cells(row, headers),
                )
            )
        unranked = []
        for row in lb.get("unranked") or []:
            ex = by_id.get(str(row.get("execution")))
            value = _number(row.get("value"))
            key = _value_key(ex.get("score") if ex else None, value, str(lb.get("rule") or ""))
            keys.add(key)
            unranked.append(
                Standing(
                    rank=None,
                    team=str(row.get("note") or TEAM_UNKNOWN),
                    value=text.shown(key, value),
                    live=text.shown(None, None),
                    differs=False,
                    execution=report_link(ex, str(row.get("execution"))),
                    cells=_cells(row, headers),
                )
            )
        # One header for the column: the ranked key's name and unit when every row agrees.
        (only,) = keys if len(keys) == 1 else (None,)
        column = f"{units.header(only)}" if only else "value"
        name = str(lb.get("benchmark"))
        shown = [board[i] for i in sorted(board)]
        with_intervals = any(p.interval is not None for p in shown)
        spec = units.quantity_of(only) if only else None
        boards.append(
            Board(
                anchor=_anchor("lb", name),
                title=str(lb.get("title") or name),
                rule=text.rule_text(str(lb.get("rule") or "")),
                # Said once: the registry's rule texts may already end with the direction.
                direction=""
                if "better" in str(lb.get("rule") or "")
                else ("lower is better" if lower else "higher is better"),
                column=column,
                rows=tuple(standings),
                unranked=tuple(unranked),
                warnings=tuple(g for g in grouped if g.benchmark == name),
                explanation=(
                    ranks.explanation(confidence, lower, only)
                    if with_intervals
                    else ranks.NONE_EXPLAINED
                    if shown
                    else ""
                ),
                summary=ranks.summary(shown) if with_intervals else "",
                plot=interval_plot(
                    shown,
                    factor=units.factor(*spec) if spec else 1.0,
                    unit=units.unit(spec[0]) if spec else "",
                    decimals=text.DECIMALS[spec[0]] if spec else 3,
                    axis=only or "value",
                    confidence=confidence,
                )
                if with_intervals
                else "",
                extra=extra,
                interval_column=(
                    f"{confidence * 100:g} % interval"
                    + (f" ({units.unit(spec[0])})" if spec else "")
                    if with_intervals
                    else ""
                ),
            )
        )

    live_rows = _live_rows(executions, paths)
    rows = []
    for ex in executions:
        status = str(ex.get("status"))
        score = ex.get("score")
        rank_value = _number(ex.get("rank_value"))
        key = _value_key(score if isinstance(score, dict) else None, rank_value)
        rows.append(
            {
                "id": str(ex.get("id")),
                "benchmark": str(ex.get("title") or ex.get("benchmark")),
                "team": _team(ex),
                "named": bool(ex.get("team")),
                "start": _when(ex.get("start")),
                "end": _when(ex.get("end")),
                "status": status,
                "level": STATUS_LEVEL.get(status, "bad"),
                "reason": text.prose_units(
                    text.manifest_terms(
                        paths.text(ex.get("reason") or ""), str(ex.get("benchmark"))
                    )
                ),
                "value": text.with_unit(key, rank_value) if key else text.shown(None, rank_value),
                "warnings": own_warnings.get(str(ex.get("id")), []),
                "cached": bool(ex.get("cached")),
                "seconds": text.shown("seconds", _number(ex.get("seconds"))),
                "report": report_link(ex, str(ex.get("report") or "")),
            }
        )
    counts = {s: sum(r["status"] == s for r in rows) for s in ("scored", "unscoreable", "failed")}
    unnamed = sum(not r["named"] for r in rows)

    timeline = results.get("timeline") or {}
    figure = str(timeline.get("figure") or "") if isinstance(timeline, dict) else ""
    figure_kind = ""
    if figure and exists(figure):
        figure_kind = "image" if Path(figure).suffix.lower() in _IMAGE_SUFFIXES else "frame"

    problems = [
        {
            "kind": p.get("kind"),
            "path": paths.path(p.get("path")) if p.get("path") else None,
            "message": text.prose_units(paths.text(p.get("message"))),
        }
        for p in results.get("problems") or []
        if isinstance(p, dict)
    ]
    provenance = [
        ("ertools version", results.get("ertools_version", "")),
        ("generated", results.get("generated", "")),
        (
            "folder",
            f"{os.path.basename(root)}/ (the folder scanned: paths on this page are relative to it)"
            if root
            else "",
        ),
        ("command", paths.text(" ".join(str(t) for t in results.get("command") or []))),
        ("manifest", paths.path(manifest_path)),
        ("manifest SHA-256", manifest.get("sha256", "")),
        ("options", ", ".join(f"{k} {v}" for k, v in (results.get("options") or {}).items())),
    ]
    inputs = [
        {"path": paths.path(i.get("path")), "size": i.get("size"), "sha256": i.get("sha256")}
        for i in results.get("inputs") or []
        if isinstance(i, dict)
    ]
    places: dict[str, int] = {}
    for entry in results.get("files") or []:
        if isinstance(entry, dict):
            places[str(entry.get("place"))] = places.get(str(entry.get("place")), 0) + 1
    nav = [(b.anchor, b.title) for b in boards] + [
        ("live", "Live scores"),
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
        "live_rows": live_rows,
        "live_differing": sum(r.status == "differs" for r in live_rows),
        "figure": h.relative_href(figure),
        "figure_kind": figure_kind,
        "sessions": timeline.get("sessions") if isinstance(timeline, dict) else None,
        "problems": h.table(problems, columns=["kind", "path", "message"]) if problems else None,
        "deviations": [
            text.prose_units(text.deviation_terms(paths.text(str(d))))
            for d in results.get("deviations_in_force") or []
        ],
        "executions": rows,
        "counts": counts,
        "unnamed": unnamed,
        "team_unknown": TEAM_UNKNOWN,
        "units": {q: units.unit(q) for q in ("length", "angle", "time")},
        "decimals": text.DECIMALS,
        "files": places,
        "provenance": provenance,
        "inputs": h.table(inputs, columns=["path", "size", "sha256"]) if inputs else None,
        "downloads": downloads,
    }


def write_site(results: dict[str, Any], out: Path) -> Path:
    """Write ``out/index.html`` from the results document; returns its path.

    Raises:
        ConfigError: not a results document, or ``out`` cannot be written.
    """

    base = out.resolve()  # once: a resolve is a stat per part of the path

    def exists(rel: str) -> bool:
        # Only files inside ``out``: a link the page shows must open from the folder alone.
        target = (base / rel).resolve()
        return target.is_file() and target.is_relative_to(base)

    context = site_context(results, exists)
    index = out / "index.html"
    try:
        out.mkdir(parents=True, exist_ok=True)
        write_text(index, h.render(TEMPLATE, **context))
    except OSError as err:
        raise ConfigError(
            f"cannot write the results site ({err.strerror or err})", path=out
        ) from err
    return index
