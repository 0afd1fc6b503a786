"""One page for a competition: several results combined, a table per benchmark, a row per run.

Reads what :func:`ertools.report.folder.write_report` wrote: a report folder, its
``result.json`` or its ``score.json`` (then ``result.json`` beside it gives the benchmark, the
team and the inputs; a lone ``score.json`` is recognised from its keys). Writes
``index.html``, ``results.json`` and ``results.csv`` into the output folder.

Results of the same inputs (the same SHA-256 of every input file) are one execution scored
several times (with and without ``--team``/``--transforms``, with a 2015 option...): they are
merged into one row, whose team is the best-sourced name any of them found (``--team`` >
payload > log name > transform, see :mod:`ertools.benchmarks.common.teams`), and whose other
results are listed by their options. A result with no team takes the one its inputs'
rockin_logger names give.
"""

from __future__ import annotations

import csv
import io
import json
import math
import os
from dataclasses import field
from pathlib import Path
from typing import Any

from ertools._version import __version__
from ertools.atomic import write_text
from ertools.benchmarks import registry
from ertools.benchmarks.base import Discovered, Reported
from ertools.benchmarks.common.teams import team_from_log_name
from ertools.csvsafe import spreadsheet_safe
from ertools.errors import ConfigError
from ertools.frozen_dataclass import frozen_dataclass
from ertools.inputs import read_regular_text, why_not
from ertools.jsonin import loads as loads_json
from ertools.report import html as h
from ertools.report import ranks
from ertools.report.folder import headline
from ertools.report.rank_plot import interval_plot
from ertools.views import units

# Command-line options that choose where or how output is written, not what is scored.
_OUTPUT_OPTIONS = frozenset(
    {
        "-o",
        "--out",
        "--output",
        "--out-dir",
        "--report",
        "--plot",
        "--plots",
        "--foxglove",
        "--format",
    }
)
_OUTPUT_FLAGS = frozenset({"-v", "--verbose", "-q", "--quiet"})
# Team sources, best first (ertools.benchmarks.common.teams.resolve_team's precedence).
_SOURCE_RANK = {"explicit": 0, "payload": 1, "log name": 2, "transform": 3}


@frozen_dataclass
class Entry:
    """One result as the combined page shows it."""

    benchmark: str
    team: str
    headline: dict[str, Any]
    inputs: tuple[str, ...]
    warnings: int
    failures: int
    findings: int | None
    source: Path  # the result.json or score.json read
    index: Path | None  # the report's index.html, when it exists
    team_source: str | None = (
        None  # explicit, payload, log name, transform (ertools.benchmarks.common.teams)
    )
    sha256: tuple[str, ...] = ()  # of the inputs, sorted: same tuple = same execution
    options: str = ""  # the scoring options of its command line ("" = the defaults)
    generated: str = ""
    score: dict[str, Any] = field(default_factory=dict)  # the whole score (for its intervals)


@frozen_dataclass
class Execution:
    """The results of one execution (same inputs): ``main`` is shown, ``others`` listed."""

    main: Entry
    others: tuple[Entry, ...]
    team: str
    team_source: str | None


def _options(argv: list[str], inputs: list[dict[str, Any]]) -> str:
    """The scoring options of a command line: from its first option on, without output
    options and input paths (``--team simbot --transforms sample_bags/fbm2h``)."""
    paths = {str(i.get(k, "")) for i in inputs for k in ("path", "name")}
    start = next((i for i, t in enumerate(argv) if t.startswith("-")), len(argv))
    kept: list[str] = []
    skip = False
    for token in argv[start:]:
        if skip:
            skip = False
            continue
        if token in _OUTPUT_OPTIONS:
            skip = True
            continue
        if token.split("=", 1)[0] in _OUTPUT_OPTIONS or token in _OUTPUT_FLAGS:
            continue
        if token in paths:
            continue
        kept.append(token)
    return " ".join(kept)


def _load_json(path: Path) -> Any:
    """A result's JSON; a key given twice is refused (the json module keeps the last)."""
    try:
        return loads_json(read_regular_text(path))  # a named pipe would block for ever
    except OSError as err:
        raise ConfigError(f"cannot read a result: {why_not(err)}", path=path) from err
    except (UnicodeDecodeError, ValueError) as err:
        raise ConfigError(f"cannot read a result: {err}", path=path) from err


