"""How an FBM1 score is computed (the options, as data): which node's behaviours to reproduce,
how the ground truth is measured, where the poses come from.

:func:`ertools.benchmarks.fbm1.declare.options_maker` builds :class:`Fbm1Options` from the
declared inputs; :meth:`Fbm1Options.for_rules` gives every behaviour of one node.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from pathlib import Path

from ertools.benchmarks.common.interval_output import IntervalSettings
from ertools.benchmarks.fbm1.gt import (
    GtOptions,
)
from ertools.benchmarks.fbm1.score import (
    ScoreRules,
)
from ertools.errors import ConfigError
from ertools.io import PoseSource

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


@dataclass(frozen=True)
class BodySources:
    """Where the table and board poses come from (the 2015 topics when None)."""

    origin: PoseSource | None = None
    board: PoseSource | None = None


@dataclass(frozen=True)
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
