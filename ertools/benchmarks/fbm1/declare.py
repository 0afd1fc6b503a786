"""FBM1@Home and FBM1@Work as the registry sees them: one set of inputs (the options of
``ertools score fbm1h|fbm1w``, the manifest keys), how they become :class:`Fbm1Options`, and
the load -> runs -> score stages. The two differ only in their name (the state topics'
namespace, where an item's name is read first, which nodes exist to reproduce).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import replace
from pathlib import Path
from typing import Any

from ertools.benchmarks.base import (
    Benchmark,
    Explanation,
    FormerName,
    Input,
    Ranking,
    notice,
    resolve_values,
    tf_value,
)
from ertools.benchmarks.common.ending import EXACT_HELP
from ertools.benchmarks.common.interval_output import (
    IntervalSettings,
    ScoreRow,
    interval_lines,
)
from ertools.benchmarks.common.uncertainty import INTERVAL_INPUTS
from ertools.benchmarks.common.validity import SCORE_AS_2015, unscoreable_input
from ertools.benchmarks.fbm1.benchmark import score_found
from ertools.benchmarks.fbm1.config import RULE_SETS, BodySources, Fbm1Options
from ertools.benchmarks.fbm1.gt import GtOptions
from ertools.benchmarks.fbm1.logs import Fbm1Logs, Fbm1Runs, load, locate_runs
from ertools.benchmarks.fbm1.result import Fbm1Result
from ertools.errors import ConfigError, UsageError
from ertools.io import PoseSource

GT_CHOICES = ("window", "placed", "goal", "result")
BODIES = "table and board poses"
GT = "ground truth"
NODES = "node rules (each option restores one behaviour of the 2015, 2016 or 2017 nodes)"


def inputs(name: str) -> tuple[Input, ...]:
    """The inputs of ``fbm1h`` or ``fbm1w`` (their default topics name the benchmark)."""
    bodies = []
    for body in ("origin", "ref_board"):
        flag = body.replace("_", "-")
        bodies += [
            Input(
                f"{body}_topic",
                "str",
                f"{body} pose topic (default /{name}/{body}/pose, else /tf frame {body})",
                metavar="TOPIC",
                group=BODIES,
            ),
            Input(
                f"{body}_tf",
                "str",
                f"take {body} from /tf PARENT -> CHILD (e.g. world:{body})",
                metavar="PARENT:CHILD",
                old_flags=(f"--{flag}-frame",),
                group=BODIES,
            ),
        ]
    return (
        Input("items", "path", "item list (seed Listing 9); required", metavar="FILE"),
        Input("results", "path", "answers kept outside the log (see below)", metavar="FILE"),
        Input(
            "items_order",
            "str",
            "comma-separated item ids (or instances) presented in runs 1, 2, ... "
            "(overrides the manual-operation payloads)",
            metavar="IDS",
        ),
        *bodies,
        Input(
            "time_source",
            "choice",
            "pose time: header stamp (mocap time, default) or bag record time",
            default="header",
            choices=("header", "record"),
            group=BODIES,
        ),
        Input(
            "gt",
            "choice",
            "window: mean over the stationary window before the goal (default); or one tf "
            "lookup interpolated at a moment: result: when the result arrived (2015 nodes), "
            "placed: when the placement was confirmed (2016 and 2017 @Home nodes), goal: when "
            "the goal was sent",
            choices=GT_CHOICES,
            group=GT,
        ),
        Input(
            "max_window",
            "float",
            "the ground-truth window reaches back at most this far before the goal (default 5 s)",
            default=5.0,
            unit="s",
            positive=True,
            group=GT,
        ),
        Input(
            "still",
            "float",
            "stationary tolerance (0.005 m)",
            default=0.005,
            unit="m",
            positive=True,
            group=GT,
        ),
        Input(
            "still_deg",
            "float",
            "stationary tolerance (1 deg)",
            default=1.0,
            unit="deg",
            positive=True,
            group=GT,
        ),
        Input(
            "max_gap",
            "float",
            "longer mocap gaps mean the body was lost (default 0.5 s)",
            default=0.5,
            unit="s",
            positive=True,
            group=GT,
        ),
        Input(
            "rules",
            "choice",
            "every behaviour of one reference at once: ertools (default), 2015 (the RoCKIn 2015 "
            "nodes: fbm1h e373be0, fbm1w 7628309), 2016 (@Home node 40ba68b, Lisbon 2016), "
            "2017 (@Home node 89dfa75, Lisbon 2017); single options below add to it",
            choices=RULE_SETS,
            group=NODES,
        ),
        Input("all_2015", "flag", "= --rules 2015", flag="--2015", group=NODES),
        # No later @Work node is known: @Work has no --2016 (--rules 2016 says why).
        *(
            [
                Input("all_2016", "flag", "= --rules 2016", flag="--2016", group=NODES),
                Input("all_2017", "flag", "= --rules 2017", flag="--2017", group=NODES),
            ]
            if name == "fbm1h"
            else []
        ),
        Input(
            "clip_above_diagonal",
            "flag",
            "translation term 1 only above sqrt(2) m (1..1.41 m stay unclipped)",
            old_flags=("--legacy-clip",),
            group=NODES,
        ),
        Input(
            "single_wrap",
            "flag",
            "theta error wrapped by a single 360",
            old_flags=("--legacy-wrap",),
            group=NODES,
        ),
        Input(
            "exact_names",
            "flag",
            "names compared exactly (blanks count)",
            old_flags=("--legacy-names",),
            group=NODES,
        ),
        Input("exact_end_payloads", "flag", EXACT_HELP, group=NODES),
        Input(
            "count_aborted",
            "flag",
            "a run stopped before its goal counts in every divisor (both nodes)",
            group=NODES,
        ),
        Input(
            "accuracy_over_10",
            "flag",
            "class and instance accuracies divided by 10 whatever the runs (2016, 2017 @Home)",
            group=NODES,
        ),
        # both nodes scored a run whose ground truth had no valid mocap sample (tracking lost)
        unscoreable_input(NODES, FormerName("score_unscoreable", SCORE_AS_2015)),
        Input(
            "legacy_totals",
            "flag",
            "deprecated: --count-aborted, and for fbm1h --accuracy-over-10",
            group=NODES,
        ),
        *INTERVAL_INPUTS,
    )


def _rules_name(v: Mapping[str, Any]) -> str:
    chosen = {v["rules"]} - {None}
    chosen |= {"2015"} if v["all_2015"] else set()
    chosen |= {"2016"} if v.get("all_2016") else set()
    chosen |= {"2017"} if v.get("all_2017") else set()
    if len(chosen) > 1:
        raise UsageError(f"--rules/--2015/--2016/--2017 name {len(chosen)} references; give one")
    return chosen.pop() if chosen else "ertools"


def _sources(name: str, v: Mapping[str, Any]) -> BodySources:
    time_source = v["time_source"]

    def one(body: str) -> PoseSource | None:
        flag = body.replace("_", "-")
        topic, tf = v[f"{body}_topic"], tf_value(f"--{flag}-tf", v[f"{body}_tf"])
        if topic is not None and tf is not None:
            raise UsageError(f"give either --{flag}-topic or --{flag}-tf, not both")
        if tf is not None:
            return PoseSource(frame=tf[1], parent=tf[0], time_source=time_source)
        if topic is None:
            if time_source == "header":
                return None  # the 2015 topic, falling back on the /tf frame
            topic = f"/{name}/{body}/pose"
        return PoseSource(topic=topic, time_source=time_source)

    return BodySources(one("origin"), one("ref_board"))


def options_maker(name: str) -> Callable[[Mapping[str, Any]], Fbm1Options]:
    """``make_options`` of ``fbm1h`` or ``fbm1w``."""

    def make_options(given: Mapping[str, Any]) -> Fbm1Options:
        """The values of :func:`inputs` -> :class:`Fbm1Options`.

        Raises:
            UsageError: a value out of range, no item list, a reference @Work lacks (exit 2).
        """
        v = resolve_values(inputs(name), given)
        if v["items"] is None:
            raise UsageError(
                "--items FILE is required (the item list, seed Listing 9); "
                f"`ertools score {name} --help` shows how"
            )
        if v["legacy_totals"]:
            now = (
                "--count-aborted (the 2015 @Work node's divisors)"
                if name == "fbm1w"
                else "--count-aborted --accuracy-over-10 (the 2016 and 2017 @Home nodes' divisors; "
                "the 2015 node's are --count-aborted alone)"
            )
            notice(f"note: --legacy-totals is deprecated, use {now}")
        gt = GtOptions(
            max_window_s=v["max_window"],
            still_m=v["still"],
            still_deg=v["still_deg"],
            max_gap_s=v["max_gap"],
        )
        rules_name = _rules_name(v)
        try:
            base = Fbm1Options.for_rules(name, rules_name, gt)
        except ConfigError as err:
            raise UsageError(f"--rules {rules_name}: {err.message}") from err
        r = base.rules
        old_totals = bool(v["legacy_totals"])
        rules = replace(
            r,
            clip_above_diagonal=r.clip_above_diagonal or v["clip_above_diagonal"],
            single_wrap=r.single_wrap or v["single_wrap"],
            exact_names=r.exact_names or v["exact_names"],
            count_aborted=r.count_aborted or v["count_aborted"] or old_totals,
            accuracy_over_10=r.accuracy_over_10
            or v["accuracy_over_10"]
            or (old_totals and name == "fbm1h"),
            score_unscoreable=r.score_unscoreable or v["unscoreable"] == SCORE_AS_2015,
        )
        if v["gt"] == "goal":
            notice(
                "--gt goal looks the ground truth up when the goal was sent; the 2016-17 nodes "
                "did it when the placement was confirmed (--gt placed)"
            )
        order = None
        if v["items_order"]:
            order = tuple(part.strip() for part in v["items_order"].split(",") if part.strip())
        return Fbm1Options(
            name,
            replace(base.gt, method=v["gt"] or base.gt.method),
            rules,
            items=v["items"],
            results=v["results"],
            items_order=order,
            sources=_sources(name, v),
            exact_end_payloads=base.exact_end_payloads or v["exact_end_payloads"],
            intervals=IntervalSettings.from_values(v),
        )

    return make_options


def _fmt(value: object, spec: str) -> str:
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return "-"
    if isinstance(value, bool):
        return "yes" if value else "no"
    return format(value, spec)


def notes(result: Fbm1Result) -> list[str]:
    """The reference reproduced and the per-run table (stdout keeps the parseable score)."""
    out = [f"reproducing: {result.reference}", f"{result.name}: {len(result.runs)} run(s)"]
    out.append(
        f"{'run':>3} {'item':<14} {'answer':<14} {'cls':>3} {'ins':>3} "
        f"{'dx mm':>7} {'dy mm':>7} {'dth deg':>8} {'pose':>6} {'time s':>7}  status"
    )
    for r in result.runs:
        e = r.errors
        item = f"{r.item.id}:{r.item.instance}" if r.item else (r.item_text or "?")
        ans = r.answer.item_instance if r.answer else "-"
        out.append(
            f"{r.index:>3} {item[:14]:<14} {ans[:14]:<14} {_fmt(r.class_ok, ''):>3} "
            f"{_fmt(r.instance_ok, ''):>3} {_fmt(e.dx * 1000 if e else None, '7.1f'):>7} "
            f"{_fmt(e.dy * 1000 if e else None, '7.1f'):>7} "
            f"{_fmt(e.theta_error_deg if e else None, '8.2f'):>8} "
            f"{_fmt(r.pose_score, '6.3f'):>6} {_fmt(r.execution_time_s, '7.2f'):>7}  {r.status}"
        )
    t = result.totals
    out.append(
        f"class_accuracy {_fmt(t.class_accuracy, '.3f')}  instance_accuracy "
        f"{_fmt(t.instance_accuracy, '.3f')}  pose_score {_fmt(t.pose_score, '.4f')}  "
        f"execution_time {t.execution_time:.2f} s"
    )
    if result.logged_score:
        logged = ", ".join(f"{k} {v}" for k, v in result.logged_score.items())
        out.append(f"the 2015 node sent: {logged}")
    out += interval_lines(
        [ScoreRow("pose_score", t.pose_score, result.intervals.get("pose_score"))],
        result.uncertainty,
    )
    if result.uncertainty is not None:
        out.append(
            "interval: class_accuracy, instance_accuracy and execution_time are counts and "
            "state times: no mocap noise enters them (no interval)"
        )
    return out


def files(bags: Sequence[Path], options: Fbm1Options, result: Fbm1Result) -> list[Path]:
    """The log and the item list (the report hashes both)."""
    return [*bags, *([options.items] if options.items is not None else [])]


def sampler(name: str) -> Callable[[Path], list[str] | None]:
    """The sample log of ``fbm1h`` or ``fbm1w`` with its item list (``make demo``)."""

    def sample(samples: Path) -> list[str] | None:
        folder = samples / name
        bags = sorted(folder.glob("*.bag"))
        items = folder / f"{name}.yaml"
        return [str(bags[0]), "--items", str(items)] if bags and items.is_file() else None

    return sample


# Why an audit's recomputed value may differ from the live one.
EXPLANATIONS = (
    Explanation(
        r"(pose_score|x_error|y_error|theta_error|position|orientation)$",
        "the ground truth is averaged over the window in which the board stood still "
        "(the 2015 node interpolated one tf lookup when the result arrived); theta is in "
        "degrees",
        ("window", "source", "topic", "items"),
    ),
    Explanation(
        r"(class|instance)(_accuracy|_correct)?$",
        "class and instance are compared as text with the item list",
        ("items",),
    ),
)


EPILOG = """examples:
  ertools score {name} run.bag --items configs/{name}.yaml
  ertools score fbm1w run.bag --items configs/fbm1w.yaml --items-order 3,7,1,2
  ertools score fbm1h run.bag --items fbm1h.yaml --results answers.yaml --format json
  ertools score fbm1h run.bag --items fbm1h.yaml --rules 2015   # RoCKIn 2015's node (e373be0)
  ertools score fbm1h run.bag --items fbm1h.yaml --rules 2016   # Lisbon 2016's (40ba68b)
  ertools score fbm1h run.bag --items fbm1h.yaml --rules 2017   # Lisbon 2017's (89dfa75)

