"""A benchmark declared with the old record (``LegacyBenchmark``) still scores through the
protocols: the registry adapts it (issue 37; the RSBB benchmarks of issue 38 come this way
until they are converted). The record's stages are plain functions here, so the numbers are
the test's own: the count of the values given times ``scale``."""

from __future__ import annotations

import sys
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pytest

from ertools.benchmarks import registry
from ertools.benchmarks.base import (
    Audited,
    Benchmark,
    Described,
    Discovered,
    Input,
    Ranking,
    Reported,
    Simulated,
    resolve_values,
)
from ertools.benchmarks.legacy import LegacyBenchmark, adapt
from ertools.benchmarks.scoring import score_execution

INPUTS = (Input("scale", "float", "multiplies the count", default=1.0, positive=True),)


@dataclass(frozen=True)
class Counted:
    count: float


def _options(values: Any) -> float:
    return float(resolve_values(INPUTS, values)["scale"])


def _load(logs: Sequence[Path], scale: float) -> list[str]:
    return [p.name for p in logs]


def _runs(loaded: list[str], scale: float) -> int:
    return len(loaded)


def _score(loaded: list[str], runs: int, scale: float) -> Counted:
    return Counted(runs * scale)


def record(**more: Any) -> LegacyBenchmark[Any, Any, Any, Any]:
    return LegacyBenchmark(
        name="counter",
        title="Counter",
        summary="counts its logs",
        example="ertools score counter a.bag",
        description="counts its logs",
        epilog="",
        inputs=INPUTS,
        make_options=_options,
        load=_load,
        find_runs=_runs,
        score_runs=_score,
        ranking=Ranking(key=lambda r: r.count, lower_is_better=False, text="count"),
        **more,
    )


def test_a_record_scores_through_the_one_scoring_path() -> None:
    bench = adapt(record())
    logs = [Path("a.bag"), Path("b.bag"), Path("c.bag")]
    scored = score_execution(bench, logs, {"scale": 2.5}, check_logs=False)
    assert scored.result == Counted(7.5)  # 3 logs x 2.5
    assert scored.options == 2.5
    assert bench.input("scale").default == 1.0


def test_the_adapted_record_implements_exactly_the_parts_it_fills() -> None:
    plain = adapt(record())
    assert isinstance(plain, Benchmark)
    assert all(isinstance(plain, p) for p in (Described, Reported, Discovered))
    assert not isinstance(plain, Audited) and not isinstance(plain, Simulated)
    assert plain.log_namespace == "counter"  # type: ignore[attr-defined]
    full = adapt(record(state_topics=True, sample=lambda samples: [str(samples / "c.bag")]))
    assert isinstance(full, Audited) and isinstance(full, Simulated)
    assert full.sample_args(Path("s")) == [str(Path("s") / "c.bag")]  # type: ignore[attr-defined]


def test_the_registry_adapts_a_record_it_loads(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(sys.modules[__name__], "RECORD", record(), raising=False)
    found = registry.load(f"{__name__}:RECORD")
    assert isinstance(found, Benchmark) and found.name == "counter"
    assert found is registry.load(f"{__name__}:RECORD")  # the same object for the same record