def _guess_benchmark(score: dict[str, Any]) -> str:
    """The benchmark a score.json read alone belongs to: the name it states, else the first
    whose declared keys it has."""
    said = score.get("benchmark")
    if isinstance(said, str) and said in registry.names():
        return said
    keys = set(score)
    declared = [
        (name, bench.score_keys)
        for name in registry.names()
        if isinstance(bench := registry.get(name), Reported)
    ]
    for name, signature in declared:
        if signature and signature <= keys:
            return name
    return "unknown"


def load_entry(path: Path) -> Entry:
    """A result from a report folder, a ``result.json`` or a ``score.json``."""

    if not path.exists():
        raise ConfigError("no such file or folder", path=path, transient=True)
    folder = path if path.is_dir() else path.parent
    meta_path = folder / "result.json"
    if path.is_dir() and not meta_path.exists():
        if not (folder / "score.json").exists():
            raise ConfigError(
                "not a report folder (no result.json or score.json): write one with --report",
                path=path,
            )
        path = folder / "score.json"
    if meta_path.exists() and (path.is_dir() or path.name in ("result.json", "score.json")):
        meta = _load_json(meta_path)
        if not isinstance(meta, dict):
            raise ConfigError("result.json is not a JSON object", path=meta_path)
        audit = meta.get("audit") or None
        findings = None
        if isinstance(audit, dict):
            findings = (
                int(audit.get("illegal_transitions") or 0)
                + int(audit.get("silences") or 0)
                + len(audit.get("early_ends") or [])
                + int(audit.get("differences") or 0)
            )
        records = [i for i in meta.get("inputs") or [] if isinstance(i, dict)]
        inputs = tuple(str(i.get("name", "")) for i in records)
        index = folder / "index.html"
        argv = [str(t) for t in meta.get("argv") or []]
        return Entry(
            benchmark=str(meta.get("benchmark") or "unknown"),
            team=str(meta.get("team") or ""),
            team_source=str(meta["team_source"]) if meta.get("team_source") else None,
            sha256=tuple(sorted(str(i.get("sha256", "")) for i in records if i.get("sha256"))),
            options=_options(argv, records),
            generated=str(meta.get("generated") or ""),
            headline=dict(meta.get("headline") or {}),
            score=dict(meta["score"]) if isinstance(meta.get("score"), dict) else {},
            inputs=inputs,
            warnings=len(meta.get("warnings") or []),
            failures=len(meta.get("failures") or []),
            findings=findings,
            source=meta_path,
            index=index if index.exists() else None,
        )
    score = _load_json(path)
    if not isinstance(score, dict):
        raise ConfigError("a score must be a JSON object", path=path)
    return Entry(
        benchmark=_guess_benchmark(score),
        team="",
        headline=headline(score),
        score=score,
        inputs=(),
        warnings=0,
        failures=0,
        findings=None,
        source=path,
        index=None,
    )


