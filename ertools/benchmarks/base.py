"""What a benchmark is: its declared inputs, how it finds runs and scores them, and what its
result offers, so that ``score``, ``report``, ``audit`` and ``rescore`` treat every benchmark
alike (the registry, :mod:`ertools.benchmarks.registry`, lists them).

Every benchmark has the same shape: its bags and :class:`Input` values become typed options
(:attr:`Benchmark.make_options`), the logs are loaded (:attr:`Benchmark.load`), the runs found
(:attr:`Benchmark.find_runs`) and scored (:attr:`Benchmark.score_runs`) into a frozen
:class:`BenchmarkResult`.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Generic, Literal, Protocol, TypeVar, runtime_checkable

from ertools.fidelity import Deviation
from ertools.streams import Provenance

Rows = list[dict[str, Any]]

InputKind = Literal["path", "paths", "float", "int", "str", "choice", "flag"]


@dataclass(frozen=True)
class Input:
    """One value a benchmark takes besides its bags, declared once: it is the command-line option
    of ``ertools score NAME``, the key of the competition manifest and a row of the report's
    parameter table.

    Attributes:
        name: Python identifier, manifest key and report row (``d_min``); the option is
            ``--`` + name with ``-`` for ``_`` unless ``flag`` says otherwise.
        kind: ``path``/``paths`` (files, checked to exist), ``float``/``int``, ``str``,
            ``choice`` (one of ``choices``), ``flag`` (a switch, default False).
        help: one line for ``--help``, the manifest documentation and the report.
        default: value when not given (None: the benchmark chooses, e.g. from a config file).
        unit: SI unit of a number (``m``, ``s``, ``m/s``, ``rad``), shown in help and report.
        minimum: smallest allowed value (inclusive unless ``positive``); a value outside is a
            usage error (exit 2).
        positive: the value must be > 0 (> ``minimum`` when both are given).
        repeat: the option may be given several times (a tuple of values).
        old_flags: former spellings, accepted for one release with a deprecation line.
        group: the help section (``2015 behaviour`` for the options that restore 2015).
        per_team: in a manifest, the value may differ per team (a marker-set transform).
        metavar: the placeholder in ``--help`` (default from ``unit`` or the kind).
        flag: the option's spelling when it is not derived from ``name``.
    """

    name: str
    kind: InputKind
    help: str
    default: Any = None
    unit: str = ""
    choices: tuple[str, ...] = ()
    minimum: float | None = None
    positive: bool = False
    repeat: bool = False
    old_flags: tuple[str, ...] = ()
    group: str = ""
    per_team: bool = False
    metavar: str = ""
    flag: str = ""

    @property
    def option(self) -> str:
        """The command-line spelling (``--d-min``)."""
        return self.flag or "--" + self.name.replace("_", "-")


@dataclass(frozen=True)
class Ranking:
    """How a leaderboard orders a benchmark's results (stated on the results page).

    ``key`` gives the number a result is ranked by (None: not ranked, e.g. nothing scored);
    ``lower_is_better`` its direction; ``text`` the rule in words.
    """

    key: Callable[[Any], float | None]
    lower_is_better: bool
    text: str


OptionsT = TypeVar("OptionsT")
LoadedT = TypeVar("LoadedT")
RunsT = TypeVar("RunsT")
ResultT = TypeVar("ResultT", bound="BenchmarkResult")


@runtime_checkable
class BenchmarkResult(Protocol):
    """A frozen result of one benchmark execution.

    Attributes:
        name: the benchmark (``fbm3w``...), a key of ``ertools.benchmarks.REGISTRY``.
        warnings: things a referee should know (d_min below the noise, identity transform...).
        deviations: every place where ertools deliberately differs from the 2015 node.
        failures: runs/segments/items that could not be scored (the CLI then exits 1).
        provenance: inputs and parameters.
    """

    # Read-only properties, so that frozen dataclasses with these fields satisfy the protocol.
    @property
    def name(self) -> str: ...

    @property
    def warnings(self) -> tuple[str, ...]: ...

    @property
    def deviations(self) -> tuple[Deviation, ...]: ...

    @property
    def failures(self) -> tuple[str, ...]: ...

    @property
    def provenance(self) -> Provenance: ...

    def to_dict(self) -> dict[str, Any]:
        """JSON-able structure (same nesting as the YAML; run indices as string keys)."""
        ...

    def to_yaml(self) -> str:
        """The seed's score listing for this benchmark."""
        ...

    def tables(self) -> dict[str, Rows]:
        """CSV-ready tables by name (``runs``, ``segments``, ``items``, ``samples``...)."""
        ...


