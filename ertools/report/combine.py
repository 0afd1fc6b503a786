"""One page for a competition: several results combined, a table per benchmark, a row per run.

Reads what :func:`ertools.report.folder.write_report` wrote: a report folder, its
``result.json`` or its ``score.json`` (then ``result.json`` beside it gives the benchmark, the
team and the inputs; a lone ``score.json`` is recognised from its keys). Writes
``index.html``, ``results.json`` and ``results.csv`` into the output folder.
"""

from __future__ import annotations

import csv
import json
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ertools import __version__
from ertools.errors import ConfigError
from ertools.report import html as h
from ertools.report import units

# Keys that identify a benchmark's score when no result.json says which it is.
_SIGNATURES: tuple[tuple[str, frozenset[str]], ...] = (
    ("fbm3w", frozenset({"best_distance_error", "runs_details"})),
    ("fbm2h", frozenset({"position_accuracy", "orientation_accuracy"})),
    ("trajectory", frozenset({"position_error", "association"})),
    ("noise", frozenset({"epsilon", "suggested_d_min"})),
    ("fbm1", frozenset({"class_accuracy", "instance_accuracy"})),
)


@dataclass(frozen=True)
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


def _load_json(path: Path) -> Any:
    try:
        return json.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as err:
        raise ConfigError(f"cannot read a result: {err}", path=path) from err


def _guess_benchmark(score: dict[str, Any]) -> str:
    keys = set(score)
    for name, signature in _SIGNATURES:
        if signature <= keys:
            return name
    return "unknown"


def load_entry(path: Path) -> Entry:
    """A result from a report folder, a ``result.json`` or a ``score.json``."""
    from ertools.report.folder import headline

    if not path.exists():
        raise ConfigError("no such file or folder", path=path)
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
        inputs = tuple(str(i.get("name", "")) for i in meta.get("inputs") or [])
        index = folder / "index.html"
        return Entry(
            benchmark=str(meta.get("benchmark") or "unknown"),
            team=str(meta.get("team") or ""),
            headline=dict(meta.get("headline") or {}),
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
        inputs=(),
        warnings=0,
        failures=0,
        findings=None,
        source=path,
        index=None,
    )


def combine(paths: list[Path], outdir: Path, *, title: str = "Competition results") -> Path:
    """Write the combined page of ``paths`` into ``outdir``; returns its ``index.html``.

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
    by_benchmark: dict[str, list[Entry]] = {}
    for e in entries:
        by_benchmark.setdefault(e.benchmark, []).append(e)

    benchmarks: list[dict[str, Any]] = []
    flat: list[dict[str, Any]] = []
    for bench in sorted(by_benchmark):
        group = sorted(by_benchmark[bench], key=lambda e: (e.team, e.inputs, str(e.source)))
        # The benchmark is the table's title, not a column.
        keys = list(dict.fromkeys(k for e in group for k in e.headline if k != "benchmark"))
        rows = []
        links = []
        for e in group:
            row: dict[str, Any] = {"team": e.team or "(unknown)"}
            row.update({k: e.headline.get(k) for k in keys})
            row["warnings"] = e.warnings
            row["failures"] = e.failures
            row["audit findings"] = e.findings
            row["inputs"] = ", ".join(e.inputs)
            rows.append(row)
            flat.append({"benchmark": bench, **row, "source": str(e.source)})
            target = e.index or e.source
            rel = os.path.relpath(target.resolve(), outdir.resolve())
            links.append((Path(rel).as_posix(), f"{e.team or '(unknown)'}: {rel}"))
        teams = len({e.team for e in group})
        benchmarks.append(
            {
                "anchor": f"b-{bench}",
                "title": f"{bench} ({len(group)} result(s), {teams} team(s))",
                "table": h.table(rows),
                "links": links,
            }
        )
    (outdir / "results.json").write_text(json.dumps(flat, indent=2) + "\n", encoding="utf-8")
    columns = list(dict.fromkeys(k for row in flat for k in row))
    with (outdir / "results.csv").open("w", newline="", encoding="utf-8") as fh:
        writer = csv.DictWriter(fh, fieldnames=columns)
        writer.writeheader()
        writer.writerows(flat)
    subtitle = f"{len(entries)} result(s), combined by ertools {__version__}"
    index = outdir / "index.html"
    nav = [(b["anchor"], b["title"]) for b in benchmarks] + [("teams", "By team")]
    page = h.render(
        "combined.html.j2",
        title=title,
        subtitle=subtitle,
        nav=nav,
        benchmarks=benchmarks,
        teams=_by_team(entries, outdir),
    )
    index.write_text(page, encoding="utf-8")
    return index


def _by_team(entries: list[Entry], outdir: Path) -> list[h.Table]:
    """One table per team: its results in every benchmark, headline values as text."""
    teams: dict[str, list[Entry]] = {}
    for e in entries:
        teams.setdefault(e.team or "(unknown)", []).append(e)
    out = []
    for team in sorted(teams):
        rows = []
        for e in sorted(teams[team], key=lambda e: (e.benchmark, str(e.source))):
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
    """``best_distance_error 0.639 mm``: a headline value as text, in its display unit."""
    spec = units.quantity_of(key)
    if spec is None or not units.is_number(value):
        return f"{key} {h.fmt(value)}"
    return f"{key} {h.fmt(units.display(key, value))} {units.unit(spec[0])}"