def combine(
    paths: list[Path],
    outdir: Path,
    *,
    title: str = "Competition results",
    confidence: float | None = None,
) -> Path:
    """Write the combined page of ``paths`` into ``outdir``; returns its ``index.html``.

    ``confidence``: the level at which ties are judged (default: the results' own, else
    0.95; :mod:`ertools.report.ranks`).

    Raises:
        ConfigError: a path that is not a result, or no path at all.
    """
    if not paths:
        raise ConfigError("no results given: pass report folders, result.json or score.json")
    entries = [load_entry(Path(p)) for p in paths]
    try:
        outdir.mkdir(parents=True, exist_ok=True)
    except OSError as err:
        raise ConfigError(f"cannot write here ({err.strerror or err})", path=outdir) from err
    runs = executions(entries)
    by_benchmark: dict[str, list[Execution]] = {}
    for ex in runs:
        by_benchmark.setdefault(ex.main.benchmark, []).append(ex)

    benchmarks: list[dict[str, Any]] = []
    flat: list[dict[str, Any]] = []
    for bench in sorted(by_benchmark):
        by_team = sorted(
            by_benchmark[bench], key=lambda x: (x.team, x.main.inputs, str(x.main.source))
        )
        board = _board(bench, by_team, confidence)
        # Ranked executions in rank order, then the others by team.
        placed = {int(s.ident): s for s in board.standings}
        order = [int(s.ident) for s in board.standings]
        order += [i for i in range(len(by_team)) if i not in placed]
        group = [by_team[i] for i in order]
        # The benchmark is the table's title, not a column.
        keys = list(dict.fromkeys(k for x in group for k in x.main.headline if k != "benchmark"))
        merged = any(x.others for x in group)
        rows = []
        ties: list[str] = []  # the rows' CSS: a tie group's bracket
        links = []
        for i, x in zip(order, group, strict=True):
            e = x.main
            standing = placed.get(i)
            record = _stability_record(board, standing, board.reasons.get(i))
            reason = board.reasons.get(i)
            row: dict[str, Any] = {}
            if board.key is not None:
                row["rank"] = standing.marker if standing else "\u2014"
            row["team"] = x.team or "(unknown)"
            for k in keys:
                row[k] = _finite(e.headline.get(k))
                if k == board.key and board.has_intervals:  # its interval right beside it
                    row[board.interval_header] = _interval_text(board.key, record["interval"])
                    row[_P_HEADER] = (
                        ranks.p_text(standing)
                        if standing
                        else f"\u2014 ({reason})"
                        if reason
                        else "\u2014"
                    )
            row["warnings"] = e.warnings
            row["failures"] = e.failures
            row["audit findings"] = e.findings
            row["inputs"] = ", ".join(e.inputs)
            if merged:
                row["options"] = e.options or "(defaults)"
                row["other results"] = "; ".join(_variant_text(o, e) for o in x.others)
            rows.append(row)
            ties.append(_tie_class(board.standings, standing))
            data = {k: v for k, v in row.items() if k not in (board.interval_header, _P_HEADER)}
            data.pop("rank", None)
            flat.append(
                {
                    "benchmark": bench,
                    **data,
                    **(record if board.key is not None else {}),
                    "team_source": x.team_source,
                    "source": str(e.source),
                    "other sources": " ".join(str(o.source) for o in x.others),
                }
            )
            for r in (e, *x.others):
                target = r.index or r.source
                rel = os.path.relpath(target.resolve(), outdir.resolve())
                label = f" ({r.options or 'defaults'})" if x.others else ""
                href = h.relative_href(Path(rel).as_posix())
                if href is not None:  # another drive (Windows): no link, the text says where
                    links.append((href, f"{x.team or '(unknown)'}{label}: {rel}"))
        teams = len({x.team for x in group})
        benchmarks.append(
            {
                "anchor": f"b-{bench}",
                "title": f"{bench} ({len(group)} result(s), {teams} team(s))",
                "table": h.table(
                    [{**row, "_tie": tie} for row, tie in zip(rows, ties, strict=True)],
                    columns=[c for c in dict.fromkeys(k for r in rows for k in r)],
                    row_class="_tie",
                ),
                "links": links,
                **_board_context(board),
            }
        )
    text = json.dumps(_finite(flat), indent=2, allow_nan=False)
    write_text(outdir / "results.json", text + "\n")
    table = [_csv_row(row) for row in flat]
    columns = list(dict.fromkeys(k for row in table for k in row))
    buffer = io.StringIO()
    writer = csv.DictWriter(buffer, fieldnames=columns)
    writer.writeheader()
    writer.writerows([{k: spreadsheet_safe(v) for k, v in row.items()} for row in table])
    write_text(outdir / "results.csv", buffer.getvalue())
    of_runs = f" of {len(runs)} execution(s)" if len(runs) != len(entries) else ""
    subtitle = f"{len(entries)} result(s){of_runs}, combined by ertools {__version__}"
    index = outdir / "index.html"
    nav = [(b["anchor"], b["title"]) for b in benchmarks] + [("teams", "By team")]
    page = h.render(
        "combined.html.j2",
        title=title,
        subtitle=subtitle,
        nav=nav,
        benchmarks=benchmarks,
        teams=_by_team(runs, outdir),
    )
    write_text(index, page)
    return index


_P_HEADER = "P(swap with next)"


