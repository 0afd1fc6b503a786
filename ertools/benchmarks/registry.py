"""Every benchmark ertools scores, in one place: one line each, naming the module that declares
it, so that ``ertools score --help`` lists them all without importing any, and a command that
scores one benchmark imports only that one's declaration.

An entry's ``target`` is a module (``.fbm3w.declare``: relative to ``ertools.benchmarks``; a
plug-in outside ertools gives an absolute name) and optionally ``:ATTRIBUTE`` (default
``BENCHMARK``): the object implementing :class:`~ertools.benchmarks.base.Benchmark`. Adding a
benchmark is one package and one line here. ``python -m ertools.benchmarks.registry`` prints
each entry with the file that declares it (what go-to-definition cannot follow).
"""

from __future__ import annotations

import sys
from importlib import import_module
from importlib.util import find_spec
from pathlib import Path
from types import ModuleType
from typing import TYPE_CHECKING, Any

from ertools.benchmarks.base import Generate, LiveText, SeasonItems, Simulated
from ertools.errors import UsageError
from ertools.frozen_dataclass import frozen_dataclass

if TYPE_CHECKING:
    from ertools.benchmarks.base import AnyBenchmark

PACKAGE = "ertools.benchmarks"


@frozen_dataclass
class Entry:
    """One registered benchmark: its name, where it is declared, one line of help."""

    name: str
    target: str
    summary: str

    @property
    def absolute(self) -> str:
        """``module:ATTRIBUTE`` with the module's absolute name (what a rescore job carries)."""
        module, _, attribute = self.target.partition(":")
        if module.startswith("."):
            module = PACKAGE + module
        return f"{module}:{attribute or 'BENCHMARK'}"


ENTRIES: tuple[Entry, ...] = (
    Entry("fbm1h", ".fbm1.declare:FBM1H", "FBM1@Home object perception"),
    Entry("fbm1w", ".fbm1.declare:FBM1W", "FBM1@Work object perception"),
    Entry("fbm2h", ".fbm2h.declare", "FBM2@Home navigation: waypoint errors"),
    Entry("fbm3w", ".fbm3w.declare", "FBM3@Work trajectory following: path error"),
    Entry("trajectory", ".trajectory.declare", "robot log vs mocap ground truth, with clock audit"),
    Entry("noise", ".noise.declare", "mocap noise of a stationary marker set, suggested d_min"),
    Entry("hnf", ".hnf.declare", "HNF (FBM2@Home 2017-19) navigation: the RSBB script re-scored"),
    Entry("hpff", ".hpff.declare", "HPFF (FBM5@Home 2019) person following: the RSBB script"),
    Entry("hopf", ".hopf.declare", "HOPF object perception (RSBB 2017-19): 10 items"),
    Entry("hppf", ".hppf.declare", "HPPF people perception (RSBB 2019): who each person is"),
    Entry("hgmf", ".hgmf.declare", "HGMF (FBM6@Home 2019) grasping and manipulation"),
    Entry("hgtkmh", ".referee.declare:HGTKMH", "HGTKMH: the referee's items, ERL-ranked"),
    Entry("hwv", ".referee.declare:HWV", "HWV: the referee's items, ERL-ranked"),
    Entry("hcfgac", ".referee.declare:HCFGAC", "HCFGAC: the referee's items, ERL-ranked"),
    Entry("stb", ".referee.declare:STB", "STB: the referee's items, ERL-ranked"),
)


def names() -> tuple[str, ...]:
    """The registered benchmark names, in the registry's order."""
    return tuple(e.name for e in ENTRIES)


def entry(name: str) -> Entry:
    """The entry called ``name``; an unknown name is a usage error listing the known ones."""
    for e in ENTRIES:
        if e.name == name:
            return e
    raise UsageError(f"unknown benchmark {name!r}: one of {', '.join(names())}")


def target(name: str) -> str:
    """The absolute ``module:ATTRIBUTE`` of the benchmark called ``name``."""
    return entry(name).absolute


def load(target: str) -> AnyBenchmark:
    """The benchmark an absolute ``module:ATTRIBUTE`` names (a rescore job's), imported now."""
    module, _, attribute = target.partition(":")
    benchmark: AnyBenchmark = getattr(import_module(module), attribute or "BENCHMARK")
    return benchmark


def get(name: str) -> AnyBenchmark:
    """The benchmark called ``name``; an unknown name is a usage error listing the known ones."""
    return load(target(name))


