"""Every benchmark ertools scores, in one place: its name and where its :class:`Benchmark` is.

The CLI's ``score`` subcommands, ``report``, ``audit`` and ``rescore`` reach benchmarks only
through this table. Entries name the module that declares the benchmark (``module:ATTRIBUTE``),
imported on first use, so that ``ertools --help`` and a command that scores one benchmark
import only what they run. Adding a benchmark is one package and one line here.
"""

from __future__ import annotations

from importlib import import_module
from typing import TYPE_CHECKING, Any

from ertools.errors import UsageError

if TYPE_CHECKING:
    # an annotation only: `ertools --help` lists the names without importing NumPy
    from ertools.benchmarks.base import Benchmark

    AnyBenchmark = Benchmark[Any, Any, Any, Any]

REGISTRY: dict[str, str] = {
    "fbm1h": "ertools.benchmarks.fbm1.declare:FBM1H",
    "fbm1w": "ertools.benchmarks.fbm1.declare:FBM1W",
    "fbm2h": "ertools.benchmarks.fbm2h.declare:BENCHMARK",
    "fbm3w": "ertools.benchmarks.fbm3w.declare:BENCHMARK",
    "trajectory": "ertools.benchmarks.trajectory.declare:BENCHMARK",
    "hnf": "ertools.benchmarks.hnf.declare:BENCHMARK",
    "hpff": "ertools.benchmarks.hpff.declare:BENCHMARK",
    "hopf": "ertools.benchmarks.hopf.declare:BENCHMARK",
    "hppf": "ertools.benchmarks.hppf.declare:BENCHMARK",
    "hgmf": "ertools.benchmarks.hgmf.declare:BENCHMARK",
    "hgtkmh": "ertools.benchmarks.referee.declare:HGTKMH",
    "hwv": "ertools.benchmarks.referee.declare:HWV",
    "hcfgac": "ertools.benchmarks.referee.declare:HCFGAC",
    "stb": "ertools.benchmarks.referee.declare:STB",
}


def names() -> tuple[str, ...]:
    """The registered benchmark names, in the registry's order."""
    return tuple(REGISTRY)


def get(name: str) -> AnyBenchmark:
    """The benchmark called ``name``; an unknown name is a usage error listing the known ones."""
    try:
        target = REGISTRY[name]
    except KeyError:
        raise UsageError(f"unknown benchmark {name!r}: one of {', '.join(REGISTRY)}") from None
    module_name, _, attribute = target.partition(":")
    benchmark: AnyBenchmark = getattr(import_module(module_name), attribute)
    return benchmark


def for_result(result: Any) -> AnyBenchmark:
    """The benchmark a result belongs to (by its ``name``)."""
    return get(str(result.name))
