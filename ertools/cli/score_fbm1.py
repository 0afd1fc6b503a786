"""Recompute an FBM1@Home / FBM1@Work (object perception) score from the log (seed 7.1).

Per run: the item shown (manual-operation payload), the robot's answer (Client COMPLETED_GOAL
payload: item_class, item_instance, x, y in metres, theta in DEGREES, table frame), the
ground-truth item pose in the table frame (origin^-1 * ref_board * item transform, averaged
while the board stood still before the goal), class/instance right, pose score
1 - min(t, 1)/2 - min(|dtheta|/180, 1)/2. Totals as the 2015 node: class_accuracy,
instance_accuracy, pose_score, execution_time.
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path
from typing import cast

from ertools.cli.common import add_output_options, all_failed, emit_result, note

EPILOG = """examples:
  ertools score fbm1h run.bag --items configs/fbm1h.yaml
  ertools score fbm1w run.bag --items configs/fbm1w.yaml --items-order 3,7,1,2
  ertools score fbm1h run.bag --items fbm1h.yaml --results answers.yaml --format json
  ertools score fbm1h run.bag --items fbm1h.yaml --rules 2015   # the 2015 node's numbers
  ertools score fbm1h run.bag --items fbm1h.yaml --rules 2016   # the 2016-17 @Home node's

