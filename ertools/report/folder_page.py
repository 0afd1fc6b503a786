"""The ``index.html`` of a report folder: score table, figures, the audit timeline and the
live vs recomputed comparison, warnings, deviations from the 2015 node and provenance, from
what :func:`ertools.report.folder.write_report` gathered."""

from __future__ import annotations

import platform
import shlex
from pathlib import Path
from typing import Any

from ertools.benchmarks.base import BenchmarkResult
from ertools.benchmarks.common.teams import SOURCE_TEXT
from ertools.report import html as h
from ertools.report.records import FileRecord, csv_stem
from ertools.timeutil import iso_utc, ns_to_s
from ertools.views import units

TABLE_MAX_ROWS = 200  # longer tables are in the CSV only
TABLE_OPEN_ROWS = 30  # longer tables are folded in the page
_EPOCH_COLUMNS = ("time", "from_time", "start_time")


def page(
    score: BenchmarkResult | None,
    audit: Any,
    meta: dict[str, Any],
    input_records: list[FileRecord],
    configs: list[tuple[FileRecord, str | None]],
    figures: list[tuple[Path, str]],
    figure_problems: list[str],
    written: list[str],
    outdir: Path,
) -> str:
    nav: list[tuple[str, str]] = []
    score_ctx: dict[str, Any] | None = None
    if score is not None:
        failures = list(score.failures)
        badges = []
        if failures:
            badges.append((f"{len(failures)} failure(s)", "bad"))
        if meta["warnings"]:
            badges.append((f"{len(meta['warnings'])} warning(s)", "warn"))
        if not failures and not meta["warnings"]:
            badges.append(("no warnings", "ok"))
        head = meta["headline"]
        score_ctx = {
            "badges": badges,
            "headline": h.key_values(list(head.items()), caption="Score") if head else None,
            "failures": [f"failure: {f}" for f in failures],
            "yaml": score.to_yaml(),
        }
        nav.append(("score", "Score"))
    figure_items = [
        h.Figure(p.relative_to(outdir).as_posix(), title, wide=p.stem == "audit_timeline")
        for p, title in figures
    ]
    if figure_items or figure_problems:
        nav.append(("figures", "Figures"))
    audit_ctx = _audit_context(audit) if audit is not None else None
    if audit_ctx is not None:
        nav.append(("audit", "Audit"))
    tables = []
    for name, rows in (score.tables() if score is not None else {}).items():
        csv_name = f"{csv_stem(name)}.csv"
        tables.append(
            {
                "name": name,
                "csv": csv_name,
                "count": len(rows),
                # Per-sample tables are long: folded (no script needed), the CSV has them all.
                "folded": len(rows) > TABLE_OPEN_ROWS,
                "table": h.table(rows, max_rows=TABLE_MAX_ROWS) if rows else None,
            }
        )
    if tables:
        nav.append(("tables", "Tables"))
    nav += [("notes", "Warnings and deviations"), ("provenance", "Provenance")]
    title = f"ertools report: {meta['benchmark']}"
    if meta["team"]:
        title += f" \u2014 {meta['team']}"
    caveat = getattr(getattr(audit, "comparison", None), "caveat", "")
    if caveat:  # the recomputed score is no score of the run: say so where it is named
        title += f" ({caveat})"
    subtitle = f"generated {meta['generated']} by ertools {meta['ertools_version']}"
    if input_records:
        subtitle += " from " + ", ".join(r.name for r in input_records)
    return h.render(
        "report.html.j2",
        title=title,
        subtitle=subtitle,
        nav=nav,
        score=score_ctx,
        figures=figure_items,
        figure_problems=figure_problems,
        audit=audit_ctx,
        tables=tables,
        warnings=meta["warnings"],
        deviations=_deviations(score, audit),
        provenance=_provenance_context(score, audit, meta, input_records, configs, written),
    )


def _deviations(score: BenchmarkResult | None, audit: Any) -> list[str]:
    items: list[str] = []
    sources: list[Any] = [score] if score is not None else []
    if audit is not None:
        sources.append(audit)
    for src in sources:
        for d in src.deviations:
            if d not in items:
                items.append(d)
    return items