def _finite(value: Any) -> Any:
    """``value`` with every float that is not finite (a result's Infinity, NaN) as None:
    results.json stays JSON, and the tables show no such number."""
    if isinstance(value, float) and not math.isfinite(value):
        return None
    if isinstance(value, dict):
        return {k: _finite(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_finite(v) for v in value]
    return value


@frozen_dataclass
class Board:
    """A benchmark's executions ranked by its rule, with their rank stability
    (:mod:`ertools.report.ranks`); ``key`` None when the benchmark has no ranking rule or
    no execution has the ranked value."""

    key: str | None
    lower_is_better: bool
    rule: str
    confidence: float
    standings: tuple[ranks.Standing, ...]  # ``ident``: the execution's index in the group
    reasons: dict[int, str]  # index -> why that execution is not ranked

    @property
    def has_intervals(self) -> bool:
        return any(s.interval is not None for s in self.standings)

    @property
    def interval_header(self) -> str:
        spec = units.quantity_of(self.key) if self.key else None
        unit = f" ({units.unit(spec[0])})" if spec else ""
        return f"{self.confidence * 100:g} % interval{unit}"


def _board(bench: str, group: list[Execution], chosen: float | None = None) -> Board:
    """The executions of ``bench`` ranked by the registry's rule for it, ties judged at the
    ``chosen`` confidence (default: the results' own)."""
    found = registry.get(bench) if bench in registry.names() else None
    if not isinstance(found, Discovered):
        return Board(None, True, "", ranks.DEFAULT_CONFIDENCE, (), {})
    ranking = found.ranking
    key = ranks.rule_key(ranking.text)
    contenders = []
    reasons: dict[int, str] = {}
    for i, x in enumerate(group):
        score = x.main.score or x.main.headline
        unscoreable = ranks.unscoreable_reason(score)
        value = score.get(key)
        if unscoreable is not None:
            reasons[i] = f"unscoreable: {unscoreable}"
            continue
        if isinstance(value, bool) or not isinstance(value, int | float):
            reasons[i] = f"no {key} in this result"
            continue
        if not math.isfinite(value):  # json reads Infinity and NaN: never a place on a board
            reasons[i] = f"{key} is {value} in this result: not a finite number"
            continue
        contenders.append(
            ranks.Contender(
                name=x.team or "(unknown)",
                score=float(value),
                interval=ranks.interval_of(score, key),
                confidence=ranks.confidence_of(score) or ranks.DEFAULT_CONFIDENCE,
                ident=str(i),
            )
        )
    if not contenders:
        return Board(None, ranking.lower_is_better, ranking.text, ranks.DEFAULT_CONFIDENCE, (), {})
    confidence = chosen or ranks.board_confidence(
        ranks.confidence_of(x.main.score) for x in group if x.main.score
    )
    standings = ranks.stability(
        _distinct(contenders), lower_is_better=ranking.lower_is_better, confidence=confidence
    )
    return Board(key, ranking.lower_is_better, ranking.text, confidence, tuple(standings), reasons)


def _distinct(contenders: list[ranks.Contender]) -> list[ranks.Contender]:
    """Team names made distinct where a team has several executions: ``homer (2)``."""
    seen: dict[str, int] = {}
    for c in contenders:
        seen[c.name] = seen.get(c.name, 0) + 1
    count: dict[str, int] = {}
    out = []
    for c in contenders:
        if seen[c.name] > 1:
            count[c.name] = count.get(c.name, 0) + 1
            c = ranks.Contender(
                f"{c.name} ({count[c.name]})", c.score, c.interval, c.confidence, c.ident
            )
        out.append(c)
    return out


def _stability_record(
    board: Board, standing: ranks.Standing | None, reason: str | None
) -> dict[str, Any]:
    """What results.json says of an execution's place: in the stored units."""
    if standing is None:
        return {
            "rank": None,
            "rank_group": None,
            "tied_with": [],
            "interval": None,
            "p_swap_next": None,
            "confidence": board.confidence,
            "rank_note": reason or "",
        }
    return {
        "rank": standing.rank,
        "rank_group": standing.group,
        "tied_with": list(standing.tied_with),
        "interval": list(standing.interval) if standing.interval else None,
        "p_swap_next": standing.p_swap_next,
        "confidence": board.confidence,
        "rank_note": standing.note,
    }


def _interval_text(key: str, interval: list[float] | None) -> str:
    if interval is None:
        return "\u2014"
    spec = units.quantity_of(key)
    low, high = (h.fmt(float(units.display(key, v)), spec[0] if spec else None) for v in interval)
    return f"{low} to {high}"


def _tie_class(standings: tuple[ranks.Standing, ...], standing: ranks.Standing | None) -> str:
    """``tied first``/``tied``/``tied last``: the row's place in a bracket of tied teams."""
    if standing is None or not standing.tied:
        return ""
    members = [s for s in standings if s.group == standing.group]
    ends = (["first"] if members[0] is standing else []) + (
        ["last"] if members[-1] is standing else []
    )
    return " ".join(["tied", *ends])


def _board_context(board: Board) -> dict[str, Any]:
    """The explanation, the one-line summary and the plot of a ranked benchmark."""
    if board.key is None:
        return {"explanation": "", "summary": "", "plot": ""}
    if not board.has_intervals:
        return {
            "explanation": f"Ranked by {board.rule}. {ranks.NONE_EXPLAINED}",
            "summary": "",
            "plot": "",
        }
    spec = units.quantity_of(board.key)
    return {
        "explanation": f"Ranked by {board.rule}. "
        + ranks.explanation(board.confidence, board.lower_is_better, board.key),
        "summary": ranks.summary(board.standings),
        "plot": interval_plot(
            board.standings,
            factor=units.factor(*spec) if spec else 1.0,
            unit=units.unit(spec[0]) if spec else "",
            decimals=units.DECIMALS[spec[0]] if spec else 3,
            axis=board.key,
            confidence=board.confidence,
        ),
    }


def _csv_row(row: dict[str, Any]) -> dict[str, Any]:
    """A results.json row as a CSV row: the interval as two columns, lists joined."""
    out = dict(row)
    if "interval" in out:
        interval = out.pop("interval")
        out["interval_low"], out["interval_high"] = interval if interval else (None, None)
    if "tied_with" in out:
        out["tied_with"] = "; ".join(out["tied_with"])
    return out


def executions(entries: list[Entry]) -> list[Execution]:
    """The entries grouped by execution: same benchmark and same input SHA-256s (an entry
    without recorded inputs is an execution of its own), in the order first seen."""
    groups: dict[object, list[Entry]] = {}
    for e in entries:
        key: object = (e.benchmark, e.sha256) if e.sha256 else ("source", str(e.source))
        groups.setdefault(key, []).append(e)
    out = []
    for group in groups.values():
        # Best team source first, a named team before none, the newest result on ties.
        ranked = sorted(group, key=lambda e: e.generated, reverse=True)
        ranked.sort(key=lambda e: (not e.team, _SOURCE_RANK.get(e.team_source or "", 4)))
        main = ranked[0]
        team, source = main.team, main.team_source
        if not team:
            # Results written before teams were recorded: the inputs' names may still say.
            found = next((t for e in group for i in e.inputs if (t := team_from_log_name(i))), None)
            team, source = found or "", "log name" if found else None
        out.append(Execution(main, tuple(ranked[1:]), team, source))
    return out


def _variant_text(other: Entry, main: Entry) -> str:
    """``(defaults): position_accuracy 165.8 mm``: another result of the execution, by its
    options, with the headline values that differ from the shown one."""
    diffs = [
        _score_text(k, v)
        for k, v in other.headline.items()
        if k != "benchmark" and main.headline.get(k) != v
    ]
    same = "same headline values" if not diffs else ", ".join(diffs)
    return f"{other.options or '(defaults)'}: {same}"


def _by_team(runs: list[Execution], outdir: Path) -> list[h.Table]:
    """One table per team: its results in every benchmark, headline values as text."""
    teams: dict[str, list[Execution]] = {}
    for x in runs:
        teams.setdefault(x.team or "(unknown)", []).append(x)
    out = []
    for team in sorted(teams):
        rows = []
        for x in sorted(teams[team], key=lambda x: (x.main.benchmark, str(x.main.source))):
            e = x.main
            target = e.index or e.source
            rows.append(
                {
                    "benchmark": e.benchmark,
                    "score": ", ".join(
                        _score_text(k, v) for k, v in e.headline.items() if k != "benchmark"
                    ),
                    "warnings": e.warnings,
                    "failures": e.failures,
                    "audit findings": e.findings,
                    "report": os.path.relpath(target.resolve(), outdir.resolve()),
                }
            )
        out.append(h.table(rows, caption=team))
    return out


def _score_text(key: str, value: Any) -> str:
    """``best_distance_error 0.64 mm``: a headline value as text, in its display unit."""
    spec = units.quantity_of(key)
    if spec is None or not units.is_number(value):
        return f"{key} {h.fmt(value)}"
    return f"{key} {h.fmt(units.display(key, value), spec[0])} {units.unit(spec[0])}"
