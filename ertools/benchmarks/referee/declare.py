"""The referee-scored RSBB benchmarks as the registry sees them: one declaration per code of
:data:`~ertools.rsbb_states.REFEREE_CODES` (``hgtkmh``, ``hwv``, ``hcfgac``, ``stb``), the
same inputs and stages for each.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

from ertools.benchmarks.base import Input, Ranking, resolve_values
from ertools.benchmarks.legacy import LegacyBenchmark
from ertools.benchmarks.referee.config import CODES, RefereeOptions, make_options, title
from ertools.benchmarks.referee.formula import leaderboard_columns
from ertools.benchmarks.referee.pipeline import RefereeLogs, find_runs, load, score_runs
from ertools.benchmarks.referee.result import RefereeResult
from ertools.benchmarks.referee.rules import RULES

INPUTS = (
    Input(
        "description",
        "path",
        "rsbb_etc/config/benchmarks_description.yaml: the items' groups and order (default: "
        "the items as the log names them)",
        metavar="FILE",
    ),
    Input(
        "result",
        "path",
        "the run's result file, whose referee_score is used when it has one (scripted "
        "benchmarks; default: the RefBox's last values in /core/to_gui)",
        metavar="FILE",
    ),
    Input("run", "int", "the run's number (default: from the bag's name)", minimum=0),
)

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


def _declare(name: str) -> LegacyBenchmark[RefereeOptions, RefereeLogs, RefereeLogs, RefereeResult]:
    code = CODES[name]

    def options(given: Mapping[str, Any]) -> RefereeOptions:
        return make_options(code, resolve_values(INPUTS, given))

    def sample(samples: Path) -> list[str] | None:
        bags = sorted((samples / "season2019" / "rsbb_logs" / code).glob("*/run_*.bag"))
        return [str(bags[0])] if bags else None

    return LegacyBenchmark(
        rules=RULES,
        name=name,
        title=title(code),
        summary=f"{code}: the referee's items of an ERL @Home run, ranked by the ERL rule",
        example=f"ertools score {name} rsbb_logs/{code}/TEAM/run_1_DATE.bag",
        description=f"""Read the referee's score of an ERL @Home {code} run from its RSBB log.

Its items (achievements, penalized behaviors, disqualifying behaviors) with their values, what
they add up to, how long the benchmark executed and how it ended; ranked by the ERL rule.""",
        epilog=EPILOG.format(name=name, code=code),
        inputs=INPUTS,
        make_options=options,
        load=load,
        find_runs=find_runs,
        score_runs=score_runs,
        ranking=Ranking(
            key=lambda r: r.rank_value,
            lower_is_better=False,
            text=RULE_TEXT,
            columns=leaderboard_columns,
        ),
        score_keys=frozenset({"erl_rank", "achievements", "penalized_behaviors"}),
        sample=sample,
        bags_help="the run's bag (rsbb_logs/<CODE>/<team>/run_<n>_<date>.bag)",
        namespace="",
    )


HGTKMH = _declare("hgtkmh")
HWV = _declare("hwv")
HCFGAC = _declare("hcfgac")
STB = _declare("stb")
