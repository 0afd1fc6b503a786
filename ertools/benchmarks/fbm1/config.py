"""How an FBM1 score is computed (the options, as data): which node's behaviours to reproduce,
how the ground truth is measured, where the poses come from.

:func:`make_options` builds :class:`Fbm1Options` from the declared :func:`inputs`;
:meth:`Fbm1Options.for_rules` gives every behaviour of one node. NumPy-free: a parser imports
it.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import field, replace
from pathlib import Path
from typing import Any, Literal

from ertools.benchmarks.base import FormerName, Input, notice, resolve_values, tf_value
from ertools.benchmarks.common.inputs import (
    EXACT_HELP,
    INTERVAL_INPUTS,
    SCORE_AS_2015,
    IntervalSettings,
    unscoreable_input,
)
from ertools.errors import ConfigError, UsageError
from ertools.frozen_dataclass import frozen_dataclass
from ertools.io.model import PoseSource

BENCHMARKS = ("fbm1h", "fbm1w")


# The nodes ertools can reproduce (rockin-robot-challenge/benchmark_and_scoring_fbm, each read
# at its commit; the version table of docs/fidelity.md).
NODE_2015 = (
    "2015 node (rockin-robot-challenge/benchmark_and_scoring_fbm scripts/fbm1h at e373be0, "
    "scripts/fbm1w at 7628309: RoCKIn 2015 Lisbon): totals over runs played + aborted, ground "
    "truth looked up when the result arrived"
)


NODE_2016 = (
    "2016 @Home node (rockin-robot-challenge/benchmark_and_scoring_fbm scripts/fbm1h at "
    "40ba68b: the Lisbon 2016 second local competition): accuracies over 10, pose score over "
    "runs played + aborted, ground truth looked up when the placement was confirmed, before "
    "the goal"
)


NODE_2017 = (
    "2017 @Home node (rockin-robot-challenge/benchmark_and_scoring_fbm scripts/fbm1h at "
    "89dfa75: the Lisbon 2017 major tournament): the 2016 node with the translation term "
    "clipped at 1 m"
)


RULE_SETS = ("ertools", "2015", "2016", "2017")
# The --rules values each benchmark has (no later FBM1@Work node is known).
RULES_OF = {"fbm1h": RULE_SETS, "fbm1w": ("ertools", "2015")}


GtMethod = Literal["window", "placed", "goal", "result"]
GT_METHODS: tuple[str, ...] = ("window", "placed", "goal", "result")


@frozen_dataclass
class GtOptions:
    """How the ground truth of a run is measured.

    Attributes:
        method: ``window`` (mean over the stationary window before the goal), or one lookup
            interpolated at a moment: ``result`` (the result arrived: the 2015 nodes),
            ``placed`` (the placement confirmed: the 2016-17 @Home node), ``goal`` (the goal
            was sent).
        max_window_s: longest stationary window averaged.
        still_m: a board sample further than this from the board's pose at the goal ends the
            stationary window (metres; mocap noise is ~0.1 mm, a placement moves centimetres).
        still_deg: the same for the rotation, degrees.
        min_still_s: a shorter window is used but warned about (the board was still moving).
        max_gap_s: a gap longer than this in either body's samples means tracking was lost.
    """

    method: GtMethod = "window"
    max_window_s: float = 5.0
    still_m: float = 0.005
    still_deg: float = 1.0
    min_still_s: float = 0.5
    max_gap_s: float = 0.5


@frozen_dataclass
class ScoreRules:
    """Which node behaviours to reproduce (all False: ertools' rules; see the module doc)."""

    clip_above_diagonal: bool = False
    single_wrap: bool = False
    exact_names: bool = False
    count_aborted: bool = False
    accuracy_over_10: bool = False
    # a run whose ground truth has no valid mocap sample is scored from it (the nodes scored
    # what tf gave them) instead of being unscoreable
    score_unscoreable: bool = False

    @staticmethod
    def node_2015() -> ScoreRules:
        """The 2015 nodes (``fbm1h`` and ``fbm1w``): divisor ``runs`` for every total."""
        return ScoreRules(True, True, True, True, False, score_unscoreable=True)

    @staticmethod
    def node_2016() -> ScoreRules:
        """The 2016 @Home node (40ba68b): as 2015, accuracies divided by 10."""
        return ScoreRules(True, True, True, True, True, score_unscoreable=True)

    @staticmethod
    def node_2017() -> ScoreRules:
        """The 2017 @Home node (89dfa75): as 2016, the translation term clipped at 1 m."""
        return ScoreRules(False, True, True, True, True, score_unscoreable=True)


@frozen_dataclass
class BodySources:
    """Where the table and board poses come from (the 2015 topics when None)."""

    origin: PoseSource | None = None
    board: PoseSource | None = None


@frozen_dataclass
class Fbm1Options:
    """Everything that changes an FBM1 score besides the inputs.

    Attributes:
        benchmark: ``fbm1h`` or ``fbm1w``.
        gt: how the ground truth is measured (see :class:`GtOptions`).
        rules: which node behaviours to reproduce (see :class:`ScoreRules`).
        moved_warn_m: warn when the board moved more than this (metres, table plane) between
            the goal and the result, i.e. while the robot was looking.
        items: the item list (Listing 9); required to score a log.
        results: answers kept outside the log (replaces the Client payloads it covers).
        items_order: item ids or instances per run (overrides the payloads).
        sources: origin/board pose sources (the 2015 topics, else their /tf frames).
        exact_end_payloads: RefBox END payloads read as the 2015 BmBox did (only
            ``reason: timeout`` / ``reason: stop``; :func:`ertools.states.end_reason`).
        intervals: confidence level, Monte Carlo draws and seed of the score intervals.
    """

    benchmark: str = "fbm1h"
    gt: GtOptions = field(default_factory=GtOptions)
    rules: ScoreRules = field(default_factory=ScoreRules)
    moved_warn_m: float = 0.01
    items: Path | None = None
    results: Path | None = None
    items_order: tuple[str, ...] | None = None
    sources: BodySources = BodySources()
    exact_end_payloads: bool = False
    intervals: IntervalSettings = field(default_factory=IntervalSettings)

    @staticmethod
    def for_rules(benchmark: str, rules: str, gt: GtOptions | None = None) -> Fbm1Options:
        """Every behaviour of one reference: ``ertools``, ``2015``, ``2016`` or ``2017`` (the
        last two @Home only).

        ``gt`` gives the tolerances of the window (its method is replaced by the node's).

        Raises:
            ConfigError: an unknown reference, or ``2016`` / ``2017`` for @Work (no later
                @Work node is known).
        """

        base = gt or GtOptions()
        if rules == "ertools":
            return Fbm1Options(benchmark, base, ScoreRules())
        if rules == "2015":
            return Fbm1Options(
                benchmark,
                replace(base, method="result"),
                ScoreRules.node_2015(),
                exact_end_payloads=True,
            )
        if rules in ("2016", "2017") and benchmark == "fbm1h":
            # Both import the 2015 BmBox.py unchanged: its two END strings only.
            node = ScoreRules.node_2016() if rules == "2016" else ScoreRules.node_2017()
            return Fbm1Options(
                benchmark, replace(base, method="placed"), node, exact_end_payloads=True
            )
        if rules in ("2016", "2017"):
            raise ConfigError(
                f"no {rules} FBM1@Work node is known (scripts/fbm1w has one version, 7628309, "
                "RoCKIn 2015); use 2015"
            )
        raise ConfigError(f"unknown FBM1 rules {rules!r}; use {', '.join(RULE_SETS)}")

    @staticmethod
    def as_2015(benchmark: str) -> Fbm1Options:
        """The 2015 node's behaviour: every rule of it, and its single tf lookup."""
        return Fbm1Options.for_rules(benchmark, "2015")

    @property
    def reference(self) -> str:
        """Which reference these options reproduce: ertools, a node, or a mixture."""
        refs = (
            ("ertools", "ertools default"),
            ("2015", NODE_2015),
            ("2016", NODE_2016),
            ("2017", NODE_2017),
        )
        for name, text in refs:
            try:
                ref = Fbm1Options.for_rules(self.benchmark, name, self.gt)
            except ConfigError:
                continue
            same = ref.rules == self.rules and ref.gt.method == self.gt.method
            if same and ref.exact_end_payloads == self.exact_end_payloads:
                return text
        return "ertools with some node behaviours (see the rules)"


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


def make_options(name: str, given: Mapping[str, Any]) -> Fbm1Options:
    """The values of :func:`inputs` of ``fbm1h`` or ``fbm1w`` -> :class:`Fbm1Options`.

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
