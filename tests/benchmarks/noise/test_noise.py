"""``ertools noise`` and the noise statistics, against the stationary sample's known noise."""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml

from ertools.benchmarks.common.epsilon import noise_from_stream, noise_statistics
from ertools.benchmarks.fbm3w import sample as fbm3w
from ertools.benchmarks.noise.sample import generate
from ertools.cli.main import main
from ertools.errors import ScoringError
from ertools.streams import PoseStream

pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def stationary(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, dict[str, Any]]:
    bag, answers = generate(tmp_path_factory.mktemp("stationary"), seed=2019)
    return bag, yaml.safe_load(answers.read_text())


@pytest.fixture(scope="module")
def fbm3w_bag(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, dict[str, Any]]:
    bag, _, _, answers = fbm3w.generate(tmp_path_factory.mktemp("fbm3w_for_noise"), seed=2015)
    return bag, yaml.safe_load(answers.read_text())


def test_hand_case() -> None:
    xy = np.array([[0.0, 0.0], [0.001, 0.0], [0.001, 0.0], [0.001, 0.0003]])
    t = np.arange(4, dtype=np.int64) * 8_333_333
    r = noise_statistics(t, xy)
    # steps 1 mm, 0 (a repeat: lost), 0.3 mm
    assert (r.samples, r.pairs, r.lost) == (4, 3, 1)
    assert r.epsilon == pytest.approx(0.00065, abs=1e-15)
    assert r.suggested_d_min == pytest.approx(0.00195, abs=1e-15)
    _, counts, overflow = r.histogram()
    # 0.3 mm is bin 2 of 0.15 mm; 1 mm is bin 6
    assert counts[2] == 1 and counts[6] == 1 and counts.sum() == 2 and overflow == 0


def test_json_against_the_stationary_sample(
    stationary: tuple[Path, dict[str, Any]], capsys: pytest.CaptureFixture[str]
) -> None:
    bag, answers = stationary
    exp = answers["expected"]
    assert main(["noise", str(bag), "--format", "json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert list(data) == ["samples", "lost", "epsilon", "percentiles", "suggested_d_min"]
    assert list(data["percentiles"]) == ["50", "95", "99"]
    assert data["samples"] == exp["samples"]
    assert data["lost"] == exp["lost"]
    # same samples as the simulation: only summation order differs
    assert data["epsilon"] == pytest.approx(exp["epsilon_xy"], abs=1e-12)
    assert data["epsilon"] == pytest.approx(
        exp["epsilon_xy_formula"], abs=answers["tolerance"]["epsilon_xy_formula"]["abs"]
    )
    assert data["suggested_d_min"] == pytest.approx(3 * exp["epsilon_xy"], abs=1e-12)
    # percentiles of the Rayleigh distribution of |d| (per-axis sd s = sigma*sqrt(2)):
    # x_q = s*sqrt(-2 ln(1-q)); standard error of a sample quantile sqrt(q(1-q)/n)/pdf(x_q),
    # 6 of them as consecutive differences are correlated
    s = answers["generator"]["parameters"]["sigma_m"] * math.sqrt(2)
    n = exp["moving_pairs"]
    for key, q in (("50", 0.5), ("95", 0.95), ("99", 0.99)):
        x = s * math.sqrt(-2 * math.log(1 - q))
        pdf = x / s**2 * math.exp(-(x**2) / (2 * s**2))
        assert data["percentiles"][key] == pytest.approx(
            x, abs=6 * math.sqrt(q * (1 - q) / n) / pdf
        )


def test_text_histogram_and_plot(
    stationary: tuple[Path, dict[str, Any]], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    bag, answers = stationary
    png = tmp_path / "noise.png"
    assert main(["noise", str(bag), "--plot", str(png), "--c", "4"]) == 0
    text = capsys.readouterr().out
    assert png.stat().st_size > 1000
    assert "suggested d_min = 4 * epsilon" in text
    rows = [ln for ln in text.splitlines() if " mm | " in ln]
    counts = [int(ln.split()[-2]) for ln in rows]
    # every differing pair falls in one bin of 0.15 mm (bins 0.00, 0.15, 0.30 ... mm)
    assert sum(counts) == answers["expected"]["moving_pairs"]
    assert rows[1].lstrip().startswith("0.15 mm")
    lost = next(ln for ln in text.splitlines() if ln.lstrip().startswith("lost"))
    assert int(lost.split()[-2]) == answers["expected"]["lost"]


def test_stationary_auto_on_a_benchmark_bag(
    fbm3w_bag: tuple[Path, dict[str, Any]], capsys: pytest.CaptureFixture[str]
) -> None:
    bag, answers = fbm3w_bag
    assert main(["noise", str(bag), "--stationary", "auto", "--format", "json"]) == 0
    data = json.loads(capsys.readouterr().out)
    noise = answers["expected"]["noise"]
    tol = answers["tolerance"]["noise.epsilon"]["abs"]
    assert data["epsilon"] == pytest.approx(noise["epsilon"], abs=tol)
    # the whole bag (robot moving) would be far off: the motion dominates the steps
    assert main(["noise", str(bag), "--format", "json"]) == 0
    captured = capsys.readouterr()
    whole = json.loads(captured.out)
    assert whole["epsilon"] > 2 * noise["epsilon"]
    assert "use --stationary auto" in captured.err


def test_bad_inputs(
    stationary: tuple[Path, dict[str, Any]], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    bag, _ = stationary
    assert main(["noise", str(bag), "--bin", "0"]) == 2  # a usage error, refused by the parser
    err = capsys.readouterr().err
    assert "--bin" in err and "Traceback" not in err
    assert main(["noise", str(bag), "--topic", "/nope"]) == 1
    assert "/nope" in capsys.readouterr().err
    assert main(["noise", str(tmp_path / "missing.bag")]) == 1
    assert "ertools: error:" in capsys.readouterr().err


def test_all_nan_stream_is_named() -> None:
    n = 5
    nan = np.full((n, 3), np.nan)
    quat = np.tile([0.0, 0.0, 0.0, 1.0], (n, 1))
    poses = PoseStream(
        t_ns=np.arange(n, dtype=np.int64) * 10_000_000,
        xyz=nan,
        quat_xyzw=quat,
        source="lost.bag:/fbm3w/robot_at_work/pose",
    )
    with pytest.raises(ScoringError) as err:
        noise_from_stream(poses)
    msg = str(err.value)
    assert "lost.bag:/fbm3w/robot_at_work/pose" in msg and f"all {n} poses are NaN" in msg
    assert "\n" not in msg
