"""The benchmark record of before issue 37 (one dataclass of 29 fields), kept while the
benchmarks declared with it are converted to the protocols of :mod:`ertools.benchmarks.base`.

The registry hands out no :class:`LegacyBenchmark`: :func:`adapt` wraps one into an object
that implements :class:`~ertools.benchmarks.base.Benchmark` and exactly the optional parts
the record fills (Audited when ``state_topics``, Simulated when ``sample``), so that every
consumer sees one shape. This module goes when the last benchmark is converted.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from functools import cache
from importlib import import_module
from pathlib import Path
from typing import TYPE_CHECKING, Any, Generic, TypeVar

from ertools.benchmarks.base import (
    AnyBenchmark,
    Audited,
    Benchmark,
    Described,
    Discovered,
    Explanation,
    Input,
    Ranking,
    Reported,
    Simulated,
)
from ertools.errors import UsageError

if TYPE_CHECKING:
    from ertools.benchmarks.base import BenchmarkResult
    from ertools.fidelity import Rule

OptionsT = TypeVar("OptionsT")
LoadedT = TypeVar("LoadedT")
RunsT = TypeVar("RunsT")
ResultT = TypeVar("ResultT", bound="BenchmarkResult")


@dataclass(frozen=True)
class LegacyBenchmark(Generic[OptionsT, LoadedT, RunsT, ResultT]):
    """A benchmark declared as one record (the fields are the protocols' members; ``figures``
    and ``foxglove`` are ``module:function`` texts, ``state_topics`` stands for Audited,
    ``sample`` for Simulated, ``files`` for :meth:`Reported.input_files`, ``namespace`` for
    :attr:`Discovered.log_namespace`, default the name)."""

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
    rules: tuple[Rule, ...] = ()


def _function(target: str) -> Callable[..., Any]:
    module, _, name = target.partition(":")
    fn: Callable[..., Any] = getattr(import_module(module), name)
    return fn


class _Core(Benchmark[Any, Any, Any, Any]):
    """:class:`~ertools.benchmarks.base.Benchmark` of a record."""

    def __init__(self, legacy: LegacyBenchmark[Any, Any, Any, Any]) -> None:
        self.legacy = legacy
        self.name = legacy.name
        self.title = legacy.title
        self.inputs = legacy.inputs
        self.rules = legacy.rules

    def make_options(self, values: Mapping[str, Any]) -> Any:
        return self.legacy.make_options(values)

    def load(self, logs: Sequence[Path], options: Any) -> Any:
        return self.legacy.load(logs, options)

    def find_runs(self, loaded: Any, options: Any) -> Any:
        return self.legacy.find_runs(loaded, options)

    def score_runs(self, loaded: Any, runs: Any, options: Any) -> Any:
        return self.legacy.score_runs(loaded, runs, options)

    def input(self, name: str) -> Input:
        for declared in self.inputs:
            if declared.name == name:
                return declared
        raise KeyError(name)

    def __repr__(self) -> str:
        return f"<benchmark {self.name} (a LegacyBenchmark record)>"


class _Described(_Core, Described):
    def __init__(self, legacy: LegacyBenchmark[Any, Any, Any, Any]) -> None:
        super().__init__(legacy)
        self.example = legacy.example
        self.description = legacy.description
        self.epilog = legacy.epilog
        self.bags_help = legacy.bags_help
        self.bags_metavar = legacy.bags_metavar


class _Reported(_Core, Reported[Any, Any]):
    def __init__(self, legacy: LegacyBenchmark[Any, Any, Any, Any]) -> None:
        super().__init__(legacy)
        self.score_keys = legacy.score_keys
        self.draws = frozenset(p for p in ("figures", "foxglove") if getattr(legacy, p))

    def notes(self, result: Any) -> Sequence[str]:
        return () if self.legacy.notes is None else self.legacy.notes(result)

    def figures(self, result: Any) -> Sequence[Any]:
        if not self.legacy.figures:
            return []
        specs: Sequence[Any] = _function(self.legacy.figures)(result)
        return specs

    def foxglove(self, out: Any, result: Any, *, limit: int) -> None:
        if not self.legacy.foxglove:
            raise UsageError(f"--foxglove: no Foxglove export for {self.name} results")
        _function(self.legacy.foxglove)(out, result, limit=limit)

    def input_files(self, logs: Sequence[Path], options: Any, result: Any) -> list[Path]:
        files = self.legacy.files
        return list(logs) if files is None else list(files(logs, options, result))


class _Audited(_Core, Audited[Any]):
    def __init__(self, legacy: LegacyBenchmark[Any, Any, Any, Any]) -> None:
        super().__init__(legacy)
        self.values_2015 = legacy.values_2015
        self.explanations = legacy.explanations

    def from_live(self, options: Any, live: Any) -> tuple[Any, tuple[str, ...]]:
        if self.legacy.from_live is None:
            return options, ()
        return self.legacy.from_live(options, live)


class _Discovered(_Core, Discovered):
    def __init__(self, legacy: LegacyBenchmark[Any, Any, Any, Any]) -> None:
        super().__init__(legacy)
        self.ranking = legacy.ranking
        self.log_namespace = legacy.name if legacy.namespace is None else legacy.namespace
        self.logs_are_bags = legacy.logs_are_bags
        self.logs_may_be_text = legacy.logs_may_be_text
        self.source_inputs = legacy.source_inputs

    def gt_only(self, logs: Sequence[Path]) -> Mapping[str, Any] | str | None:
        return None if self.legacy.gt_only is None else self.legacy.gt_only(logs)


class _Simulated(_Core, Simulated):
    def sample_args(self, samples: Path) -> Sequence[str] | None:
        return None if self.legacy.sample is None else self.legacy.sample(samples)


@cache
def _shape(audited: bool, simulated: bool) -> type[_Core]:
    parts: list[type[_Core]] = [_Described, _Reported, _Discovered]
    parts += [_Audited] if audited else []
    parts += [_Simulated] if simulated else []
    name = "Legacy" + "".join(p.__name__.strip("_") for p in parts)
    return type(name, tuple(parts), {})


# By the record's id: the adapted object holds its record, so the id stays its own.
_ADAPTED: dict[int, AnyBenchmark] = {}


def adapt(legacy: LegacyBenchmark[Any, Any, Any, Any]) -> AnyBenchmark:
    """The record as a benchmark of the protocols (the same object for the same record)."""
    adapted = _ADAPTED.get(id(legacy))
    if adapted is None:
        shape = _shape(legacy.state_topics, legacy.sample is not None)
        adapted = _ADAPTED[id(legacy)] = shape(legacy)
    return adapted
