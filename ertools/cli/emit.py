"""A benchmark result written as the commands that score print it: YAML/JSON with its
warnings, plots, report and Foxglove file. Their options are :mod:`ertools.cli.result_options`
(light: the parsers need them); the plain output helpers (``note``, ``write_text``,
``dump_json``) are in :mod:`ertools.cli.output`."""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from ertools.benchmarks import document
from ertools.benchmarks.base import BenchmarkResult
from ertools.benchmarks.common.teams import with_team
from ertools.benchmarks.document import all_failed
from ertools.cli.output import dump_json, note, write_text
from ertools.fidelity import differs_line


def emit_result(result: BenchmarkResult, args: argparse.Namespace, inputs: list[Path]) -> int:
    """Print a result in the chosen format, write its plots and report, return the exit code.

    Warnings and deviations from the 2015 node go to stderr, so a referee sees them even when
    stdout is redirected to a file. A result with nothing scored (:func:`all_failed`) prints
    its failures only and writes no output file, report, figure or Foxglove file.
    """
    if all_failed(result):
        for failure in result.failures:
            note(f"error: {failure}")
        return 1
    result = with_team(result, getattr(args, "team", None), inputs)
    fmt = getattr(args, "format", "yaml")
    text = result.to_yaml() if fmt == "yaml" else dump_json(document.score_json(result))
    write_text(text, getattr(args, "out", None))
    for line in getattr(result, "validity_lines", list)():
        note(line)
    for warning in result.warnings:
        note(f"warning: {warning}")
    for deviation in result.deviations:
        note(differs_line(deviation))
    write_plots_option(result, args)
    report_dir: Path | None = getattr(args, "report", None)
    if report_dir is not None:
        from ertools.report.folder import write_report  # lazy: pages, Jinja2: 35-70 ms

        index = write_report(
            result, report_dir, inputs=inputs, argv=getattr(args, "command_line", sys.argv)
        )
        note(f"wrote report {index}")
    write_foxglove_option(result, args, inputs)
    for failure in result.failures:
        note(f"error: {failure}")
    return 1 if result.failures else 0


def write_plots_option(result: Any, args: argparse.Namespace) -> None:
    """``--plot FILE`` / ``--plots DIR``: the result's figures (an audit's are those of its
    recomputed score), when asked for."""
    if getattr(args, "plot", None) is None and getattr(args, "plots", None) is None:
        return
    scored = getattr(result, "recomputed", None)
    from ertools.report.figures import figure_specs  # lazy: the charts, 40 ms; --plot only

    write_plots(figure_specs(scored if scored is not None else result), args)


def write_foxglove_option(result: Any, args: argparse.Namespace, inputs: list[Path]) -> None:
    """``--foxglove FILE.mcap``: the result's Foxglove file, when asked for."""
    path: Path | None = getattr(args, "foxglove", None)
    if path is None:
        return
    from ertools.report.foxglove.write import write_foxglove  # lazy: protobuf, 20-75 ms

    written = write_foxglove(result, path, inputs=inputs)
    note(f"wrote {written.path} ({written.messages} messages on {len(written.counts)} topics)")


def write_plots(specs: Sequence[Any], args: argparse.Namespace) -> list[Path]:
    """Write ``--plot FILE`` and ``--plots DIR`` of ``specs`` (:class:`FigureSpec`), when asked."""
    from ertools.report.figures import save_figures, save_one_file  # lazy: 40 ms

    written: list[Path] = []
    one: Path | None = getattr(args, "plot", None)
    if one is not None:
        written.append(save_one_file(specs, one))
        note(f"wrote {one} ({len(specs)} figure(s))")
    folder: Path | None = getattr(args, "plots", None)
    if folder is not None:
        paths = save_figures(specs, folder)
        written.extend(paths)
        note(f"wrote {len(paths)} figure(s) to {folder}/")
    return written
