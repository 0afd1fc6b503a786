"""A toy benchmark registered only by the rescore tests: `ertools rescore` must score it with no
change to ertools/competition (adding a benchmark adds it to rescore).

A toy "log" is a text file of numbers, one per line. The score of an execution is
``mean(numbers) * scale + offset`` (``mode: max``: the largest number instead of the mean), the
offset read from the team's per-team input (a YAML file ``{offset: X}``, like a marker-set
transform). Words in a log make the scorer misbehave on purpose: ``bad`` (an unscoreable log:
ScoringError), ``boom`` (a bug: RuntimeError), ``die`` (the worker process dies); ``sleep``
waits a second; ``moment`` looks for a file ``LOG.absent`` and goes on without it (a scorer
skipping a file it could not find at that moment); ``warn`` logs a warning naming the log;
``replace`` replaces the log by a file of other numbers while it is scored (the numbers
already read are scored); ``hold`` writes the scoring process's pid beside the log
(``LOG.pid``) and waits for ever: a kill point the fault tests choose by waiting for that
file; ``locked`` takes :data:`LOCK` (a scorer forked while another thread of its parent held
it would wait for ever).
"""

from __future__ import annotations

import contextlib
import logging
import os
import threading
import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import yaml

from ertools.benchmarks.base import Benchmark, Described, Discovered, Input, Ranking, Rows
from ertools.errors import BagError, ConfigError, ScoringError, UsageError
from ertools.fidelity import Deviation
from ertools.io.formats import detect_format
from ertools.streams import Provenance

LOCK = threading.Lock()


@dataclass(frozen=True)
class ToyOptions:
    transform: Path | None
    scale: float
    mode: str


@dataclass(frozen=True)
class ToyResult:
    name: str
    value: float
    count: int
    offset: float
    warnings: tuple[str, ...] = ()
    deviations: tuple[Deviation, ...] = ()
    failures: tuple[str, ...] = ()
    provenance: Provenance = field(default_factory=Provenance)

    def to_dict(self) -> dict[str, Any]:
        return {"toy": {"value": self.value, "count": self.count, "offset": self.offset}}

    def to_yaml(self) -> str:
        return f"toy:\n  value: {self.value}\n"

    def tables(self) -> dict[str, Rows]:
        return {"values": [{"value": self.value}]}


def make_options(values: Mapping[str, Any]) -> ToyOptions:
    scale = float(values.get("scale", 1.0))
    if scale <= 0:
        raise UsageError(f"--scale {scale}: must be > 0")
    transform = values.get("transform")
    return ToyOptions(
        transform=None if transform is None else Path(transform),
        scale=scale,
        mode=str(values.get("mode", "mean")),
    )


def load(bags: Sequence[Path], options: ToyOptions) -> list[float]:
    numbers: list[float] = []
    for bag in bags:
        for line in Path(bag).read_text(encoding="utf-8").split():
            if line == "bad":
                raise ScoringError("no toy values can be scored here", path=bag)
            if line == "boom":
                raise RuntimeError("the toy scorer has a bug")
            if line == "die":
                os._exit(7)
            if line == "hold":
                Path(f"{bag}.pid").write_text(f"{os.getpid()}\n")
                threading.Event().wait()
            if line == "locked":
                with LOCK:
                    continue
            if line == "warn":
                logging.getLogger("ertools.toy").warning("toy warning from %s", Path(bag).name)
                continue
            if line == "moment":
                with contextlib.suppress(BagError):
                    detect_format(Path(f"{bag}.absent"))
                continue
            if line == "replace":
                new = Path(f"{bag}.new")
                new.write_text("100\n")
                new.replace(bag)
                continue
            if line == "sleep":  # long enough for a progress bar to show
                time.sleep(1.0)
                continue
            numbers.append(float(line))
    return numbers


def find_runs(loaded: list[float], options: ToyOptions) -> list[float]:
    return loaded


def score_runs(loaded: list[float], runs: list[float], options: ToyOptions) -> ToyResult:
    offset = 0.0
    if options.transform is not None:
        data = yaml.safe_load(options.transform.read_text(encoding="utf-8"))
        if not isinstance(data, dict) or "offset" not in data:
            raise ConfigError("expected {offset: X}", path=options.transform)
        offset = float(data["offset"])
    base = max(runs) if options.mode == "max" else sum(runs) / len(runs)
    return ToyResult("toy", base * options.scale + offset, len(runs), offset)


class Toy(Benchmark[ToyOptions, list[float], list[float], ToyResult], Described, Discovered):
    """Registered as ``tests.rescore.rescore_toy:TOY`` (``rescore_toy:TOY`` by the scripts run
    from its folder)."""

    name = "toy"
    title = "Toy@Test"
    rules = ()
    example = "ertools score toy log.txt"
    description = "mean of the numbers times scale plus the team's offset"
    epilog = ""
    bags_help = "text files of numbers"
    logs_are_bags = False
    log_namespace = "toy"
    inputs = (
        Input("transform", "path", "the team's offset file", per_team=True),
        Input("scale", "float", "a factor", default=1.0, positive=True),
        Input("mode", "choice", "mean or max", default="mean", choices=("mean", "max")),
    )
    ranking = Ranking(key=lambda r: r.value, lower_is_better=True, text="the lowest value wins")

    def make_options(self, values: Mapping[str, Any]) -> ToyOptions:
        return make_options(values)

    def load(self, logs: Sequence[Path], options: ToyOptions) -> list[float]:
        return load(logs, options)

    def find_runs(self, loaded: list[float], options: ToyOptions) -> list[float]:
        return find_runs(loaded, options)

    def score_runs(self, loaded: list[float], runs: list[float], options: ToyOptions) -> ToyResult:
        return score_runs(loaded, runs, options)


TOY = Toy()