def _audit_context(audit: Any) -> dict[str, Any]:
    facts = [
        ("benchmark", audit.benchmark or "(unknown)"),
        ("first state message", iso_utc(audit.start_ns) if audit.timeline else None),
        ("duration (s)", ns_to_s(audit.end_ns - audit.start_ns)),
        ("BmBox transitions checked", audit.transitions_checked),
        ("illegal transitions", len(audit.illegal_transitions)),
        (f"silences > {ns_to_s(audit.max_silence_ns):g} s", len(audit.silences)),
        ("ended by the RefBox", ", ".join(e.reason for e in audit.early_ends) or "no"),
    ]
    found = []
    if audit.topics:
        found.append(
            h.table(
                [{"machine": m, "topic": t, "messages": n} for m, t, n in audit.topics],
                caption="State topics",
            )
        )
    tables = audit.tables()
    for key, caption in (
        ("illegal_transitions", "Illegal BmBox transitions"),
        ("silences", "Heartbeat silences"),
        ("early_ends", "Benchmark ended by the RefBox"),
    ):
        if tables[key]:
            # Epoch columns stay in the CSV; the page shows seconds from the first message.
            columns = [c for c in tables[key][0] if c not in _EPOCH_COLUMNS]
            found.append(h.table(tables[key], columns=columns, caption=caption))
    comparison = None
    if audit.comparison is not None:
        cmp = audit.comparison
        rows = [_comparison_row(r) for r in cmp.rows() if r["status"] != "only recomputed"]
        comparison = {
            "summary": (f"{cmp.caveat[0].upper()}{cmp.caveat[1:]}. " if cmp.caveat else "")
            + f"{cmp.same} value(s) agree within {cmp.abs_tol:g} (in the units of "
            f"score.yaml), {len(cmp.differences)} differ.",
            "notes": list(cmp.notes),
            "extra": len(cmp.lines) - len(rows),
            "table": h.table(
                rows,
                columns=["key", "live", "recomputed", "difference", "status", "explanation"],
                row_class="status",
            ),
        }
    runs = None
    if tables["runs"]:
        runs = h.table(
            tables["runs"],
            columns=[
                "run",
                "start",
                "end",
                "duration",
                "outcome",
                "states",
                "manual_operation",
                "goal",
                "result",
            ],
        )
    timeline = None
    if tables["timeline"]:
        timeline = h.table(
            tables["timeline"],
            columns=["start", "machine", "state", "duration", "kind", "payload"],
            max_rows=TABLE_MAX_ROWS,
        )
    return {
        "facts": [(k, h.fmt(v)) for k, v in facts],
        "tables": found,
        "comparison": comparison,
        "live_text": audit.live_score_text,
        "runs": runs,
        "timeline": timeline,
        "timeline_count": len(tables["timeline"]),
    }


def _comparison_row(row: dict[str, Any]) -> dict[str, Any]:
    """A live-vs-recomputed row in display units: the key names its unit, values converted.

    The row's values are in the score's units; the quantity comes from the key's last part
    (``runs_details.0.distance_error`` is a length).
    """
    key = str(row["key"])
    spec = units.quantity_of(key)
    if spec is None or not any(
        units.is_number(row.get(c)) for c in ("live", "recomputed", "difference")
    ):
        return dict(row)
    k = units.factor(*spec)
    out = dict(row)
    out["key"] = units.label(key, spec[0])
    for col in ("live", "recomputed", "difference"):
        if units.is_number(row.get(col)):
            out[col] = float(row[col]) * k
    return out


def _provenance_context(
    score: BenchmarkResult | None,
    audit: Any,
    meta: dict[str, Any],
    input_records: list[FileRecord],
    configs: list[tuple[FileRecord, str | None]],
    written: list[str],
) -> dict[str, Any]:
    file_columns = ["name", "size (bytes)", "sha256", "path"]

    def files(records: list[FileRecord]) -> list[dict[str, Any]]:
        return [
            {"name": r.name, "size (bytes)": r.size, "sha256": r.sha256, "path": r.path}
            for r in records
        ]

    params: list[tuple[str, Any]] = []
    if score is not None:
        params += list(score.provenance.parameters)
    if audit is not None:
        params += [(f"audit {k}", v) for k, v in audit.provenance.parameters]
    if meta["team"]:
        source = SOURCE_TEXT.get(meta["team_source"] or "", "the command line")
        params.insert(0, ("team", f"{meta['team']} (from {source})"))
    software = [
        ("ertools", meta["ertools_version"]),
        ("python", platform.python_version()),
        ("platform", platform.platform()),
        ("generated", meta["generated"]),
        ("command line", shlex.join(meta["argv"]) if meta["argv"] else None),
    ]
    return {
        "inputs": h.table(files(input_records), columns=file_columns) if input_records else None,
        "configs": h.table(files([r for r, _ in configs]), columns=file_columns)
        if configs
        else None,
        "config_texts": [(r.name, text) for r, text in configs if text is not None],
        "parameters": [(k, h.fmt(v)) for k, v in params],
        "software": [(k, h.fmt(v)) for k, v in software],
        "files": ["result.json", *written],
    }
