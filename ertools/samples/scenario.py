"""The scenario registry of the simulated sample logs.

A scenario is a function ``generate(outdir: Path, *, seed: int) -> list[Path]`` in its own
module. It writes one or more logs into ``outdir`` (which exists and is empty) with
:class:`ertools.simulator.writer.BagWriter`, the answers a correct scorer must find next to each
log, and any config YAML the scorer needs; it returns every path it wrote (files, or rosbag2
directories). ``python -m ertools.samples OUTDIR`` runs each registered scenario into
``OUTDIR/<name>/``.

Rules for scenario authors:

- Deterministic: every random draw from ``np.random.default_rng(seed)`` (or a child of it);
  no wall clock, no ``hash()`` of strings, no dict/set order that depends on the run. Use a
  fixed epoch start (e.g. :data:`ertools.simulator.answers.EPOCH_2015` + an offset): the
  logs look like 2015's.
- Small: each log <= ~2.5 MB, all of ``sample_bags/`` <= ~15 MB. One body at 120 Hz
  (PoseStamped + Pose2D + /tf) costs ~45 kB/s in an uncompressed ROS1 bag, so keep the
  mocap part under ~50 s per body (compress time: short manual operations, fast runs), and
  publish 120 Hz only for the bodies the benchmark needs.
- Independent: compute ``expected`` from the noiseless truth with the seed manual's formulas,
  written out in the scenario module; never import ``ertools.benchmarks``.
- Use :mod:`ertools.simulator.mocap` for what the mocap node published,
  :mod:`ertools.simulator.statemachine` for the state topics and
  :func:`ertools.simulator.answers.write_answers` for the answers file (its conventions are
  written there).
"""

from __future__ import annotations

import importlib
from pathlib import Path
from typing import Protocol

from ertools.benchmarks.fbm1.config import BENCHMARKS as FBM1
from ertools.benchmarks.fbm2h.config import NAMESPACE as FBM2H
from ertools.benchmarks.fbm3w.config import NAMESPACE as FBM3W
from ertools.errors import UsageError

SCENARIOS: dict[str, str] = {
    FBM3W: "ertools.benchmarks.fbm3w.sample:generate",
    FBM2H: "ertools.benchmarks.fbm2h.sample:generate",
    FBM1[0]: "ertools.benchmarks.fbm1.sample:generate",
    "robotlog": "ertools.benchmarks.trajectory.sample:generate",
    "stationary": "ertools.benchmarks.noise.sample:generate",
    "timeline": "ertools.samples.timeline_folder:generate",
    "hnf": "ertools.benchmarks.hnf.sample:generate",
    "hpff": "ertools.benchmarks.hpff.sample:generate",
    "hopf": "ertools.benchmarks.hopf.sample:generate",
    "hppf": "ertools.benchmarks.hppf.sample:generate",
    "hgmf": "ertools.benchmarks.hgmf.sample:generate",
    "season2019": "ertools.samples.season:generate",
}


class Generate(Protocol):
    """The signature every scenario's ``generate`` has."""

    def __call__(self, outdir: Path, *, seed: int) -> list[Path]: ...


class ScenarioMissingError(UsageError):
    """A registered scenario whose module (or function) does not exist yet."""


def load_scenario(name: str) -> Generate:
    """The ``generate`` function of a registered scenario.

    Raises:
        UsageError: unknown name.
        ScenarioMissingError: its module or function is not there.
    """
    if name not in SCENARIOS:
        raise UsageError(f"unknown scenario {name!r}; known: {', '.join(SCENARIOS)}")
    module_name, _, func = SCENARIOS[name].partition(":")
    try:
        module = importlib.import_module(module_name)
    except ModuleNotFoundError as exc:
        if exc.name != module_name:
            raise
        raise ScenarioMissingError(
            f"scenario {name!r}: module {module_name} does not exist (not written yet?)"
        ) from None
    fn = getattr(module, func, None)
    if fn is None:
        raise ScenarioMissingError(f"scenario {name!r}: {module_name} has no function {func}()")
    generate: Generate = fn
    return generate


def run_scenario(name: str, outdir: Path, *, seed: int) -> list[Path]:
    """Run one registered scenario into ``outdir`` (created) and return what it wrote."""
    generate = load_scenario(name)
    outdir.mkdir(parents=True, exist_ok=True)
    return generate(outdir, seed=seed)


# Per-scenario default seeds: fixed so `python -m ertools.samples` reproduces sample_bags/.
DEFAULT_SEEDS: dict[str, int] = {name: 2015 + i for i, name in enumerate(SCENARIOS)}
