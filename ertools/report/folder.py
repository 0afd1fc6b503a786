"""A self-contained report folder a referee can open, archive and check.

``write_report(result, outdir, inputs=..., argv=...)`` writes:

- ``index.html``: score table, every figure of the benchmark, the audit timeline when the
  bag has state topics, warnings, deviations from the 2015 node, and the provenance needed to
  reproduce the score (inputs with SHA-256, configs, parameters, command line, version);
  no network needed: inline CSS, figures as PNG files beside it;
- ``score.yaml`` (the seed's listing), ``score.json``;
- one CSV per table of the result (``runs.csv``, ``segments.csv``...), ``audit_*.csv``;
- ``figures/*.png``;
- ``result.json``: the metadata ``ertools report`` combines (benchmark, team, inputs, the
  headline numbers and the whole score).

An :class:`~ertools.audit.model.Audit` is accepted as well: its recomputed score (when there
is one) becomes the score of the folder, and ``audit.yaml``/``audit.json`` are added.
"""

from __future__ import annotations

import csv
import hashlib
import json
import logging
import platform
import re
import shlex
from dataclasses import dataclass
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

from ertools import __version__
from ertools.benchmarks import registry
from ertools.benchmarks.base import BenchmarkResult, Rows, jsonable
from ertools.benchmarks.common.teams import SOURCE_TEXT
from ertools.report import html as h
from ertools.report import units

log = logging.getLogger("ertools.report.folder")

CONFIG_MAX_BYTES = 64 * 1024  # configs up to this size are shown in the page
TABLE_MAX_ROWS = 200  # longer tables are in the CSV only
TABLE_OPEN_ROWS = 30  # longer tables are folded in the page
_CHUNK = 1 << 20
_EPOCH_COLUMNS = ("time", "from_time", "start_time")
_OUTPUT_OPTIONS = frozenset(
    {"-o", "--output", "--report", "--plot", "--plots", "--out", "--out-dir", "--foxglove"}
)


@dataclass(frozen=True)
class FileRecord:
    """An input or config file as the report records it."""

    name: str
    path: str
    sha256: str
    size: int

    def to_dict(self) -> dict[str, Any]:
        return {"name": self.name, "path": self.path, "sha256": self.sha256, "size": self.size}


def sha256_file(path: Path) -> str:
    """SHA-256 of a file, read in chunks (bags are large); of a directory (rosbag2), the
    SHA-256 of the sorted list of '<relative path> <sha256 of that file>' lines."""
    if path.is_dir():
        lines = [
            f"{p.relative_to(path).as_posix()} {sha256_file(p)}\n"
            for p in sorted(path.rglob("*"))
            if p.is_file()
        ]
        return hashlib.sha256("".join(lines).encode()).hexdigest()
    digest = hashlib.sha256()
    with path.open("rb") as fh:
        while chunk := fh.read(_CHUNK):
            digest.update(chunk)
    return digest.hexdigest()


def file_record(path: Path) -> FileRecord:
    size = (
        sum(p.stat().st_size for p in path.rglob("*") if p.is_file())
        if path.is_dir()
        else path.stat().st_size
    )
    return FileRecord(path.name, str(path), sha256_file(path), size)


def write_report(
    result: BenchmarkResult,
    outdir: Path,
    *,
    inputs: list[Path],
    argv: list[str],
    audit: Any = None,
    team: str | None = None,
) -> Path:
    """Write the report folder of ``result`` into ``outdir``; returns the ``index.html`` path.

    Args:
        result: any benchmark result, or an :class:`ertools.audit.model.Audit`.
        outdir: the folder (created; files of the same names are overwritten).
        inputs: the bags the result was computed from (hashed, not modified).
        argv: the command line (shown; file arguments that are not inputs are the configs).
        audit: an audit to include; by default, when ``result`` is a benchmark score whose
            bags have its state topics, they are audited here.
        team: the team, when the caller knows it (else from ``--team``, the parameters or a
            ``transform-<team>.yaml`` argument).
    """
    from ertools.errors import ConfigError

    try:
        outdir.mkdir(parents=True, exist_ok=True)
        return _write_report(result, outdir, inputs, argv, audit, team)
    except OSError as err:
        raise ConfigError(
            f"cannot write the report folder ({err.strerror or err}): choose another --report DIR",
            path=outdir,
        ) from err


