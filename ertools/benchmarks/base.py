"""What a benchmark is: the :class:`Benchmark` protocol every benchmark implements (its
:class:`Input` values become typed options, the logs are loaded, the runs found and scored
into a frozen :class:`BenchmarkResult`), and the optional parts a benchmark may add
(:class:`Described`, :class:`Reported`, :class:`Audited`, :class:`Discovered`,
:class:`Simulated`), so that ``score``, ``report``, ``audit`` and ``rescore`` treat every
benchmark alike (the registry, :mod:`ertools.benchmarks.registry`, lists them). Consumers ask
for a part with ``isinstance``, never for a name.

NumPy-free: the command line builds its parsers from these declarations.
"""

from __future__ import annotations

import math
import sys
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any, Literal, Protocol, TypeVar, runtime_checkable

from ertools.errors import UsageError
from ertools.frozen_dataclass import frozen_dataclass
from ertools.progress import clear_current

if TYPE_CHECKING:  # annotations only: the registry (and `ertools score --help`) stays light
    import pandas as pd

    from ertools.fidelity import Deviation, Rule
    from ertools.streams import Provenance

Rows = list[dict[str, Any]]

InputKind = Literal["path", "paths", "float", "int", "str", "choice", "flag"]


@frozen_dataclass
class FormerName:
    """A former name of an input, still accepted with a one-line deprecation note naming the
    new spelling: the option ``--`` + name (``-`` for ``_``), the manifest key and the keyword
    argument of :func:`ertools.score`.

    Attributes:
        name: the former name (``unscoreable_runs``).
        value: what a former *switch* (an option taking no value, ``--score-unscoreable``)
            stood for (``"2015"``); None: the former name took the input's own values.
    """

    name: str
    value: str | None = None

    @property
    def option(self) -> str:
        return "--" + self.name.replace("_", "-")

    def new_value(self, value: Any) -> Any:
        """The input's value for ``value`` given under this name (None: not given)."""
        if self.value is None:
            return value
        return self.value if value is True else None