def dump_yaml(data: Any) -> str:
    """YAML as the 2015 nodes dumped it (block style, keys in insertion order), floats
    rounded to 9 decimal places (:mod:`ertools.yamlout`)."""
    from ertools.yamlout import dump

    return dump(data)


def jsonable(value: Any) -> Any:
    """Convert NumPy scalars/arrays and tuples inside ``value`` to plain JSON types."""
    import numpy as np

    if isinstance(value, dict):
        return {str(k): jsonable(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [jsonable(v) for v in value]
    if isinstance(value, np.ndarray):
        return jsonable(value.tolist())
    if isinstance(value, np.bool_):
        return bool(value)
    if isinstance(value, np.integer):
        return int(value)
    if isinstance(value, np.floating):
        f = float(value)
        return None if math.isnan(f) else f
    if isinstance(value, float) and math.isnan(value):
        return None
    return value


@dataclass(frozen=True)
class Benchmark(Generic[OptionsT, LoadedT, RunsT, ResultT]):
    """A benchmark: what ``score``, ``report``, ``audit`` and ``rescore`` need to know of it.

    Attributes:
        name: the command name and registry key (``fbm3w``).
        title: the rulebook's name (``FBM3@Work``).
        summary: one line for ``ertools score --help``.
        example: one command line shown under the summary.
        description: the ``ertools score NAME --help`` text.
        epilog: examples and notes after the options in ``--help``.
        bags_help: what the positional ``BAG...`` arguments are.
        inputs: every value it takes besides its bags (see :class:`Input`).
        make_options: the values by :attr:`Input.name` (missing ones at their defaults) ->
            validated options; raises :class:`~ertools.errors.UsageError` (exit 2) or
            :class:`~ertools.errors.ConfigError` (a file's content, exit 1).
        load: bags and options -> the logs read (poses, states, configs).
        find_runs: the logs -> the runs (segments, items) to score.
        score_runs: logs, runs, options -> the frozen result.
        ranking: the leaderboard rule.
        notes: extra stderr lines after a score (runs found by ``--runs auto``...).
        figures: ``module:function`` drawing the result's figures (imported only for a report:
            matplotlib is heavy), empty when it has none.
        foxglove: ``module:function`` giving its Foxglove content, empty when it has none.
    """

    name: str
    title: str
    summary: str
    example: str
    description: str
    epilog: str
    bags_help: str
    inputs: tuple[Input, ...]
    make_options: Callable[[Mapping[str, Any]], OptionsT]
    load: Callable[[Sequence[Path], OptionsT], LoadedT]
    find_runs: Callable[[LoadedT, OptionsT], RunsT]
    score_runs: Callable[[LoadedT, RunsT, OptionsT], ResultT]
    ranking: Ranking
    notes: Callable[[ResultT], Sequence[str]] | None = None
    figures: str = ""
    foxglove: str = ""

    def score(self, bags: Sequence[Path], options: OptionsT) -> ResultT:
        """The whole shape: load -> find runs -> score."""
        loaded = self.load(bags, options)
        return self.score_runs(loaded, self.find_runs(loaded, options), options)

    def input(self, name: str) -> Input:
        """The declared input called ``name`` (KeyError when there is none)."""
        for declared in self.inputs:
            if declared.name == name:
                return declared
        raise KeyError(name)
