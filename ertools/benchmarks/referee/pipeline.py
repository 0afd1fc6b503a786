"""A referee-scored run, from its bag (and result file) to its result: the load, find runs and
score runs stages.

The items' values come from the run's result file (``referee_score``: scripted benchmarks such
as STB) or else from the RefBox's GUI messages in the bag (``/core/to_gui``: the task
benchmarks, which have no result file). The time the benchmark executed comes from the RefBox
state topic when the run has one (from EXECUTING_BENCHMARK to its end), else from the GUI
messages (the time the stop button was enabled).
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

from ertools.benchmarks.base import notice
from ertools.benchmarks.referee.config import RefereeOptions
from ertools.benchmarks.referee.items import (
    Item,
    items_from_result,
    load_descriptions,
    match_description,
    tally,
)
from ertools.benchmarks.referee.result import RefereeResult
from ertools.benchmarks.referee.zone import ZoneSeries, read_zone
from ertools.errors import ConfigError, TopicError, UsageError
from ertools.frozen_dataclass import frozen_dataclass
from ertools.io.reader import topics
from ertools.rsbb.layout import FileKind, classify
from ertools.rsbb.log import EndKind, read_rsbb_run
from ertools.rsbb.results import load_result
from ertools.rsbb.sidefiles import find_side_files, run_place
from ertools.rsbb_states import BENCHMARKS, REFBOX_STATE_TOPIC
from ertools.streams import Provenance

_END_TEXT = {
    EndKind.END: "END: benchmark ended normally",
    EndKind.STOP: "STOP: benchmark stopped by referee",
    EndKind.GLOBAL_TIMEOUT: "GLOBAL_TIMEOUT: benchmark ended due to global timeout",
    EndKind.LOG_ENDS: "still executing when the log ends",
    EndKind.NOT_STARTED: "never started in the log",
    EndKind.OTHER: "ended by an emergency stop or an error",
}


@frozen_dataclass
class RefereeLogs:
    """What a run's files say.

    Attributes:
        bag: the run bag.
        team, run: the run's team and number ("" / None when nothing says).
        items: the items' values as logged, and where they were read.
        executing_ns: how long the benchmark executed (None: not in the log).
        end: how it ended.
        notes: warnings met while reading.
    """

    bag: Path
    team: str
    run: int | None
    items: tuple[Item, ...]
    items_source: str
    executing_ns: int | None
    end: str
    notes: tuple[str, ...]
    result: Path | None = None


DESCRIPTION = Path("rsbb_etc", "config", "benchmarks_description.yaml")


def description_file(bag: Path) -> Path | None:
    """``rsbb_etc/config/benchmarks_description.yaml`` of the season holding ``bag``."""
    root = run_place(bag).root
    path = None if root is None else root / DESCRIPTION
    return path if path is not None and path.is_file() else None


def _where(bag: Path, options: RefereeOptions) -> tuple[str | None, int | None]:
    """The run's team and number: the options', else the RSBB folder's and name's."""
    found = classify(bag)
    team, run = options.team, options.run
    if found is not None and found.kind is FileKind.RUN_BAG:
        if found.code != options.code:
            raise ConfigError(
                f"{bag} is a {found.code} run (its RSBB folder says so), not {options.code}: "
                f"score it with `ertools score {str(found.code).lower()}`"
            )
        team = team or found.team
        run = run if run is not None else found.run
    return team, run


def _from_result(path: Path, options: RefereeOptions) -> tuple[Item, ...] | None:
    result = load_result(path)
    if result.code != options.code:
        raise ConfigError(f"{path}: a {result.code} result file, not {options.code}'s")
    if result.referee_score is None:
        return None
    return items_from_result(result.referee_score, str(path))


def _time_from_states(bag: Path) -> tuple[int | None, str]:
    run = read_rsbb_run(bag)
    if run.t_start_ns is None or run.t_end_ns is None:
        return None, _END_TEXT[run.end_kind]
    return run.t_end_ns - run.t_start_ns, _END_TEXT[run.end_kind]


def load(bags: Sequence[Path], options: RefereeOptions) -> RefereeLogs:
    """Read the run.

    Raises:
        UsageError: more than one bag.
        ConfigError: a bag of another benchmark (exit 1: the file, not the command line).
        TopicError: no items anywhere (no result file's ``referee_score``, no GUI messages).
        ConfigError: an unreadable result or description file.
    """
    if len(bags) != 1:
        raise UsageError(f"give one run bag (rsbb_logs/{options.code}/<team>/run_<n>_<date>.bag)")
    bag = Path(bags[0])
    team, run = _where(bag, options)
    notes: list[str] = []
    result = options.result
    if result is None and BENCHMARKS[options.code].scripted:
        side = find_side_files(bag, options.code, want={"result"}, team=team)
        result = side.result
        for line in side.found:
            notice(line)
    items = _from_result(result, options) if result is not None else None
    source = f"result file {result}"
    zone: ZoneSeries | None = None
    try:
        zone = read_zone(bag, options.code, team, run)
    except TopicError:
        if items is None:
            raise
    if items is None:
        assert zone is not None
        items, source = zone.items, "/core/to_gui (the RefBox's last values)"
    elif zone is not None and _values(zone.items) != _values(items):
        notes.append(
            "the RefBox's last values (/core/to_gui) differ from the result file's "
            "referee_score: the result file's are used (the referee changed them after its "
            "last save?)"
        )
    if zone is not None:
        team = team or zone.team
        run = run if run is not None else zone.run
    if REFBOX_STATE_TOPIC in topics(bag):
        executing, end = _time_from_states(bag)
    elif zone is not None:
        spans = zone.spans()
        executing = zone.executing_ns() if spans else None
        end = zone.end_state() or ("still executing when the log ends" if spans else "")
    else:
        executing, end = None, ""
    if executing is None:
        notes.append("the log does not say how long the benchmark executed: ranked last on time")
    return RefereeLogs(
        bag, team or "", run, tuple(items), source, executing, end, tuple(notes), result
    )


def _values(items: Sequence[Item]) -> list[tuple[str, int]]:
    return sorted((i.desc.strip(), i.value) for i in items)


def find_runs(loaded: RefereeLogs, options: RefereeOptions) -> RefereeLogs:
    """A run bag is one run."""
    return loaded


def score_runs(loaded: RefereeLogs, runs: RefereeLogs, options: RefereeOptions) -> RefereeResult:
    """The items in the description's order (when given) and their tally."""
    notes = list(runs.notes)
    items = runs.items
    inputs = [str(runs.bag)]
    description = options.description
    if description is None:
        description = description_file(runs.bag)
        if description is not None:
            notice(f"the benchmarks description found in the RSBB layout: {description}")
    if description is not None:
        descriptions = load_descriptions(description)
        inputs.append(str(description))
        spec = descriptions.get(options.code)
        if spec is None:
            notes.append(f"{description} does not describe {options.code}")
        else:
            items, differences = match_description(items, spec.items)
            notes += list(differences)
    if runs.result is not None:
        inputs.append(str(runs.result))
    counted = tally(items)
    if counted.disqualified:
        notes.append("disqualified: " + "; ".join(counted.disqualified))
    return RefereeResult(
        name=options.code.lower(),
        code=options.code,
        team=runs.team or None,
        run=runs.run,
        items=items,
        items_source=runs.items_source,
        tally=counted,
        executing_ns=runs.executing_ns,
        end=runs.end,
        warnings=tuple(notes),
        provenance=Provenance(
            inputs=tuple(inputs),
            parameters=(("benchmark_code", options.code),),
            team=runs.team or None,
            team_source="RSBB folder" if runs.team else None,
        ),
    )
