"""The output options of the commands that print a benchmark result (``--format``, ``--out``,
``--report``, ``--plot``, ``--foxglove``, ``--team``). Light: a command's parser is built from
them before anything is scored; :mod:`ertools.cli.emit` writes what they ask for."""

from __future__ import annotations

import argparse
from pathlib import Path

from ertools.cli.options import add_output, add_plots, add_report


def add_output_options(
    parser: argparse.ArgumentParser,
    formats: tuple[str, ...] = ("yaml", "json"),
    *,
    report: bool = True,
    plot: bool = True,
    foxglove: bool = True,
    team: bool = True,
) -> None:
    """``--format``, ``--out/-o``, ``--team``, and where the benchmark has them
    ``--report``/``--plot``/``--plots``/``--foxglove``: the vocabulary of
    :mod:`ertools.cli.options` (old spellings ``--output`` and ``--plot DIR`` still work, with
    a deprecation note)."""
    add_output(parser, formats)
    if report:
        add_report(
            parser,
            "write a self-contained report folder (index.html, score.yaml/json, CSV, plots)",
        )
    if plot:
        add_plots(parser, what="the benchmark's figures (one panel each)")
    if foxglove:
        parser.add_argument(
            "--foxglove",
            type=Path,
            metavar="FILE.mcap",
            help="write what was scored (paths, targets, pairs, errors, states) as an MCAP "
            "file for Foxglove (docs/foxglove.md)",
        )
    if team:
        parser.add_argument(
            "--team",
            metavar="NAME",
            help="the team that ran it, kept in the result and report (default: a name in the "
            "state payloads, else the rockin_logger log name <BENCHMARK>_<DATE>_<NAME>.bag, "
            "else the FBM2H transform's team); fbm2h --transforms DIR: DIR/transform-NAME.yaml",
        )
