"""A self-contained report folder a referee can open, archive and check.

``write_report(result, outdir, inputs=..., argv=...)`` writes:

- ``index.html``: score table, every figure of the benchmark, the audit timeline when the
  bag has state topics, warnings, deviations from the 2015 node, and the provenance needed to
  reproduce the score (inputs with SHA-256, configs, parameters, command line, version);
  no network needed: inline CSS, figures as PNG files beside it;
- ``score.yaml`` (the seed's listing), ``score.json``;
- one CSV per table of the result (``runs.csv``, ``segments.csv``...), ``audit_*.csv``;
- ``figures/*.svg`` (and ``*.png`` for figures still drawn by matplotlib);
- ``result.json``: the metadata ``ertools report`` combines (benchmark, team, inputs, the
  headline numbers and the whole score).

An :class:`~ertools.auditing.model.Audit` is accepted as well: its recomputed score (when there
is one) becomes the score of the folder, and ``audit.yaml``/``audit.json`` are added.
"""

from __future__ import annotations

import contextlib
import csv
import io
import json
import logging
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

from ertools._version import __version__
from ertools.atomic import write_text
from ertools.auditing.analyse import audit_states
from ertools.auditing.model import Audit
from ertools.benchmarks import registry
from ertools.benchmarks.base import Audited, BenchmarkResult, Rows
from ertools.benchmarks.common.teams import team_from_log_name, team_from_transform_name
from ertools.csvsafe import spreadsheet_safe
from ertools.errors import ConfigError, ErtoolsError
from ertools.io.reader import read_benchmark_states
from ertools.report import folder_page, plots_audit
from ertools.report.figures import FigureSpec, drawable, figure_specs, save_figures
from ertools.report.records import FileRecord, csv_stem, file_record
from ertools.serialize import jsonable

log = logging.getLogger("ertools.report.folder")

CONFIG_MAX_BYTES = 64 * 1024  # configs up to this size are shown in the page
_OUTPUT_OPTIONS = frozenset(
    {"-o", "--output", "--report", "--plot", "--plots", "--out", "--out-dir", "--foxglove"}
)


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
        result: any benchmark result, or an :class:`ertools.auditing.model.Audit`.
        outdir: the folder (created; files of the same names are overwritten).
        inputs: the bags the result was computed from (hashed, not modified).
        argv: the command line (shown; file arguments that are not inputs are the configs).
        audit: an audit to include; by default, when ``result`` is a benchmark score whose
            bags have its state topics, they are audited here.
        team: the team, when the caller knows it (else from ``--team``, the parameters or a
            ``transform-<team>.yaml`` argument).
    """

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

    before = _listed(outdir)
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
    files = [*written, "index.html", *(f"figures/{p.name}" for p, _ in figures)]
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
        "files": files,
    }
    _write(outdir / "result.json", json.dumps(jsonable(meta), indent=2))
    page = folder_page.page(
        score, audit, meta, input_records, configs, figures, figure_problems, written, outdir
    )
    index = outdir / "index.html"
    _write(index, page)
    _remove_stale(outdir, before - set(files))
    return index


def _listed(outdir: Path) -> set[str]:
    """The files a report already in ``outdir`` wrote (its ``result.json`` lists them)."""
    try:
        files = json.loads((outdir / "result.json").read_text(encoding="utf-8"))["files"]
    except (OSError, UnicodeDecodeError, ValueError, KeyError, TypeError):
        return set()  # no report of ertools' here: nothing is ours to remove
    return {f for f in files if isinstance(f, str)} if isinstance(files, list) else set()


def _remove_stale(outdir: Path, names: set[str]) -> None:
    """Remove the files of the previous report in ``outdir`` that this one did not write (a
    reused folder kept another benchmark's tables and figures beside the new ones); only
    files inside the folder, never anything else there."""
    root = outdir.resolve()
    for name in sorted(names):
        path = (outdir / name).resolve()
        if path.parent == root or root in path.parents:
            with contextlib.suppress(OSError):
                if path.is_file():
                    path.unlink()


# --------------------------------------------------------------------------------------------
# Gathering


def _write(path: Path, text: str) -> None:
    write_text(path, text if text.endswith("\n") else text + "\n")


def _audit_inputs(name: str, inputs: list[Path]) -> Any:
    """The audit of the bags' state topics, or None (no namespace, no topics, unreadable)."""
    bench = registry.get(name) if name in registry.names() else None
    if not isinstance(bench, Audited) or not inputs:
        return None

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
    return "" if value is None else spreadsheet_safe(value)


def _write_tables(outdir: Path, tables: dict[str, Rows], *, prefix: str) -> list[str]:
    names = []
    for name, rows in tables.items():
        safe = csv_stem(f"{prefix}{name}")
        columns = list(dict.fromkeys(k for row in rows for k in row))
        buffer = io.StringIO(newline="")
        writer = csv.writer(buffer)
        writer.writerow(columns)
        for row in rows:
            writer.writerow([_csv_cell(row.get(c)) for c in columns])
        write_text(outdir / f"{safe}.csv", buffer.getvalue())
        names.append(f"{safe}.csv")
    return names


def _figures(
    score: BenchmarkResult | None, audit: Any, figdir: Path
) -> tuple[list[tuple[Path, str]], list[str]]:
    """Draw every figure, one at a time, so that one failing plot does not lose the others."""

    specs: list[FigureSpec] = []
    problems: list[str] = []
    if score is not None:
        try:
            specs += figure_specs(score)
        except Exception as err:  # a missing or broken plot module must not lose the report
            log.warning("no figures for %s: %s", score.name, err)
            problems.append(f"no figures for {score.name}: {type(err).__name__}: {err}")
    if audit is not None:
        specs += [drawable(spec) for spec in plots_audit.figure_specs(audit)]
    out: list[tuple[Path, str]] = []
    for spec in specs:
        try:
            out += [(p, spec.title or spec.name) for p in save_figures([spec], figdir, None)]
        except Exception as err:  # a plotting bug must not cost the referee the report
            log.warning("figure %s failed: %s", spec.name, err)
            problems.append(f"figure {spec.name} could not be drawn: {err}")
    return out, problems