def for_result(result: Any) -> AnyBenchmark:
    """The benchmark a result belongs to (by its ``name``)."""
    return get(str(result.name))


def warm(target: str, *, report: bool = False) -> None:
    """Import now what scoring with the benchmark ``target`` names would import on first use:
    its declaration, the ``pipeline`` beside it and, for a report, its ``plots`` and
    ``foxglove`` (a rescore's server, before it forks its scorers: they inherit them)."""
    module = target.partition(":")[0]
    import_module(module)
    package = module.rpartition(".")[0]
    wanted = [f"{package}.pipeline"]
    if report:
        wanted += [f"{package}.plots", f"{package}.foxglove"]
    for name in wanted:
        if find_spec(name) is not None:
            import_module(name)


@frozen_dataclass
class Scenario:
    """A benchmark package's simulated scenario: the ``sample`` module beside its declaration
    (``module``, absolute), the folder of ``sample_bags/`` it writes and the benchmark's
    ``sample_seed`` (0: none declared)."""

    folder: str
    module: str
    seed: int = 0

    def load(self) -> ModuleType:
        """The sample module, imported now (for a sample built from a benchmark's runs)."""
        return import_module(self.module)

    def generate(self, outdir: Path, *, seed: int) -> list[Path]:
        """Its :class:`~ertools.benchmarks.base.Generate`: the logs written into ``outdir``."""
        generate: Generate = self.load().generate
        return generate(outdir, seed=seed)


def scenarios() -> tuple[Scenario, ...]:
    """The scenario of every benchmark package with a ``sample`` module, once per package (the
    first entry's: fbm1h for fbm1), in the registry's order; the folder is the benchmark's
    ``sample_folder`` (and seed ``sample_seed``) when
    :class:`~ertools.benchmarks.base.Simulated`, else its name. Imports
    the declarations (light), not the simulators."""
    found: dict[str, Scenario] = {}
    for e in ENTRIES:
        package = e.absolute.partition(":")[0].rpartition(".")[0]
        if package in found or find_spec(f"{package}.sample") is None:
            continue
        bench = get(e.name)
        if isinstance(bench, Simulated) and bench.sample_part:
            continue
        folder, seed = (
            (bench.sample_folder, bench.sample_seed) if isinstance(bench, Simulated) else ("", 0)
        )
        found[package] = Scenario(folder or e.name, f"{package}.sample", seed)
    return tuple(found.values())


def sample_parts() -> tuple[ModuleType, ...]:
    """The ``sample`` modules of the packages whose benchmarks declare ``sample_part`` (once
    per package, in the registry's order), imported now: a scenario composes them."""
    found: dict[str, ModuleType] = {}
    for e in ENTRIES:
        package = e.absolute.partition(":")[0].rpartition(".")[0]
        bench = get(e.name)
        if package not in found and isinstance(bench, Simulated) and bench.sample_part:
            found[package] = import_module(f"{package}.sample")
    return tuple(found.values())


def season_items() -> frozenset[str]:
    """The RSBB codes (the names in capitals) whose runs take the season's items file: the
    benchmarks that are :class:`~ertools.benchmarks.base.SeasonItems`."""
    return frozenset(
        e.name.upper()
        for e in ENTRIES
        if isinstance(bench := get(e.name), SeasonItems) and bench.season_items
    )


def live_numbers(value: str) -> tuple[tuple[str, float], ...] | None:
    """The numbers of a live score's value some benchmark logs as text
    (:class:`~ertools.benchmarks.base.LiveText`), with their quantities' keys; None: no
    benchmark's."""
    for e in ENTRIES:
        bench = get(e.name)
        if isinstance(bench, LiveText) and (found := bench.live_numbers(value)) is not None:
            return found
    return None


def package_module(name: str, module: str) -> ModuleType | None:
    """The module ``module`` (``rules``...) of the package declaring the benchmark ``name``,
    imported now; None when that package has none."""
    package = entry(name).absolute.partition(":")[0].rpartition(".")[0]
    wanted = f"{package}.{module}"
    return import_module(wanted) if find_spec(wanted) is not None else None


def main() -> int:
    """Each entry: name, summary, the file that declares it."""
    for e in ENTRIES:
        module = import_module(e.absolute.partition(":")[0])
        print(f"{e.name:<12} {e.summary}\n{'':<12} {module.__file__}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
