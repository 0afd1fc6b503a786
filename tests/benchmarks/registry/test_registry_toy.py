"""A sixth benchmark takes one package and one registry line (issue 16).

The toy benchmark below lives in a package written to ``tmp_path`` (on ``sys.path``) and is
registered with one line; with no other change it gets ``ertools score toy``, ``ertools
report`` and ``ertools audit``. Its score is simple enough to compute by hand: ``count`` is
the number of marker poses times ``--scale``, ``mean_x`` their mean x.
"""

from __future__ import annotations

import json
import textwrap
from pathlib import Path

import numpy as np
import pytest

from ertools.benchmarks import registry
from ertools.cli.main import main
from ertools.simulator.statemachine import Transition, publish_states
from ertools.simulator.writer import BagWriter
from ertools.states import BmBoxState, Machine

T0 = 1_448_013_600 * 1_000_000_000
N_POSES = 40
X = np.linspace(0.0, 3.9, N_POSES)  # metres: mean 1.95

DECLARE = '''
"""A toy benchmark: counts the marker poses of /toy/marker."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ertools.benchmarks.base import (
    Audited,
    Benchmark,
    Described,
    Discovered,
    Input,
    Ranking,
    resolve_values,
)
from ertools.io.model import PoseSource
from ertools.io.reader import read_pose_source
from ertools.serialize import dump_yaml
from ertools.streams import Provenance

INPUTS = (
    Input("scale", "float", "multiplies the count", default=1.0, positive=True),
    Input("topic", "str", "marker pose topic", default="/toy/marker", metavar="TOPIC"),
)


@dataclass(frozen=True)
class ToyOptions:
    scale: float
    topic: str


@dataclass(frozen=True)
class ToyResult:
    count: float
    mean_x: float
    name: str = "toy"
    warnings: tuple[str, ...] = ()
    deviations: tuple[Any, ...] = ()
    failures: tuple[str, ...] = ()
    provenance: Provenance = field(default_factory=Provenance)

    def to_dict(self) -> dict[str, Any]:
        return {"count": self.count, "mean_x": self.mean_x}

    def to_yaml(self) -> str:
        return dump_yaml(self.to_dict())

    def tables(self) -> dict[str, list[dict[str, Any]]]:
        return {"score": [self.to_dict()]}


class Toy(Benchmark[ToyOptions, Any, None, ToyResult], Described, Audited[ToyOptions], Discovered):
    name = "toy"
    title = "Toy@Test"
    inputs = INPUTS
    rules = ()
    example = "ertools score toy run.bag"
    description = "Count the marker poses."
    epilog = "examples:\\n  ertools score toy run.bag --scale 2"
    values_2015 = {}
    explanations = ()
    ranking = Ranking(key=lambda r: r.count, lower_is_better=False, text="count: higher")
    log_namespace = "toy"

    def make_options(self, values):
        v = resolve_values(INPUTS, values)
        return ToyOptions(v["scale"], v["topic"])

    def load(self, logs, options):
        return read_pose_source([Path(b) for b in logs], PoseSource(topic=options.topic))

    def find_runs(self, loaded, options):
        return None

    def score_runs(self, loaded, runs, options):
        return ToyResult(
            count=len(loaded) * options.scale,
            mean_x=float(loaded.xyz[:, 0].mean()),
            provenance=Provenance(
                inputs=(loaded.source,), parameters=(("scale", str(options.scale)),)
            ),
        )


BENCHMARK = Toy()
'''


@pytest.fixture
def toy(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """The toy package on sys.path, its registry line, and a log: BmBox states sending the
    live score ``count: 40`` and 40 marker poses."""
    package = tmp_path / "pkg" / "toybench"
    package.mkdir(parents=True)
    (package / "__init__.py").write_text("", encoding="utf-8")
    (package / "declare.py").write_text(textwrap.dedent(DECLARE), encoding="utf-8")
    monkeypatch.syspath_prepend(str(tmp_path / "pkg"))
    line = registry.Entry("toy", "toybench.declare", "a toy benchmark")
    monkeypatch.setattr(registry, "ENTRIES", (*registry.ENTRIES, line))
    bag = tmp_path / "toy.bag"
    t = T0 + np.arange(N_POSES, dtype=np.int64) * 100_000_000
    with BagWriter(bag) as writer:
        xyz = np.column_stack([X, np.zeros(N_POSES), np.zeros(N_POSES)])
        quat = np.tile([0.0, 0.0, 0.0, 1.0], (N_POSES, 1))
        writer.write_pose_stamped("/toy/marker", t, t, "world", xyz, quat)
        publish_states(
            writer,
            "toy",
            [
                Transition(T0, Machine.BMBOX, BmBoxState.START),
                Transition(T0 + 100_000_000, Machine.BMBOX, BmBoxState.WAITING_CLIENT),
                Transition(T0 + 200_000_000, Machine.BMBOX, BmBoxState.READY),
                Transition(
                    T0 + 4_000_000_000,
                    Machine.BMBOX,
                    BmBoxState.TRANSMITTING_SCORE,
                    f"count: {N_POSES}\nmean_x: 1.95\n",
                ),
            ],
            end_ns=int(t[-1]) + 200_000_000,
            validate=False,
        )
    return bag


def test_score_takes_the_declared_inputs(toy: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["score", "toy", str(toy), "--scale", "2.5", "--format", "json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["count"] == pytest.approx(2.5 * N_POSES, abs=1e-12)
    assert data["mean_x"] == pytest.approx(1.95, abs=1e-9)  # mean of 0..3.9 m in 0.1 m steps
    assert main(["score", "toy", str(toy), "--scale", "0"]) == 2
    assert "--scale must be positive" in capsys.readouterr().err
    assert main(["score", "toy", "--help"]) == 0
    shown = capsys.readouterr().out
    assert "--scale" in shown and "--topic TOPIC" in shown and "Count the marker poses." in shown
    assert main(["score", "--help"]) == 0
    members = capsys.readouterr().out.split("members:")[1].split()
    assert members[-4:] == ["toy", "a", "toy", "benchmark"]  # its registry line, unimported


@pytest.mark.slow
def test_report_folder_and_combined_page(
    toy: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    folder = tmp_path / "r"
    assert main(["score", "toy", str(toy), "--report", str(folder)]) == 0
    score = json.loads((folder / "score.json").read_text(encoding="utf-8"))
    assert score["count"] == pytest.approx(N_POSES, abs=1e-12)
    meta = json.loads((folder / "result.json").read_text(encoding="utf-8"))
    assert meta["benchmark"] == "toy"
    assert [i["name"] for i in meta["inputs"]] == ["toy.bag"]
    combined = tmp_path / "all"
    assert main(["report", str(folder), "--out", str(combined)]) == 0
    page = (combined / "index.html").read_text(encoding="utf-8")
    assert "toy" in page and "toy.bag" in page


def test_audit_recomputes_and_compares(toy: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["audit", str(toy), "--format", "json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["benchmark"] == "toy"
    # The live score sent 40 poses; the recomputed one (scale 1) counts the 40 written.
    assert data["live_score"] == {"count": N_POSES, "mean_x": 1.95}
    assert data["recomputed"]["count"] == pytest.approx(N_POSES, abs=1e-12)
    comparison = data["score_comparison"]
    assert (comparison["same"], comparison["differences"]) == (2, 0), comparison