--results FILE: a YAML list of answers, each {run: N or item: ID, item_class, item_instance,
x, y, theta} (theta in degrees), used instead of the Client payloads it covers.
The per-run table goes to stderr; stdout carries the score (YAML or JSON).
Exit status 1 when any run could not be scored (each named on stderr); the others are scored."""


def add_arguments(parser: argparse.ArgumentParser) -> None:
    # One module serves `score fbm1h` and `score fbm1w`: the parser's prog says which.
    benchmark = "fbm1w" if parser.prog.rstrip().endswith("fbm1w") else "fbm1h"
    parser.set_defaults(benchmark=benchmark)
    parser.add_argument("bags", nargs="+", type=Path, metavar="BAG", help="log file(s)")
    parser.add_argument(
        "--items", type=Path, required=True, metavar="FILE", help="item list (seed Listing 9)"
    )
    parser.add_argument(
        "--results", type=Path, metavar="FILE", help="answers kept outside the log (see below)"
    )
    parser.add_argument(
        "--items-order",
        metavar="IDS",
        help="comma-separated item ids (or instances) presented in runs 1, 2, ... "
        "(overrides the manual-operation payloads)",
    )
    bodies = parser.add_argument_group("table and board poses")
    for body, flag in (("origin", "origin"), ("ref_board", "ref-board")):
        bodies.add_argument(
            f"--{flag}-topic",
            metavar="TOPIC",
            help=f"{body} pose topic (default /{benchmark}/{body}/pose, else /tf frame {body})",
        )
        bodies.add_argument(
            f"--{flag}-frame", metavar="FRAME", help=f"take {body} from /tf world -> FRAME"
        )
    bodies.add_argument(
        "--time-source",
        choices=("header", "record"),
        default="header",
        help="pose time: header stamp (mocap time, default) or bag record time",
    )
    gt = parser.add_argument_group("ground truth")
    gt.add_argument(
        "--gt",
        choices=GT_CHOICES,
        default=None,
        help="window: mean over the stationary window before the goal (default); or one tf "
        "lookup interpolated at a moment: result: when the result arrived (2015 nodes), "
        "placed: when the placement was confirmed (2016-17 @Home node), goal: when the goal "
        "was sent",
    )
    gt.add_argument("--max-window", type=float, default=5.0, metavar="S", help="default 5")
    gt.add_argument(
        "--still", type=float, default=0.005, metavar="M", help="stationary tolerance (0.005 m)"
    )
    gt.add_argument(
        "--still-deg", type=float, default=1.0, metavar="DEG", help="stationary tolerance (1 deg)"
    )
    gt.add_argument(
        "--max-gap",
        type=float,
        default=0.5,
        metavar="S",
        help="longer mocap gaps mean the body was lost (default 0.5 s)",
    )
    nodes = parser.add_argument_group(
        "node rules (each option restores one behaviour of the 2015 / 2016-17 nodes)"
    )
    nodes.add_argument(
        "--rules",
        choices=RULE_SETS,
        default=None,
        help="every behaviour of one reference at once: ertools (default), 2015 (the 2015 "
        "nodes), 2016 (the 2016-17 @Home node); single options below add to it",
    )
    nodes.add_argument(
        "--2015", dest="rules", action="store_const", const="2015", help="= --rules 2015"
    )
    nodes.add_argument(
        "--2016", dest="rules", action="store_const", const="2016", help="= --rules 2016"
    )
    nodes.add_argument(
        "--clip-above-diagonal",
        action="store_true",
        help="translation term 1 only above sqrt(2) m (1..1.41 m stay unclipped)",
    )
    nodes.add_argument(
        "--single-wrap", action="store_true", help="theta error wrapped by a single 360"
    )
    nodes.add_argument(
        "--exact-names", action="store_true", help="names compared exactly (blanks count)"
    )
    nodes.add_argument(
        "--count-aborted",
        action="store_true",
        help="a run stopped before its goal counts in every divisor (both nodes)",
    )
    nodes.add_argument(
        "--accuracy-over-10",
        action="store_true",
        help="class and instance accuracies divided by 10 whatever the runs (2016-17 @Home)",
    )
    for old_flag in DEPRECATED:
        nodes.add_argument(old_flag, action="store_true", help=argparse.SUPPRESS)
    add_output_options(parser)


GT_CHOICES = ("window", "placed", "goal", "result")
RULE_SETS = ("ertools", "2015", "2016")
# Old spellings: what each now means (one note on stderr when used).
DEPRECATED = {
    "--legacy-clip": "--clip-above-diagonal",
    "--legacy-wrap": "--single-wrap",
    "--legacy-names": "--exact-names",
    "--legacy-totals": "--count-aborted --accuracy-over-10 (the 2016-17 @Home node's divisors; "
    "the 2015 node's are --count-aborted alone)",
}


def _options(args: argparse.Namespace) -> object:
    from dataclasses import replace

    from ertools.benchmarks.fbm1.benchmark import Fbm1Options
    from ertools.benchmarks.fbm1.gt import GtOptions
    from ertools.errors import ConfigError, UsageError

    for name in ("max_window", "still", "still_deg", "max_gap"):
        if getattr(args, name) <= 0:
            raise UsageError(f"--{name.replace('_', '-')} must be positive")
    for old_flag, now in DEPRECATED.items():
        if getattr(args, old_flag[2:].replace("-", "_")):
            if old_flag == "--legacy-totals" and args.benchmark == "fbm1w":
                now = "--count-aborted (the 2015 @Work node's divisors)"
            note(f"{old_flag} is deprecated: it now means {now}")
    gt = GtOptions(
        max_window_s=args.max_window,
        still_m=args.still,
        still_deg=args.still_deg,
        max_gap_s=args.max_gap,
    )
    try:
        base = Fbm1Options.for_rules(args.benchmark, args.rules or "ertools", gt)
    except ConfigError as err:
        raise UsageError(f"--rules {args.rules}: {err.message}") from err
    old_totals = bool(args.legacy_totals)
    r = base.rules
    rules = replace(
        r,
        clip_above_diagonal=r.clip_above_diagonal or args.clip_above_diagonal or args.legacy_clip,
        single_wrap=r.single_wrap or args.single_wrap or args.legacy_wrap,
        exact_names=r.exact_names or args.exact_names or args.legacy_names,
        count_aborted=r.count_aborted or args.count_aborted or old_totals,
        accuracy_over_10=r.accuracy_over_10
        or args.accuracy_over_10
        or (old_totals and args.benchmark == "fbm1h"),
    )
    method = args.gt or base.gt.method
    options = Fbm1Options(args.benchmark, replace(base.gt, method=method), rules)
    if args.gt == "goal":
        note(
            "--gt goal looks the ground truth up when the goal was sent; the 2016-17 node "
            "did it when the placement was confirmed (--gt placed)"
        )
    return options


def _sources(args: argparse.Namespace) -> object:
    from ertools.benchmarks.fbm1.benchmark import BodySources
    from ertools.io import PoseSource

    def one(body: str, topic: str | None, frame: str | None) -> PoseSource | None:
        if topic is None and frame is None:
            if args.time_source == "header":
                return None  # the 2015 topic, falling back on the /tf frame
            topic = f"/{args.benchmark}/{body}/pose"
        return PoseSource(topic=topic, frame=frame, time_source=args.time_source)

    return BodySources(
        one("origin", args.origin_topic, args.origin_frame),
        one("ref_board", args.ref_board_topic, args.ref_board_frame),
    )


def run(args: argparse.Namespace) -> int:
    from ertools.benchmarks.base import BenchmarkResult
    from ertools.benchmarks.fbm1.benchmark import BodySources, Fbm1Options, score_fbm1_bag

    options = _options(args)
    sources = _sources(args)
    assert isinstance(options, Fbm1Options) and isinstance(sources, BodySources)
    order = None
    if args.items_order:
        order = [part.strip() for part in args.items_order.split(",") if part.strip()]
    result = score_fbm1_bag(
        args.bags,
        args.items,
        options=options,
        results_path=args.results,
        items_order=order,
        sources=sources,
    )
    if not all_failed(result):  # nothing scored: only the errors (emit_result)
        note(f"reproducing: {result.reference}")
        print_table(result)
    # A frozen dataclass satisfies the protocol at run time; mypy wants settable attributes.
    return emit_result(cast("BenchmarkResult", result), args, [*args.bags, args.items])


def _fmt(value: object, spec: str) -> str:
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return "-"
    if isinstance(value, bool):
        return "yes" if value else "no"
    return format(value, spec)


def print_table(result: object) -> None:
    """The per-run table on stderr (stdout keeps the parseable score)."""
    from ertools.benchmarks.fbm1.result import Fbm1Result

    assert isinstance(result, Fbm1Result)
    head = (
        f"{'run':>3} {'item':<14} {'answer':<14} {'cls':>3} {'ins':>3} "
        f"{'dx mm':>7} {'dy mm':>7} {'dth deg':>8} {'pose':>6} {'time s':>7}  status"
    )
    note(f"{result.name}: {len(result.runs)} run(s)")
    note(head)
    for r in result.runs:
        e = r.errors
        item = f"{r.item.id}:{r.item.instance}" if r.item else (r.item_text or "?")
        ans = r.answer.item_instance if r.answer else "-"
        note(
            f"{r.index:>3} {item[:14]:<14} {ans[:14]:<14} {_fmt(r.class_ok, ''):>3} "
            f"{_fmt(r.instance_ok, ''):>3} {_fmt(e.dx * 1000 if e else None, '7.1f'):>7} "
            f"{_fmt(e.dy * 1000 if e else None, '7.1f'):>7} "
            f"{_fmt(e.theta_error_deg if e else None, '8.2f'):>8} "
            f"{_fmt(r.pose_score, '6.3f'):>6} {_fmt(r.execution_time_s, '7.2f'):>7}  {r.status}"
        )
    t = result.totals
    note(
        f"class_accuracy {_fmt(t.class_accuracy, '.3f')}  instance_accuracy "
        f"{_fmt(t.instance_accuracy, '.3f')}  pose_score {_fmt(t.pose_score, '.4f')}  "
        f"execution_time {t.execution_time:.2f} s"
    )
    if result.logged_score:
        logged = ", ".join(f"{k} {v}" for k, v in result.logged_score.items())
        note(f"the 2015 node sent: {logged}")