def _write_report(
    result: BenchmarkResult,
    outdir: Path,
    inputs: list[Path],
    argv: list[str],
    audit: Any,
    team: str | None,
) -> Path:
    from ertools.audit.model import Audit

    score: BenchmarkResult | None
    if isinstance(result, Audit):
        audit, score = result, result.recomputed
    else:
        score = result
        if audit is None:
            audit = _audit_inputs(result.name, inputs)
    benchmark = score.name if score is not None else (audit.benchmark or "audit")
    inputs = [Path(p) for p in inputs]
    input_records = [file_record(p) for p in inputs if p.exists()]
    configs = _configs(argv, inputs, score)
    team_source: str | None = "explicit" if team else None
    if not team:
        team, team_source = _team(argv, inputs, score, audit, configs)

    written: list[str] = []
    if score is not None:
        _write(outdir / "score.yaml", score.to_yaml())
        _write(outdir / "score.json", json.dumps(jsonable(score.to_dict()), indent=2))
        written += ["score.yaml", "score.json"]
        written += _write_tables(outdir, score.tables(), prefix="")
    if audit is not None:
        _write(outdir / "audit.yaml", audit.to_yaml())
        _write(outdir / "audit.json", json.dumps(jsonable(audit.to_dict()), indent=2))
        written += ["audit.yaml", "audit.json"]
        audit_tables = {k: v for k, v in audit.tables().items() if k != "score_comparison"}
        written += _write_tables(outdir, audit_tables, prefix="audit_")
        if audit.comparison is not None:
            written += _write_tables(
                outdir, {"score_comparison": audit.comparison.rows()}, prefix=""
            )
    figures, figure_problems = _figures(score, audit, outdir / "figures")

    generated = datetime.now(UTC).isoformat(timespec="seconds")
    meta = {
        "benchmark": benchmark,
        "team": team,
        "team_source": team_source,
        "generated": generated,
        "ertools_version": __version__,
        "argv": list(argv),
        "inputs": [r.to_dict() for r in input_records],
        "configs": [r.to_dict() for r, _ in configs],
        "headline": headline(jsonable(score.to_dict())) if score is not None else {},
        "score": jsonable(score.to_dict()) if score is not None else None,
        "warnings": list(_warnings(score, audit)),
        "failures": list(score.failures if score is not None else ()),
        "audit": _audit_summary(audit),
        "files": [*written, "index.html", *(f"figures/{p.name}" for p, _ in figures)],
    }
    _write(outdir / "result.json", json.dumps(jsonable(meta), indent=2))
    page = _page(
        score, audit, meta, input_records, configs, figures, figure_problems, written, outdir
    )
    index = outdir / "index.html"
    _write(index, page)
    return index


# --------------------------------------------------------------------------------------------
# Gathering


def _write(path: Path, text: str) -> None:
    path.write_text(text if text.endswith("\n") else text + "\n", encoding="utf-8")


def _audit_inputs(name: str, inputs: list[Path]) -> Any:
    """The audit of the bags' state topics, or None (no namespace, no topics, unreadable)."""
    if name not in registry.names() or not registry.get(name).state_topics or not inputs:
        return None
    from ertools.audit.analyse import audit_states
    from ertools.errors import ErtoolsError
    from ertools.io import read_benchmark_states

    try:
        states = read_benchmark_states([Path(p) for p in inputs], name)
    except ErtoolsError as err:
        log.info("no audit in the report: %s", err)
        return None
    if states.bmbox is None and states.refbox is None and states.client is None:
        return None
    return audit_states(
        states.bmbox,
        states.refbox,
        states.client,
        benchmark=name,
        inputs=tuple(str(p) for p in inputs),
    )


def _configs(
    argv: list[str], inputs: list[Path], score: BenchmarkResult | None
) -> list[tuple[FileRecord, str | None]]:
    """Files named on the command line or in the provenance that are not inputs: configs.

    The text is kept (to show) when small and UTF-8.
    """
    seen = {p.resolve() for p in inputs if p.exists()}
    candidates: list[Path] = []
    skip_next = False
    for token in argv[1:]:
        if skip_next:  # the value of an output option: written by ertools, not read
            skip_next = False
            continue
        if token in _OUTPUT_OPTIONS:
            skip_next = True
            continue
        if token.split("=", 1)[0] in _OUTPUT_OPTIONS:
            continue
        value = token.split("=", 1)[1] if token.startswith("--") and "=" in token else token
        if value.startswith("-"):
            continue
        candidates.append(Path(value))
    if score is not None:
        candidates += [Path(p) for p in score.provenance.inputs]
    out: list[tuple[FileRecord, str | None]] = []
    for path in candidates:
        try:
            if not path.is_file() or path.resolve() in seen:
                continue
        except OSError:
            continue
        seen.add(path.resolve())
        record = file_record(path)
        text: str | None = None
        if record.size <= CONFIG_MAX_BYTES:
            try:
                text = path.read_text(encoding="utf-8")
            except (UnicodeDecodeError, OSError):
                text = None
        out.append((record, text))
    return out


