"""Reconstruct a benchmark from its state topics and check it.

The timeline of the BmBox, RefBox and Client states (durations and payloads: goals, manual
operations, results, the score sent live, timeout/halt reasons); BmBox transitions the 2015
implementation did not allow; silences in the 10 Hz state heartbeat; runs ended by timeout or
halt. Where a scorer exists, the score is recomputed from the same bag and shown beside the
live score, each difference explained.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import TYPE_CHECKING

from ertools.auditing.recompute import ScoreInputs, audit_bag
from ertools.benchmarks import registry
from ertools.cli.emit import emit_result, write_foxglove_option, write_plots_option
from ertools.cli.options import non_negative_int, positive
from ertools.cli.output import note, write_text
from ertools.cli.result_options import add_output_options
from ertools.timeutil import s_to_ns

if TYPE_CHECKING:  # reached as an attribute of the package, imported on first use
    pass

EPILOG = """examples:
  ertools audit fbm2h.bag                       # YAML on stdout (--format text: a summary)
  ertools audit fbm2h.bag --transform transform-homer.yaml --report audit/
  ertools audit fbm1h.bag --items configs/fbm1h.yaml --format json
  ertools audit fbm3w.bag --config configs/fbm3w.yaml --max-silence 0.5 --no-rescore

The benchmark is the namespace of the state topics (/fbm2h/bmbox_state -> fbm2h); give
--benchmark when a bag holds several. Scoring inputs (--goal, --transform, --items, --config...)
are passed to the benchmark's scorer as `ertools score NAME` takes them.
Exit status: 0 (findings are reported, not errors; --strict makes them exit 1), 1 when the bag
has no state topics or cannot be read, or the recomputed score has failures."""

# Every registered benchmark (those without state topics say so when asked to audit).
BENCHMARKS = registry.names()


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("bags", nargs="+", type=Path, metavar="BAG", help="benchmark log(s)")
    parser.add_argument(
        "--benchmark", choices=BENCHMARKS, help="namespace of the state topics (default: inferred)"
    )
    parser.add_argument(
        "--max-silence",
        type=positive,
        default=1.0,
        metavar="S",
        help="report heartbeat gaps longer than S seconds (default 1; the beat is 0.1 s)",
    )
    parser.add_argument(
        "--no-rescore", action="store_true", help="do not recompute the score (timeline only)"
    )
    parser.add_argument(
        "--no-2015-check",
        action="store_true",
        help="when the scores differ, do not recompute with the 2015 rules to explain why",
    )
    parser.add_argument(
        "--strict",
        action="store_true",
        help="exit 1 when anything is found (illegal transition, silence, early end, difference)",
    )
    scoring = parser.add_argument_group("scoring inputs (passed to the benchmark's scorer)")
    scoring.add_argument("--goal", type=Path, metavar="FILE", help="fbm2h goal list")
    scoring.add_argument("--transform", type=Path, metavar="FILE", help="fbm2h transform")
    scoring.add_argument("--team", metavar="NAME", help="fbm2h: with --transforms")
    scoring.add_argument("--transforms", type=Path, metavar="DIR", help="fbm2h transforms folder")
    scoring.add_argument(
        "--hits", type=non_negative_int, metavar="N", help="fbm2h: the referee's hits"
    )
    scoring.add_argument("--items", type=Path, metavar="FILE", help="fbm1 item list")
    scoring.add_argument("--results", type=Path, metavar="FILE", help="fbm1 answers file")
    scoring.add_argument("--config", type=Path, metavar="FILE", help="fbm3w config")
    scoring.add_argument("--d-min", type=positive, metavar="M", help="fbm3w d_min in metres")
    scoring.add_argument("--topic", metavar="TOPIC", help="pose topic of the scorer")
    # YAML by default, as `ertools score`: an audit is a result (the recomputed score beside
    # the live one); text is the referee's summary. --plot/--plots: the recomputed score's
    # figures.
    add_output_options(parser, ("yaml", "json", "text"), team=False)


def run(args: argparse.Namespace) -> int:
    bags: list[Path] = list(args.bags)
    inputs = ScoreInputs(
        goal=args.goal,
        transform=args.transform,
        team=args.team,
        transforms=args.transforms,
        config=args.config,
        items=args.items,
        results=args.results,
        topic=args.topic,
        d_min=args.d_min,
        hits=args.hits,
    )
    audit, notes = audit_bag(
        bags,
        benchmark=args.benchmark,
        max_silence_ns=s_to_ns(args.max_silence),
        inputs=inputs,
        recompute=not args.no_rescore,
        check_2015=not args.no_2015_check,
    )
    for line in notes:
        note(f"warning: {line}")
    if args.format != "text":
        code = emit_result(audit, args, bags)
    else:
        write_text(audit.to_text(), args.out)
        for deviation in audit.deviations:
            note(f"differs from 2015: {deviation}")
        if args.report is not None:
            from ertools.report.folder import write_report  # lazy: pages, Jinja2: 35-70 ms

            index = write_report(
                audit, args.report, inputs=bags, argv=getattr(args, "command_line", sys.argv)
            )
            note(f"wrote report {index}")
        write_plots_option(audit, args)
        write_foxglove_option(audit, args, bags)
        for failure in audit.failures:
            note(f"error: {failure}")
        code = 1 if audit.failures else 0
    if args.strict and audit.findings and code == 0:
        note(f"{audit.findings} finding(s) and --strict: exit 1")
        return 1
    return code
