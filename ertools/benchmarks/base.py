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
import sys
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, Generic, Literal, Protocol, TypeVar, runtime_checkable

import numpy as np

import ertools
from ertools.errors import UsageError
from ertools.progress import clear_current

if TYPE_CHECKING:  # annotations only: the registry (and `ertools score --help`) stays light
    import pandas as pd

    import ertools.yamlout  # reached as an attribute of the package, imported on first use
    from ertools.fidelity import Deviation
    from ertools.streams import Provenance

Rows = list[dict[str, Any]]

InputKind = Literal["path", "paths", "float", "int", "str", "choice", "flag"]


@dataclass(frozen=True)
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


@dataclass(frozen=True)
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


@dataclass(frozen=True)
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


@runtime_checkable
class BenchmarkResult(Protocol):
    """A frozen result of one benchmark execution.

    Attributes:
        name: the benchmark (``fbm3w``...), a key of ``ertools.benchmarks.registry.REGISTRY``.
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
    benchmark's :attr:`Benchmark.make_options` says about the values it was given (a
    deprecated spelling, a choice that differs from a node)."""

    clear_current()
    print(f"ertools: {message}", file=sys.stderr)


def dump_yaml(data: Any) -> str:
    """YAML as the 2015 nodes dumped it (block style, keys in insertion order), floats
    rounded to 9 decimal places (:mod:`ertools.yamlout`)."""
    # PyYAML (~25 ms) imported now, when YAML is written (JSON and text outputs do without it)
    text: str = ertools.yamlout.dump(data)
    return text


def jsonable(value: Any) -> Any:
    """Convert NumPy scalars/arrays and tuples inside ``value`` to plain JSON types."""

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
        bags_help: what the positional ``BAG...`` arguments are (default: log files).
        logs_are_bags: its logs are ROS1 bags, rosbag2 bags or MCAP files, which the
            manifest's ``--check`` verifies of every listed one; False for a benchmark that
            reads other files.
        logs_may_be_text: it also reads text trajectories (TUM, KITTI, EuRoC, ertools CSV),
            which ``--check`` accepts beside bags.
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
        files: bags, options, result -> the input files a report lists and hashes (default:
            the bags; e.g. the item list too, or the GT files a folder held).
        bags_metavar: the positional arguments' placeholder: one name (``BAG``: one or more
            bags) or two (``ROBOT_BAG``, ``GT_PATH``: the first, then any number of others).
        score_keys: keys of its ``score.json`` that say a score is this benchmark's (a
            score.json read without its result.json, ``ertools report``).
        state_topics: its RefBox/BmBox/Client state topics are logged under ``/NAME/``
            (``ertools audit`` can reconstruct it).
        values_2015: the :class:`Input` values that restore every 2015 behaviour (the audit
            compares the live score with the score recomputed with them); empty: none.
        from_live: the audit's hook: the options made from the values given and the live
            score (parsed) -> the options to rescore with and notes saying what was taken
            from the live score (FBM2H: the transform the node used).
        explanations: why a recomputed value may differ from the live one, by key (the
            audit's comparison shows the first that matches a differing key).
        sample: the sample logs' folder (``sample_bags/``) -> the arguments scoring this
            benchmark on them (``make demo``); None, or a None result: no sample.
        gt_only: a recording of the GT logger alone (its benchmark's topics, no state topics;
            its files, the first holding the name) -> the input values that score it as an
            execution (FBM2H: the timing file beside it; FBM3W: ``runs: auto``), or one line
            saying why it cannot be one. None: such recordings are never executions.
        namespace: the first part of its logs' topics (``/fbm2h/...``; default: ``name``),
            by which a log given to the wrong benchmark is recognised; empty: none.
        source_inputs: the inputs naming the logs' topics or frames: given, the user has
            chosen them and the log is taken as it is.
    """

    name: str
    title: str
    summary: str
    example: str
    description: str
    epilog: str
    inputs: tuple[Input, ...]
    make_options: Callable[[Mapping[str, Any]], OptionsT]
    load: Callable[[Sequence[Path], OptionsT], LoadedT]
    find_runs: Callable[[LoadedT, OptionsT], RunsT]
    score_runs: Callable[[LoadedT, RunsT, OptionsT], ResultT]
    ranking: Ranking
    notes: Callable[[ResultT], Sequence[str]] | None = None
    figures: str = ""
    foxglove: str = ""
    files: Callable[[Sequence[Path], OptionsT, ResultT], Sequence[Path]] | None = None
    bags_metavar: str | tuple[str, str] = "BAG"
    score_keys: frozenset[str] = frozenset()
    state_topics: bool = False
    values_2015: Mapping[str, Any] = field(default_factory=dict)
    from_live: Callable[[OptionsT, Any], tuple[OptionsT, tuple[str, ...]]] | None = None
    explanations: tuple[Explanation, ...] = ()
    sample: Callable[[Path], Sequence[str] | None] | None = None
    bags_help: str = "log file(s)"
    gt_only: Callable[[Sequence[Path]], Mapping[str, Any] | str] | None = None
    logs_are_bags: bool = True
    logs_may_be_text: bool = False
    namespace: str | None = None
    source_inputs: tuple[str, ...] = ("topic", "tf", "namespace")

    @property
    def log_namespace(self) -> str:
        """The first part of its logs' topics (:attr:`namespace`, default the name)."""
        return self.name if self.namespace is None else self.namespace

    def score(self, bags: Sequence[Path], options: OptionsT) -> ResultT:
        """The whole shape: load -> find runs -> score."""
        loaded = self.load(bags, options)
        return self.score_runs(loaded, self.find_runs(loaded, options), options)

    def input_files(self, bags: Sequence[Path], options: OptionsT, result: ResultT) -> list[Path]:
        """The files a report lists as this execution's inputs (:attr:`files`)."""
        if self.files is None:
            return list(bags)
        return list(self.files(bags, options, result))

    def input(self, name: str) -> Input:
        """The declared input called ``name`` (KeyError when there is none)."""
        for declared in self.inputs:
            if declared.name == name:
                return declared
        raise KeyError(name)


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
    stands for "not given". The first half of every :attr:`Benchmark.make_options`.

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
