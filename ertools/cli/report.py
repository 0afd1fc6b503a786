"""Combine several results (a competition's runs) into one HTML page.

RESULTS are report folders written with `--report DIR`, their result.json, or score.json
files. The page has one table per benchmark, one row per result in rank order (rank, team,
headline numbers, warnings, failures, audit findings) and links to each report. Where the
results carry confidence intervals, each rank says whether the data supports it: the interval,
the probability of swapping with the next team, ties marked =N, and a plot of the intervals
(docs/uncertainty.md, "Rank stability").
"""

from __future__ import annotations

import argparse
from pathlib import Path

from ertools.cli.options import add_report, finite
from ertools.cli.output import note
from ertools.report.combine import combine

EPILOG = """examples:
  ertools score fbm3w run1.bag --report results/team-a-run1
  ertools score fbm3w run2.bag --report results/team-b-run1
  ertools report results/*/ --report competition/
  ertools report results/*/score.json --report competition/ --title "Lisbon 2015"
  ertools report results/*/ --report competition/ --confidence 0.9
"""


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "results", nargs="+", type=Path, metavar="RESULT", help="report folder or its JSON"
    )

    add_report(
        parser, "write the combined page here (DIR/index.html)", required=True, old=("--out",)
    )
    parser.add_argument("--title", default="Competition results", help="the page's title")
    parser.add_argument(
        "--confidence",
        type=_confidence,
        default=None,
        metavar="C",
        help="judge which rank differences the data supports at this confidence, 0 < C < 1 "
        "(default: the results' own, else 0.95); each interval is read at its own",
    )


def _confidence(text: str) -> float:
    value = finite(text)
    if not 0.0 < value < 1.0:
        raise argparse.ArgumentTypeError(f"{text}: a confidence is between 0 and 1 (0.95)")
    return value


def run(args: argparse.Namespace) -> int:
    index = combine(list(args.results), args.report, title=args.title, confidence=args.confidence)
    note(f"combined {len(args.results)} result(s) into {index}")
    print(index)
    return 0
