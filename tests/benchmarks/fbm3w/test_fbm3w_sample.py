"""The simulated FBM3@Work benchmark scored in the three run-finding modes vs its answers."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

from ertools.benchmarks import registry
from ertools.benchmarks.scoring import score_execution
from tests.benchmarks.fbm3w.fbm3w_kit import Sample


def _score(bag: Path, **values: Any) -> Any:
    """``ertools score fbm3w BAG`` with these inputs; the answers hold scores, not intervals:
    no Monte Carlo draws."""
    return score_execution(registry.get("fbm3w"), [bag], {"draws": 0, **values}).result


def _runs(windows: tuple[tuple[str, float, float, float], ...]) -> list[str]:
    """Windows as ``--run SPEC:REF_T:START_T:END_T`` texts (repr: the floats read back exactly)."""
    return [f"{spec}:{ref!r}:{start!r}:{end!r}" for spec, ref, start, end in windows]


def _tol(sample: Sample, key: str) -> float:
    return float(sample.answers["tolerance"][key]["abs"])


@pytest.mark.slow_cases("states")
@pytest.mark.parametrize("mode", ["states", "windows", "auto"])
def test_each_run_matches_the_answers(fbm3w_sample: Sample, mode: str) -> None:
    windows = fbm3w_sample.windows() if mode == "windows" else ()
    result = _score(fbm3w_sample.bag, runs=mode, run=_runs(windows))
    # the answers file justifies it: single noisy reference/start samples fix the run frame
    tol = _tol(fbm3w_sample, "distance_error")
    scored = [r for r in result.runs if r.distance_error is not None]
    assert [r.index for r in scored] == [0, 1, 2, 3]
    for run in scored:
        exp = fbm3w_sample.expected_run(run.index)
        assert run.spec == exp["spec"]
        assert run.distance_error == pytest.approx(exp["distance_error"], abs=tol), run.index
    assert result.failures == ()
    assert result.best_run == fbm3w_sample.answers["expected"]["best_run"]


def test_states_mode_equals_the_live_node(fbm3w_sample: Sample) -> None:
    """The scenario recomputes what the 2015 node saw (the published Pose2D messages)."""
    result = _score(fbm3w_sample.bag)
    live = fbm3w_sample.answers["expected"]["published"]
    tol = _tol(fbm3w_sample, "published")
    for run in result.runs[:4]:
        exp = live["runs_details"][str(run.index)]
        assert run.distance_error == pytest.approx(exp["distance_error"], abs=tol)
        assert run.score is not None
        assert len(run.score.kept) == exp["kept_samples"]
        assert run.score.path_length == pytest.approx(exp["path_length"], abs=tol)
    assert result.best_run == live["best_run"]
    assert result.best_distance_error == pytest.approx(live["best_distance_error"], abs=tol)


def test_states_mode_times_and_timeout(fbm3w_sample: Sample) -> None:
    result = _score(fbm3w_sample.bag)
    assert len(result.runs) == 5
    assert all(r.window.mode == "states" for r in result.runs)
    tol = _tol(fbm3w_sample, "execution_time")
    for run in result.runs:
        exp = fbm3w_sample.expected_run(run.index)
        assert run.execution_time == pytest.approx(exp["execution_time"], abs=tol)
    timed_out = result.runs[4]
    assert timed_out.status == "timeout"
    assert timed_out.distance_error is None
    assert result.execution_time == pytest.approx(
        fbm3w_sample.answers["expected"]["execution_time"], abs=5 * tol
    )
    losses = fbm3w_sample.answers["expected"]["tracking_losses"]
    assert {str(r.index): r.tracking_losses for r in result.runs if r.tracking_losses} == losses
    # sigma = 0.05 mm: 3 * epsilon = 0.27 mm is below the 2015 d_min, so no noise warning
    assert not any("below the mocap noise" in w for w in result.warnings)
    assert result.noise is not None
    assert result.noise.epsilon == pytest.approx(
        fbm3w_sample.answers["expected"]["noise"]["epsilon"],
        abs=_tol(fbm3w_sample, "noise.epsilon"),
    )


@pytest.mark.slow
def test_rosbag2_mcap_copy_scores_the_same(fbm3w_sample: Sample) -> None:
    ros1 = _score(fbm3w_sample.bag)
    mcap = _score(fbm3w_sample.mcap)
    # same messages in another container: identical numbers
    assert mcap.to_dict() == ros1.to_dict()


@pytest.mark.slow_cases("auto", "states")
@pytest.mark.parametrize("mode", ["states", "windows", "auto"])
def test_noiseless_recording_gives_the_answers_exactly(fbm3w_noiseless: Sample, mode: str) -> None:
    windows = fbm3w_noiseless.windows() if mode == "windows" else ()
    result = _score(fbm3w_noiseless.bag, runs=mode, run=_runs(windows))
    tol = _tol(fbm3w_noiseless, "distance_error_noiseless")
    for run in result.runs[:4]:
        exp = fbm3w_noiseless.expected_run(run.index)
        assert run.distance_error is not None
        # runs without the tracking loss: same samples, same formula, only float rounding
        limit = tol if run.index == 1 else 1e-9
        assert run.distance_error == pytest.approx(exp["distance_error"], abs=limit)
        if run.index != 1:
            assert run.score is not None
            assert len(run.score.kept) == exp["kept_samples"]


@pytest.mark.slow
def test_auto_mode_reports_detected_times(fbm3w_sample: Sample) -> None:
    result = _score(fbm3w_sample.bag, runs="auto")
    truth = fbm3w_sample.answers["truth"]["runs"]
    start_ns = fbm3w_sample.answers["truth"]["bag_start_ns"]
    for run in result.runs:
        details = run.details()
        motion = truth[run.index]["path_motion"]
        # the path window hugs the motion: the sample's minimum-jerk robot is 0.5 mm (the
        # edge radius at this noise) from the start ~0.2 s after it set off (10 (t/T)^3 of
        # 15-28 cm over 3-4.5 s); the detector extrapolates that by <= 0.1 s and keeps 0.3 s
        # more: 0.2-0.3 s of stillness each side (+-0.15 s)
        assert details["start_time"] == pytest.approx(
            (motion["start_ns"] - start_ns) / 1e9 - 0.2, abs=0.15
        )
        assert details["end_time"] == pytest.approx(
            (motion["end_ns"] - start_ns) / 1e9 + 0.2, abs=0.15
        )
        assert details["run_finding"] == "auto"
    # the printed times, given back as windows, select the same samples: the same scores
    given = tuple(
        (r.spec, r.details()["reference_time"], r.details()["start_time"], r.details()["end_time"])
        for r in result.runs
    )
    again = _score(fbm3w_sample.bag, runs="windows", run=_runs(given))
    assert [r.distance_error for r in again.runs] == [r.distance_error for r in result.runs]
    assert all(r.distance_error is not None for r in again.runs)


def test_d_min_below_noise_is_warned(fbm3w_sample: Sample) -> None:
    result = _score(fbm3w_sample.bag, d_min=0.0002, d_min_sweep="0.0002:0.0005:2")
    eps = fbm3w_sample.answers["expected"]["noise"]["epsilon"]
    warning = next(w for w in result.warnings if "below the mocap noise" in w)
    assert "suggested d_min" in warning
    assert result.noise is not None
    assert result.noise.suggested_d_min == pytest.approx(3 * eps, abs=3 * 2.5e-5)
    assert any("d_min = 0.0002" in d for d in result.deviations)
    sweep = result.runs[0].sweep
    assert [d for d, _ in sweep] == [0.0002, 0.0005]
    assert sweep[0][1] == pytest.approx(result.runs[0].distance_error, abs=1e-15)
