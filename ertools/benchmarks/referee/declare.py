"""The referee-scored RSBB benchmarks as the registry sees them: one :class:`Referee` per code
of :data:`~ertools.benchmarks.referee.config.REFEREE_CODES` (``hgtkmh``, ``hwv``, ``hcfgac``,
``stb``), the same inputs (``config``) and stages (``pipeline``) for each. NumPy-free:
``ertools score hgtkmh``'s parser imports it.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ertools.benchmarks.base import (
    Benchmark,
    Described,
    Discovered,
    Ranking,
    Reported,
    Simulated,
)
from ertools.benchmarks.referee.config import CODES, INPUTS, RefereeOptions, make_options, title
from ertools.benchmarks.referee.rules import RULES
from ertools.errors import UsageError

if TYPE_CHECKING:  # annotations only: the stages import NumPy and the readers
    from ertools.benchmarks.referee.pipeline import RefereeLogs
    from ertools.benchmarks.referee.result import RefereeResult

RULE_TEXT = (
    "ERL rule: most achievements, then fewest penalized behaviors, then least time "
    "(erl_rank = achievements - penalties/1000 - seconds/10^7); a disqualifying behavior: "
    "not ranked: higher is better"
)

EPILOG = """examples:
  ertools score {name} rsbb_logs/{code}/teamA/run_1_2019-04-11-10-00-00.bag
  ertools score {name} RUN.bag --description rsbb_etc/config/benchmarks_description.yaml
  ertools score {name} RUN.bag --result RESULT.yaml        # a scripted run's referee_score

Nothing is recomputed: the referee scored these benchmarks. The items (achievements,
penalized and disqualifying behaviors, benchmarks_description.yaml) are read from the result
file's referee_score when given, else from the RefBox's GUI messages in the bag; a bool item
counts 0 or 1, a count item its value. The time is the time the benchmark executed (the RefBox
state topic, else the GUI's stop button enabled, to 0.1 s)."""

DESCRIPTION = """Read the referee's score of an ERL @Home {code} run from its RSBB log.

Its items (achievements, penalized behaviors, disqualifying behaviors) with their values, what
they add up to, how long the benchmark executed and how it ended; ranked by the ERL rule."""


def leaderboard_columns(score: Mapping[str, Any]) -> list[tuple[str, Any, str]]:
    """A leaderboard row's cells (the totals, the time, each item: ``formula``'s)."""
    from ertools.benchmarks.referee import formula  # lazy: the items' roles, PyYAML, 30 ms

    return formula.leaderboard_columns(score)


class Referee(
    Benchmark[RefereeOptions, "RefereeLogs", "RefereeLogs", "RefereeResult"],
    Described,
    Reported[RefereeOptions, "RefereeResult"],
    Discovered,
    Simulated,
):
    """A referee-scored benchmark: one class, four benchmarks (:data:`HGTKMH`, :data:`HWV`,
    :data:`HCFGAC`, :data:`STB`). Not Audited: its score is the referee's, nothing to
    recompute; it draws nothing."""

    inputs = INPUTS
    rules = RULES
    sample_part = True  # Simulated: its runs are part of season2019 (samples/season.py)
    bags_help = "the run's bag (rsbb_logs/<CODE>/<team>/run_<n>_<date>.bag)"
    score_keys = frozenset({"erl_rank", "achievements", "penalized_behaviors"})
    draws: frozenset[str] = frozenset()
    ranking = Ranking(
        key=lambda r: r.rank_value,
        lower_is_better=False,
        text=RULE_TEXT,
        columns=leaderboard_columns,
    )
    log_namespace = ""  # the RSBB's topics (/core/to_gui, /rsbb_log...), no namespace of its own

    def __init__(self, name: str) -> None:
        self.name = name
        self.code = CODES[name]
        self.title = title(self.code)
        self.example = f"ertools score {name} rsbb_logs/{self.code}/TEAM/run_1_DATE.bag"
        self.description = DESCRIPTION.format(code=self.code)
        self.epilog = EPILOG.format(name=name, code=self.code)

    def make_options(self, values: Mapping[str, Any]) -> RefereeOptions:
        return make_options(self.code, values)

    def load(self, logs: Sequence[Path], options: RefereeOptions) -> RefereeLogs:
        from ertools.benchmarks.referee import pipeline  # lazy: NumPy, the readers, 400 ms

        return pipeline.load(logs, options)

    def find_runs(self, loaded: RefereeLogs, options: RefereeOptions) -> RefereeLogs:
        from ertools.benchmarks.referee import pipeline  # lazy: NumPy, the readers, 400 ms

        return pipeline.find_runs(loaded, options)

    def score_runs(
        self, loaded: RefereeLogs, runs: RefereeLogs, options: RefereeOptions
    ) -> RefereeResult:
        from ertools.benchmarks.referee import pipeline  # lazy: NumPy, the readers, 400 ms

        return pipeline.score_runs(loaded, runs, options)

    def figures(self, result: RefereeResult) -> Sequence[Any]:
        """None: nothing is drawn from the referee's items (``draws`` is empty)."""
        return []

    def foxglove(self, out: Any, result: RefereeResult, *, limit: int) -> None:
        raise UsageError(f"--foxglove: no Foxglove export for {self.name} results")

    def sample_args(self, samples: Path) -> Sequence[str] | None:
        """The first run of the season sample (``make demo``)."""
        bags = sorted((samples / "season2019" / "rsbb_logs" / self.code).glob("*/run_*.bag"))
        return [str(bags[0])] if bags else None


HGTKMH = Referee("hgtkmh")
HWV = Referee("hwv")
HCFGAC = Referee("hcfgac")
STB = Referee("stb")