@frozen_dataclass
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
        maximum: largest allowed value (inclusive); above it a usage error (exit 2) that names
            it, so that a typo (``--draws 1000000000``) is refused rather than run for hours.
        below: the value must be < this (a confidence level, below 1).
        repeat: the option may be given several times (a tuple of values).
        old_flags: former spellings, accepted for one release with a deprecation line.
        former: former names (:class:`FormerName`): unlike ``old_flags`` (command line only),
            also former manifest keys and keyword arguments, and possibly a switch standing
            for one value (``--score-unscoreable`` = ``--unscoreable 2015``).
        group: the help section (``2015 behaviour`` for the options that restore 2015).
        per_team: in a manifest, the value may differ per team (a marker-set transform).
        metavar: the placeholder in ``--help`` (default from ``unit`` or the kind).
        flag: the option's spelling when it is not derived from ``name``.
        with_file: for a ``choice``: the choices followed by a FILE on the command line
            (``--reached timing FILE``); the value is then ``(choice, path)``, else ``(choice,)``.
        needed_unless: for a ``per_team`` input without a default: the (input, choices) that
            make it unnecessary (a manifest requires it of every team otherwise). FBM2H's
            transform is not needed with ``reached`` ``timing`` or ``auto``: a log the GT logger
            wrote alone is scored as ``ertools score`` scores it without ``--transform``.
    """

    name: str
    kind: InputKind
    help: str
    default: Any = None
    unit: str = ""
    choices: tuple[str, ...] = ()
    minimum: float | None = None
    positive: bool = False
    maximum: float | None = None
    below: float | None = None
    repeat: bool = False
    old_flags: tuple[str, ...] = ()
    group: str = ""
    per_team: bool = False
    metavar: str = ""
    flag: str = ""
    with_file: tuple[str, ...] = ()
    needed_unless: tuple[tuple[str, tuple[str, ...]], ...] = ()
    former: tuple[FormerName, ...] = ()

    def needed(self, values: Mapping[str, Any]) -> bool:
        """Whether a manifest must give this per-team input, given the other ``values``."""
        if not self.per_team or self.default is not None:
            return False
        for name, choices in self.needed_unless:
            value = values.get(name)
            word = value[0] if isinstance(value, tuple | list) and value else value
            if word in choices:
                return False
        return True

    @property
    def option(self) -> str:
        """The command-line spelling (``--d-min``)."""
        return self.flag or "--" + self.name.replace("_", "-")


@frozen_dataclass
class Ranking:
    """How a leaderboard orders a benchmark's results (stated on the results page).

    ``key`` gives the number a result is ranked by (None: not ranked, e.g. nothing scored);
    ``lower_is_better`` its direction; ``text`` the rule in words; ``columns``, when given,
    what a leaderboard row shows beside it, from the result's JSON score: (header, value,
    what the header means) per cell (a referee-scored benchmark's items).
    """

    key: Callable[[Any], float | None]
    lower_is_better: bool
    text: str
    columns: Callable[[Mapping[str, Any]], Sequence[tuple[str, Any, str]]] | None = None


@frozen_dataclass
class Explanation:
    """Why a recomputed value may differ from the live one (``ertools audit``).

    ``pattern`` is a regular expression on the last component of the differing key,
    ``text`` the explanation, ``params`` fragments of parameter names worth showing beside it.
    """

    pattern: str
    text: str
    params: tuple[str, ...] = ()


OptionsT = TypeVar("OptionsT")
LoadedT = TypeVar("LoadedT")
RunsT = TypeVar("RunsT")
ResultT = TypeVar("ResultT", bound="BenchmarkResult")
ResultT_co = TypeVar("ResultT_co", bound="BenchmarkResult", covariant=True)
ResultT_contra = TypeVar("ResultT_contra", bound="BenchmarkResult", contravariant=True)
OptionsT_contra = TypeVar("OptionsT_contra", contravariant=True)


@runtime_checkable
class BenchmarkResult(Protocol):
    """A frozen result of one benchmark execution.

    Attributes:
        name: the benchmark (``fbm3w``...), a name of ``ertools.benchmarks.registry``.
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

    def to_frames(self) -> dict[str, pd.DataFrame]:
        """The :meth:`tables` as pandas DataFrames (epoch times as a UTC index)."""
        ...


def notice(message: str) -> None:
    """A human note on stderr (``ertools: message``), below any progress bar: what a
    benchmark's :meth:`Benchmark.make_options` says about the values it was given (a
    deprecated spelling, a choice that differs from a node)."""

    clear_current()
    print(f"ertools: {message}", file=sys.stderr)


@runtime_checkable
class Benchmark(Protocol[OptionsT, LoadedT, RunsT, ResultT_co]):
    """The part every benchmark has: its inputs and rules, and the four stages ``score``,
    ``audit``, ``rescore`` and :func:`ertools.score` run (through
    :func:`ertools.benchmarks.scoring.score_execution`): the values given -> options -> the
    logs loaded -> the runs found -> the frozen result.

    A benchmark's ``declare`` module defines a class that subclasses this protocol and the
    optional parts it has (:class:`Described`, :class:`Reported`, :class:`Audited`,
    :class:`Discovered`, :class:`Simulated`), so that mypy checks it, and names an instance
    ``BENCHMARK``; each stage method calls the function of the same name in its ``config``
    or ``pipeline`` module (docs/writing-a-benchmark.md).

    Attributes:
        name: the command name and registry key (``fbm3w``).
        title: the rulebook's name (``FBM3@Work``).
        inputs: every value it takes besides its logs (:class:`Input`).
        rules: its :class:`~ertools.fidelity.Rule` constants (the catalogue of deviations).
    """

    name: str
    title: str
    inputs: tuple[Input, ...]

    @property
    def rules(self) -> tuple[Rule, ...]:
        """Its :class:`~ertools.fidelity.Rule` constants: a class attribute, or a property
        that imports them when asked (not for a parser)."""
        ...

    def make_options(self, values: Mapping[str, Any]) -> OptionsT:
        """The values by :attr:`Input.name` (missing ones at their defaults) -> validated
        options; raises :class:`~ertools.errors.UsageError` (exit 2) or
        :class:`~ertools.errors.ConfigError` (a file's content, exit 1)."""
        ...

    def load(self, logs: Sequence[Path], options: OptionsT) -> LoadedT:
        """The logs read (poses, states, configs)."""
        ...

    def find_runs(self, loaded: LoadedT, options: OptionsT) -> RunsT:
        """The runs (segments, items) to score."""
        ...

    def score_runs(self, loaded: LoadedT, runs: RunsT, options: OptionsT) -> ResultT_co:
        """The frozen result."""
        ...

    def input(self, name: str) -> Input:
        """The declared input called ``name`` (KeyError when there is none)."""
        for declared in self.inputs:
            if declared.name == name:
                return declared
        raise KeyError(name)


@runtime_checkable
class Described(Protocol):
    """Its help: ``ertools score NAME --help`` and the examples of ``make demo``.

    Attributes:
        example: one command line (``ertools score fbm3w run.bag --config fbm3w.yaml``).
        description: the ``--help`` text above the options.
        epilog: examples and notes after the options.
        bags_help: what the positional log arguments are.
        bags_metavar: their placeholder: one name (``BAG``: one or more logs) or two
            (``ROBOT_BAG``, ``GT_PATH``: the first, then any number of others).
    """

    example: str
    description: str
    epilog: str
    bags_help: str = "log file(s)"
    bags_metavar: str | tuple[str, str] = "BAG"


@runtime_checkable
class Reported(Protocol[OptionsT_contra, ResultT_contra]):
    """What a report shows of its results: notes, figures, a Foxglove file, the input files.

    Attributes:
        score_keys: keys of its ``score.json`` that say a score is this benchmark's (a
            ``score.json`` read without its ``result.json`` by ``ertools report``).
        draws: which of ``figures`` and ``foxglove`` it has (:func:`offers`); one that draws
            nothing (the referee-scored benchmarks) is offered neither ``--plot`` nor
            ``--foxglove``.
    """

    score_keys: frozenset[str]
    draws: frozenset[str] = frozenset({"figures", "foxglove"})

    def notes(self, result: ResultT_contra) -> Sequence[str]:
        """Extra stderr lines after a score (the runs ``--runs auto`` found...)."""
        return ()

    def figures(self, result: ResultT_contra) -> Sequence[Any]:
        """The result's figures (:class:`ertools.views.spec.ChartSpec` or the report's
        ``FigureSpec``), drawn only for a report or ``--plot``."""
        ...

    def foxglove(self, out: Any, result: ResultT_contra, *, limit: int) -> None:
        """Add the result's Foxglove messages to ``out`` (a ``Collected``), streams thinned
        to ``limit`` messages."""
        ...

    def input_files(
        self, logs: Sequence[Path], options: OptionsT_contra, result: ResultT_contra
    ) -> list[Path]:
        """The files a report lists and hashes as this execution's inputs (the logs; the item
        list too, or the GT files a folder held)."""
        return list(logs)


def offers(bench: Any, part: str) -> bool:
    """Whether ``bench`` has ``part`` (``figures`` or ``foxglove``): what ``score`` offers
    (``--plot``, ``--foxglove``) and the demo asks for."""
    return isinstance(bench, Reported) and part in bench.draws


@runtime_checkable
class Audited(Protocol[OptionsT]):
    """Its state topics are logged under ``/NAME/`` (RefBox, BmBox, Client): ``ertools audit``
    reconstructs an execution and compares the live score with the recomputed one.

    Attributes:
        values_2015: the :class:`Input` values that restore every 2015 behaviour (the audit
            also recomputes with them); empty: none.
        explanations: why a recomputed value may differ from the live one, by key.
    """

    values_2015: Mapping[str, Any]
    explanations: tuple[Explanation, ...]

    def from_live(self, options: OptionsT, live: Any) -> tuple[OptionsT, tuple[str, ...]]:
        """The options to rescore with, given the live score (parsed), and notes saying what
        was taken from it (FBM2H: the transform its node used)."""
        return options, ()


@runtime_checkable
class Discovered(Protocol):
    """It is found among other logs: a competition ranks it, a log given to another benchmark
    is recognised as its.

    Attributes:
        ranking: the leaderboard rule.
        log_namespace: the first part of its logs' topics (``/fbm2h/...``); empty: none.
        logs_are_bags: its logs are bags or MCAP files (a manifest's ``--check`` opens them).
        logs_may_be_text: it also reads text trajectories (TUM, KITTI, EuRoC, ertools CSV).
        source_inputs: the inputs naming the logs' topics or frames: given, the user has
            chosen them and the log is taken as it is.
    """

    ranking: Ranking
    log_namespace: str
    logs_are_bags: bool = True
    logs_may_be_text: bool = False
    source_inputs: tuple[str, ...] = ("topic", "tf", "namespace")

    def gt_only(self, logs: Sequence[Path]) -> Mapping[str, Any] | str | None:
        """A recording of the GT logger alone (its topics, no state topics) -> the input
        values that score it as an execution (FBM2H: the timing file beside it), or one line
        saying why it cannot be one; None: such recordings are never executions."""
        return None


class Generate(Protocol):
    """A simulated scenario: writes its logs, answers and configs into ``outdir`` (which exists
    and is empty), every draw from ``seed``, and returns every path it wrote."""

    def __call__(self, outdir: Path, *, seed: int) -> list[Path]: ...


@runtime_checkable
class SeasonItems(Protocol):
    """Its RSBB runs (their code: its name in capitals) take the season's items file
    (``items_with_pose.yaml``: HOPF's objects and their poses) beside their config; the season
    layout attaches it to those runs alone (:func:`ertools.benchmarks.registry.season_items`)."""

    season_items: bool


@runtime_checkable
class LiveText(Protocol):
    """Its live score holds a value logged as text (HNF's ``robot_pose``: a Pose2D as PyYAML
    dumped it) that a results page shows as numbers
    (:func:`ertools.benchmarks.registry.live_numbers`)."""

    def live_numbers(self, value: str) -> tuple[tuple[str, float], ...] | None:
        """The numbers in ``value``, each with its quantity's key (``robot_pose.theta``);
        None: not such a text."""
        ...


@runtime_checkable
class Simulated(Protocol):
    """It has a simulated sample (``sample_bags/``, ``make demo``): the ``generate`` of the
    ``sample`` module beside its declaration, reached with
    :func:`ertools.benchmarks.registry.scenarios`."""

    #: The folder of ``sample_bags/`` its scenario writes ("": the benchmark's name).
    sample_folder: str = ""
    #: The seed its folder of ``sample_bags/`` was written with (fixed, so that ``python -m
    #: ertools.samples`` reproduces it byte for byte); 0: one derived from the folder's name.
    sample_seed: int = 0
    #: Its ``sample`` module writes no scenario of its own but a part another composes (the
    #: referee-scored runs of ``season2019``): :func:`ertools.benchmarks.registry.sample_parts`.
    sample_part: bool = False

    def sample_args(self, samples: Path) -> Sequence[str] | None:
        """The arguments scoring it on the sample logs under ``samples`` (None: not there)."""
        ...


AnyBenchmark = Benchmark[Any, Any, Any, Any]


def _one_value(declared: Input, value: Any) -> Any:
    """``value`` as ``declared`` types it; UsageError when it does not fit."""

    option = declared.option
    kind = declared.kind
    if kind == "flag":
        if not isinstance(value, bool):
            raise UsageError(f"{option} is a switch (true or false), got {value!r}")
        return value
    if kind in ("path", "paths"):
        if not isinstance(value, str | Path):
            raise UsageError(f"{option} must be a path, got {value!r}")
        return Path(value)
    if kind in ("str", "choice"):
        if kind == "choice" and declared.with_file:
            words = (value,) if isinstance(value, str) else tuple(map(str, value))
            return _choice_words(declared, words)
        if not isinstance(value, str):
            raise UsageError(f"{option} must be text, got {value!r}")
        if kind == "choice" and value not in declared.choices:
            raise UsageError(f"{option} {value!r}: choose from {', '.join(declared.choices)}")
        return value
    number: float
    try:
        if isinstance(value, bool):
            raise ValueError
        number = int(value) if kind == "int" else float(value)
        # an int is whole however large (float() would round 10**23 and call it fractional)
        if kind == "int" and not isinstance(value, int) and float(value) != number:
            raise ValueError
    except (TypeError, ValueError):
        what = "a whole number" if kind == "int" else "a number"
        raise UsageError(f"{option} must be {what}, got {value!r}") from None
    if not math.isfinite(number):
        raise UsageError(f"{option} must be a finite number, got {value!r}")
    from ertools.timeutil import MAX_SECONDS  # lazy: datetime, 1.4 ms: not for a parser

    if kind == "float" and abs(number) >= MAX_SECONDS:
        raise UsageError(f"{option} {value}: give a number smaller than {MAX_SECONDS:g} in size")
    unit = f" {declared.unit}" if declared.unit else ""
    if declared.positive and number <= (declared.minimum or 0.0):
        bound = "positive" if not declared.minimum else f"> {declared.minimum:g}{unit}"
        raise UsageError(f"{option} must be {bound}, got {value}")
    if declared.minimum is not None and number < declared.minimum:
        raise UsageError(f"{option} must be >= {declared.minimum:g}{unit}, got {value}")
    if declared.below is not None and number >= declared.below:
        raise UsageError(f"{option} must be < {declared.below:g}{unit}, got {value}")
    if declared.maximum is not None and number > declared.maximum:
        top = f"{declared.maximum:g}" if kind == "float" else str(int(declared.maximum))
        raise UsageError(f"{option} {value}: at most {top}{unit}")
    return number


def _choice_words(declared: Input, words: tuple[str, ...]) -> tuple[str, ...]:
    """``(choice,)`` or ``(choice, FILE)`` for a choice declared ``with_file``."""

    expected = " | ".join(c + " FILE" if c in declared.with_file else c for c in declared.choices)
    if not words or words[0] not in declared.choices:
        raise UsageError(f"{declared.option}: expected {expected}, got {' '.join(words)}")
    need = 2 if words[0] in declared.with_file else 1
    if len(words) != need:
        if need == 2:
            raise UsageError(f"{declared.option} {words[0]} needs exactly one FILE")
        raise UsageError(f"{declared.option}: expected {expected}, got {' '.join(words)}")
    return words


def tf_value(option: str, text: str | None) -> tuple[str, str] | None:
    """A ``--tf``-style value as (parent, child): ``PARENT:CHILD``, or a bare ``FRAME`` (the
    old ``--frame FRAME`` spelling) meaning ``world:FRAME``; None when not given.

    Raises:
        UsageError: not one or two non-empty frame names.
    """

    if text is None:
        return None
    parent, sep, child = text.partition(":")
    if not sep:
        parent, child = "world", text
    if not parent or not child or ":" in child:
        raise UsageError(f"{option} {text!r}: give PARENT:CHILD, e.g. world:robot_at_work")
    return parent, child


def resolve_values(inputs: Sequence[Input], given: Mapping[str, Any]) -> dict[str, Any]:
    """Every declared input's value: ``given`` (by :attr:`Input.name`) checked against its
    declaration (kind, choices, minimum, positive), the others at their defaults. None
    stands for "not given". The first half of every :meth:`Benchmark.make_options`.

    Raises:
        UsageError: an unknown name, or a value that does not fit its declaration.
    """

    known = {i.name: i for i in inputs}
    unknown = sorted(set(given) - set(known))
    if unknown:
        raise UsageError(
            f"unknown input(s) {', '.join(unknown)}: expected some of {', '.join(known)}"
        )
    out: dict[str, Any] = {}
    for name, declared in known.items():
        value: Any = given.get(name)
        if value is None:
            value = declared.default
        if value is None and declared.kind == "flag":
            value = False
        if value is None:
            out[name] = () if declared.repeat else None
        elif declared.repeat or declared.kind == "paths":
            values: list[Any] = [value] if isinstance(value, str | Path) else list(value)
            out[name] = tuple(_one_value(declared, v) for v in values)
        else:
            out[name] = _one_value(declared, value)
    return out


def rename_former(
    inputs: Sequence[Input], given: Mapping[str, Any], *, where: str = ""
) -> dict[str, Any]:
    """``given`` (values by name) with each :attr:`Input.former` name's value moved to its
    input's name, each said once on stderr naming the new spelling: as a keyword argument
    (``unscoreable_runs='2015' is deprecated, use unscoreable='2015'``), or as a manifest
    key under ``where`` (``benchmarks.fbm3w.inputs.unscoreable_runs is deprecated, use
    benchmarks.fbm3w.inputs.unscoreable: 2015``). The current name wins when both are given.
    """

    formers = {f.name: (i, f) for i in inputs for f in i.former}
    out = {k: v for k, v in given.items() if k not in formers}
    for key, value in given.items():
        if key not in formers or value is None or value is False:
            continue
        declared, former = formers[key]
        new = former.new_value(value)
        if where:
            old_text = f"{where}.{key}"
            new_text = f"{where}.{declared.name}: {new}"
        else:
            old_text = f"{key}={value!r}"
            new_text = f"{declared.name}={new!r}"
        notice(f"note: {old_text} is deprecated, use {new_text}")
        if out.get(declared.name) is None and new is not None:
            out[declared.name] = new
    return out