--results FILE: a YAML list of answers, each {{run: N or item: ID, item_class, item_instance,
x, y, theta}} (theta in degrees), used instead of the Client payloads it covers.
The per-run table goes to stderr; stdout carries the score (YAML or JSON).
Exit status 1 when any run could not be scored (each named on stderr); the others are scored."""

DESCRIPTION = """Recompute an FBM1@Home / FBM1@Work (object perception) score from the log
(seed 7.1).

Per run: the item shown (manual-operation payload), the robot's answer (Client COMPLETED_GOAL
payload: item_class, item_instance, x, y in metres, theta in DEGREES, table frame), the
ground-truth item pose in the table frame (origin^-1 * ref_board * item transform, averaged
while the board stood still before the goal), class/instance right, pose score
1 - min(t, 1)/2 - min(|dtheta|/180, 1)/2. Totals as the 2015 node: class_accuracy,
instance_accuracy, pose_score, execution_time."""


def _declare(
    name: str, title: str, summary: str
) -> Benchmark[Fbm1Options, Fbm1Logs, Fbm1Runs, Fbm1Result]:
    return Benchmark(
        name=name,
        title=title,
        source_inputs=("origin_topic", "origin_tf", "ref_board_topic", "ref_board_tf"),
        summary=summary,
        example=f"ertools score {name} run.bag --items configs/{name}.yaml",
        description=DESCRIPTION,
        epilog=EPILOG.format(name=name),
        inputs=inputs(name),
        make_options=options_maker(name),
        load=load,
        find_runs=locate_runs,
        score_runs=score_found,
        ranking=Ranking(
            key=lambda r: r.totals.pose_score,
            lower_is_better=False,
            text="pose_score (0..1, the mean of the runs' pose scores): higher is better",
        ),
        notes=notes,
        figures="ertools.report.plots_fbm1:figure_specs",
        foxglove="ertools.report.foxglove.fbm1:content",
        files=files,
        score_keys=frozenset({"class_accuracy", "instance_accuracy"}),
        state_topics=True,
        values_2015={"rules": "2015"},
        sample=sampler(name),
        explanations=EXPLANATIONS,
    )


FBM1H = _declare("fbm1h", "FBM1@Home", "FBM1@Home object perception")
FBM1W = _declare("fbm1w", "FBM1@Work", "FBM1@Work object perception")