def _team(
    argv: list[str],
    inputs: list[Path],
    score: BenchmarkResult | None,
    audit: Any,
    configs: list[tuple[FileRecord, str | None]],
) -> tuple[str | None, str | None]:
    """(team, where it was found): the result's own (``provenance.team``, set by the scoring
    commands), else ``--team`` on the command line, a rockin_logger input name, a
    ``team``/``robot_info`` parameter, a ``transform-<team>.yaml`` argument."""
    from ertools.benchmarks.common.teams import team_from_log_name, team_from_transform_name

    for holder in (score, audit):
        provenance = getattr(holder, "provenance", None)
        if provenance is not None and getattr(provenance, "team", None):
            return provenance.team, provenance.team_source
    for i, token in enumerate(argv):
        if token == "--team" and i + 1 < len(argv):
            return argv[i + 1], "explicit"
        if token.startswith("--team="):
            return token.split("=", 1)[1], "explicit"
    named = [*inputs, *(score.provenance.inputs if score is not None else ())]
    for path in (*named, *(getattr(getattr(audit, "provenance", None), "inputs", ()) or ())):
        found = team_from_log_name(path)
        if found:
            return found, "log name"
    if score is not None:
        for name, value in score.provenance.parameters:
            if name.lower() in ("team", "robot_info") and value not in ("", "identity"):
                return value, "transform" if name.lower() == "robot_info" else "explicit"
    for record, _ in configs:
        found = team_from_transform_name(record.name)
        if found:
            return found, "transform"
    return None, None


def headline(score: dict[str, Any]) -> dict[str, Any]:
    """The top-level scalar values of a score (``position_accuracy``, ``best_run``...)."""
    return {k: v for k, v in score.items() if v is None or isinstance(v, bool | int | float | str)}


def _warnings(score: BenchmarkResult | None, audit: Any) -> tuple[str, ...]:
    items = list(score.warnings) if score is not None else []
    if audit is not None:
        items += [w for w in audit.warnings if w not in items]
    return tuple(items)


def _audit_summary(audit: Any) -> dict[str, Any] | None:
    if audit is None:
        return None
    return {
        "runs": len(audit.runs),
        "illegal_transitions": len(audit.illegal_transitions),
        "silences": len(audit.silences),
        "early_ends": [e.reason for e in audit.early_ends],
        "live_score": jsonable(audit.live_score),
        "differences": len(audit.comparison.differences) if audit.comparison else None,
    }


def _csv_cell(value: Any) -> Any:
    value = jsonable(value)
    if isinstance(value, dict | list):
        return json.dumps(value)
    return "" if value is None else value


def csv_stem(name: str) -> str:
    """A table name as a safe file stem (the table names come from the scorers)."""
    return re.sub(r"[^A-Za-z0-9_.-]+", "_", name).strip(".") or "table"


def _write_tables(outdir: Path, tables: dict[str, Rows], *, prefix: str) -> list[str]:
    names = []
    for name, rows in tables.items():
        safe = csv_stem(f"{prefix}{name}")
        columns = list(dict.fromkeys(k for row in rows for k in row))
        with (outdir / f"{safe}.csv").open("w", newline="", encoding="utf-8") as fh:
            writer = csv.writer(fh)
            writer.writerow(columns)
            for row in rows:
                writer.writerow([_csv_cell(row.get(c)) for c in columns])
        names.append(f"{safe}.csv")
    return names


def _figures(
    score: BenchmarkResult | None, audit: Any, figdir: Path
) -> tuple[list[tuple[Path, str]], list[str]]:
    """Draw every figure, one at a time, so that one failing plot does not lose the others."""
    from ertools.report import plots_audit
    from ertools.report.figures import FigureSpec, figure_specs, save_figures

    specs: list[FigureSpec] = []
    problems: list[str] = []
    if score is not None:
        try:
            specs += figure_specs(score)
        except Exception as err:  # a missing or broken plot module must not lose the report
            log.warning("no figures for %s: %s", score.name, err)
            problems.append(f"no figures for {score.name}: {type(err).__name__}: {err}")
    if audit is not None:
        specs += plots_audit.figure_specs(audit)
    out: list[tuple[Path, str]] = []
    for spec in specs:
        try:
            out += [(p, spec.title or spec.name) for p in save_figures([spec], figdir)]
        except Exception as err:  # a plotting bug must not cost the referee the report
            log.warning("figure %s failed: %s", spec.name, err)
            problems.append(f"figure {spec.name} could not be drawn: {err}")
    return out, problems


# --------------------------------------------------------------------------------------------
# The page


def _page(
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
    from ertools.timeutil import iso_utc, ns_to_s

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
