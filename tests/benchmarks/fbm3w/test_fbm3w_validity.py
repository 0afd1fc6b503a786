"""FBM3W validity masks and the unscoreable verdict, on noiseless synthetic runs whose gaps are
cut by hand: the coverage, the spans and the verdict follow from where the frames were removed.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from ertools.benchmarks.base import rename_former
from ertools.benchmarks.fbm3w.config import Fbm3wOptions, options_2015
from ertools.benchmarks.fbm3w.declare import BENCHMARK
from ertools.benchmarks.fbm3w.formula import score_path
from ertools.benchmarks.fbm3w.pipeline import MAX_INNER_GAP_S, MIN_COVERAGE, score_paths
from ertools.benchmarks.fbm3w.runs import RunWindow
from ertools.benchmarks.fbm3w.settings import Fbm3wConfig
from ertools.benchmarks.fbm3w.shapes import builtin_shapes
from ertools.cli.main import main
from ertools.streams import PoseStream
from tests.benchmarks.fbm3w.fbm3w_synth import FRAME_NS, T0, one_run

STILL = 30
PATH = 3000  # 25 s at 120 Hz


def _run() -> tuple[PoseStream, RunWindow]:
    path = builtin_shapes()["line"](np.linspace(0.0, 1.0, PATH))
    return one_run(path, still=STILL)


def _cut(stream: PoseStream, cuts: list[tuple[int, int]]) -> PoseStream:
    """The stream without the frames [a, b) of each cut (counted from the path's start)."""
    keep = np.ones(len(stream), dtype=bool)
    for a, b in cuts:
        keep[2 * STILL + a : 2 * STILL + b] = False
    return stream.take(keep)


def _expected_score(stream: PoseStream, window: RunWindow) -> float:
    t = stream.t_ns
    sel = (t >= window.start_ns) & (t <= window.end_ns)
    ref = stream.xyz[int(np.searchsorted(t, window.ref_ns, side="right")) - 1, :2]
    shape = builtin_shapes()["line"]
    return score_path(stream.xyz[sel, :2], ref, shape, Fbm3wConfig().d_min).distance_error


@pytest.mark.slow
def test_a_clean_run_is_fully_covered() -> None:
    stream, window = _run()
    run = score_paths(stream, [window], Fbm3wConfig(), bag_start_ns=0).runs[0]
    assert run.status == "scored"
    # noiseless still phases repeat their pose: 29 + 1 at the start (the path's first point
    # repeats the start phase), 30 at the end; neither hides a motion
    d = run.details()
    assert d["invalid_samples"] == {"tracking_lost": 60}
    assert d["valid_fraction"] == round((PATH + 2 * STILL - 60) / (PATH + 2 * STILL), 6)
    assert d["path_coverage"] == 1.0
    assert "unscoreable_reason" not in d
    assert list(d)[:3] == ["spec", "distance_error", "execution_time"]  # Listing 16 first


def test_a_long_gap_mid_path_is_unscoreable() -> None:
    stream, window = _run()
    cut = _cut(stream, [(1000, 1072)])  # 72 frames: 73 frame periods without data
    result = score_paths(cut, [window], Fbm3wConfig(), bag_start_ns=T0)
    run = result.runs[0]
    span_s = 73 * FRAME_NS / 1e9
    assert span_s > MAX_INNER_GAP_S
    assert run.status == "unscoreable"
    assert run.distance_error is None
    assert result.best_run is None and result.best_distance_error is None
    assert run.unscoreable_reason is not None
    assert run.unscoreable_reason.startswith(
        f"{span_s:.2f} s without valid data in the middle of the path (gap"
    )
    d = run.details()
    assert d["status"] == "unscoreable" and d["unscoreable_reason"] == run.unscoreable_reason
    assert d["invalid_samples"] == {"tracking_lost": 60, "gap": 72}
    assert result.unscoreable_reason == f"no run can be scored: run 0: {run.unscoreable_reason}"
    assert not result.nothing_scored  # an unscoreable run is a verdict, not a failure
    assert any("[fbm3w.unscoreable-runs]" in d for d in result.deviations)
    (line,) = result.validity_lines()
    assert line.startswith("validity: run 0 ") and "1 gap 0.61 s" in line
    assert line.endswith(f"unscoreable: {run.unscoreable_reason}")
    # the gap where the path plot draws it: its ends are the samples either side, in the
    # run frame of frame_xy
    # the start and end phases' repeats (a still marker set, noiseless), and the cut
    still, gap, end = run.gaps
    assert [(g.reason, g.lost) for g in run.gaps] == [
        ("tracking_lost", False),
        ("gap", True),
        ("tracking_lost", False),
    ]
    assert end.end_xy is None and still.start_xy is not None
    sample = 2 * STILL + 999  # the last sample before the cut
    assert gap.start_s == pytest.approx(sample * FRAME_NS / 1e9)
    assert gap.end_s == pytest.approx((sample + 73) * FRAME_NS / 1e9)
    first = int(np.searchsorted(cut.t_ns, window.start_ns))
    assert gap.start_xy == pytest.approx(tuple(run.frame_xy[sample - first]))
    assert gap.end_xy == pytest.approx(tuple(run.frame_xy[sample - first + 1]))
    spans = result.tables()["invalid_spans"]
    assert [(r["run"], r["reason"]) for r in spans] == [
        (0, "tracking_lost"),
        (0, "gap"),
        (0, "tracking_lost"),
    ]


@pytest.mark.slow
def test_2015_scores_it_with_a_warning() -> None:
    stream, window = _run()
    cut = _cut(stream, [(1000, 1072)])
    options = options_2015(Fbm3wOptions())
    assert options.unscoreable_runs == "2015"
    result = score_paths(cut, [window], Fbm3wConfig(), options=options, bag_start_ns=0)
    run = result.runs[0]
    assert run.status == "scored"
    assert run.distance_error == _expected_score(cut, window)
    assert run.unscoreable_reason is not None  # kept, said in the warning and the details
    covered = run.path_coverage
    assert covered == pytest.approx(1 - 73 / (PATH + 2 * STILL - 1), abs=1e-12)
    assert any(
        w.startswith(f"run 0: 2015 scored this run from {covered:.1%} of its path")
        for w in result.warnings
    )
    assert not any("unscoreable-runs" in d for d in result.deviations)


def test_both_spellings_score_it_alike(capsys: pytest.CaptureFixture[str]) -> None:
    """``--unscoreable 2015`` and the former ``--unscoreable-runs 2015`` give the options that
    score the gapped run from its path (the default leaves it unscoreable)."""
    stream, window = _run()
    cut = _cut(stream, [(1000, 1072)])

    def run(**given: str) -> Any:
        options = BENCHMARK.make_options(rename_former(BENCHMARK.inputs, given))
        return score_paths(cut, [window], Fbm3wConfig(), options=options, bag_start_ns=0).runs[0]

    assert run().status == "unscoreable"
    new = run(unscoreable="2015")
    assert capsys.readouterr().err == ""
    old = run(unscoreable_runs="2015")
    assert capsys.readouterr().err == (
        "ertools: note: unscoreable_runs='2015' is deprecated, use unscoreable='2015'\n"
    )
    assert new.status == old.status == "scored"
    assert new.distance_error == old.distance_error == _expected_score(cut, window)


@pytest.mark.slow
def test_coverage_below_the_fraction_is_unscoreable() -> None:
    stream, window = _run()
    # 8 gaps of 0.45 s (54 frames, 55 periods each), each under MAX_INNER_GAP_S: 440 of
    # 3059 periods lost, 85.6% covered
    cuts = [(200 + 300 * k, 254 + 300 * k) for k in range(8)]
    result = score_paths(_cut(stream, cuts), [window], Fbm3wConfig(), bag_start_ns=0)
    run = result.runs[0]
    covered = 1 - 8 * 55 / (PATH + 2 * STILL - 1)
    assert covered < MIN_COVERAGE
    assert run.path_coverage == pytest.approx(covered, abs=1e-12)
    assert run.status == "unscoreable"
    assert run.unscoreable_reason is not None
    assert run.unscoreable_reason.startswith(f"valid data covers only {covered:.1%} of the window")
    # 4 such gaps leave 92.7%: scored, and with the same number as without the mask
    four = _cut(stream, cuts[:4])
    ok = score_paths(four, [window], Fbm3wConfig(), bag_start_ns=0).runs[0]
    assert ok.status == "scored"
    assert ok.distance_error == _expected_score(four, window)


def test_a_tracking_loss_while_moving_is_lost_path() -> None:
    stream, window = _run()
    xyz = stream.xyz.copy()
    a = 2 * STILL + 1500
    xyz[a : a + 72] = xyz[a - 1]  # Motive repeats the last pose for 0.6 s while the robot moves
    frozen = PoseStream(stream.t_ns, xyz, stream.quat_xyzw, "world", "robot_at_work", "synthetic")
    run = score_paths(frozen, [window], Fbm3wConfig(), bag_start_ns=0).runs[0]
    assert run.status == "unscoreable"
    assert run.unscoreable_reason is not None
    assert "(tracking_lost," in run.unscoreable_reason
    assert run.details()["invalid_samples"] == {"tracking_lost": 132}


SAMPLE = Path(__file__).resolve().parents[3] / "sample_bags" / "fbm3w"


@pytest.mark.slow
def test_the_score_command_prints_validity(capsys: pytest.CaptureFixture[str]) -> None:
    bag = SAMPLE / "log_fbm3w_mocap_2015-11-20-12-00-00_0.bag"
    config = SAMPLE / "fbm3w.yaml"
    args = ["score", "fbm3w", str(bag), "--config", str(config), "--format", "json"]
    assert main(args) == 0
    out, err = capsys.readouterr()
    data = json.loads(out)
    lines = [line for line in err.splitlines() if line.startswith("ertools: validity: ")]
    scored = [k for k, r in data["runs_details"].items() if r["status"] == "scored"]
    assert len(lines) == len(scored)
    for line, k in zip(lines, scored, strict=True):
        r = data["runs_details"][k]
        assert line.startswith(f"ertools: validity: run {k} {r['valid_fraction']:.1%} valid")
    # the sample's runs are covered: --unscoreable-runs 2015 changes nothing
    assert main([*args, "--unscoreable", "2015"]) == 0
    assert json.loads(capsys.readouterr().out) == data
