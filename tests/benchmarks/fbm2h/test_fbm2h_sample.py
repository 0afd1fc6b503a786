"""``ertools score fbm2h`` on the simulated sample, in the three --reached modes."""

from __future__ import annotations

import json
from typing import Any

import pytest
import yaml

from ertools.cli.main import main


def _score(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, dict[str, Any], str]:
    code = main(["score", "fbm2h", *argv, "--format", "json"])
    out = capsys.readouterr()
    return code, json.loads(out.out) if out.out.strip() else {}, out.err


def _check_errors(result: dict[str, Any], sample: Any) -> None:
    exp = sample.answers["expected"]
    tol = sample.answers["tolerance"]
    d_tol = tol["distance_error"]["abs"]
    o_tol = tol["orientation_error"]["abs"]
    segs = result["details"]["segments_details"]
    assert list(segs) == [str(k) for k in range(len(exp["segments"]))]
    for k, e in enumerate(exp["segments"]):
        s = segs[str(k)]
        assert s["dinstance_error"] == pytest.approx(e["distance_error"], abs=d_tol)
        assert s["orientation_error"] == pytest.approx(e["orientation_error"], abs=o_tol)
        assert [s["target_pose"][c] for c in ("x", "y", "theta")] == pytest.approx(
            e["target_pose"], abs=1e-12
        )
        assert s["robot_pose"]["x"] == pytest.approx(e["robot_pose"][0], abs=d_tol)
        assert s["robot_pose"]["y"] == pytest.approx(e["robot_pose"][1], abs=d_tol)
    # Means of five values each within the tolerance stay within it.
    assert result["position_accuracy"] == pytest.approx(exp["position_accuracy"], abs=d_tol)
    assert result["orientation_accuracy"] == pytest.approx(exp["orientation_accuracy"], abs=o_tol)


def test_states_mode(fbm2h_sample: Any, capsys: pytest.CaptureFixture[str]) -> None:
    code, result, err = _score(
        capsys,
        str(fbm2h_sample.bag),
        "--team",
        "simbot",
        "--transforms",
        str(fbm2h_sample.folder),
        "--hits",
        "2",
    )
    assert code == 0, err
    _check_errors(result, fbm2h_sample)
    exp = fbm2h_sample.answers["expected"]
    t_tol = fbm2h_sample.answers["tolerance"]["segment_time"]["abs"]
    for k, e in enumerate(exp["segments"]):
        s = result["details"]["segments_details"][str(k)]
        assert s["start_segment_time"] == pytest.approx(e["start"], abs=t_tol)
        assert s["end_segment_time"] == pytest.approx(e["end"], abs=t_tol)
        assert s["segment_time"] == pytest.approx(e["segment_time"], abs=t_tol)
        assert s["result_payload"] == {"waypoint": k}
    assert result["execution_time"] == pytest.approx(exp["execution_time"], abs=5 * t_tol)
    assert result["hits"] == 2
    assert result["timeout_segments"] == 0
    # The goal came from the BmBox payload (no --goal) and the transform from the team file.
    assert "identity" not in err
    assert "wrapped to [0, pi]" in err


def test_timing_mode(fbm2h_sample: Any, capsys: pytest.CaptureFixture[str]) -> None:
    code, result, err = _score(
        capsys,
        str(fbm2h_sample.bag),
        "--goal",
        str(fbm2h_sample.goal),
        "--transform",
        str(fbm2h_sample.transform),
        "--reached",
        "timing",
        str(fbm2h_sample.timing),
    )
    assert code == 0, err
    _check_errors(result, fbm2h_sample)
    # Segment k runs from p(k) to p(k+1), seconds from the bag's first message.
    entries = yaml.safe_load(fbm2h_sample.timing.read_text())["reached_waypoint_timing"]
    p = [next(iter(e.values())) for e in entries]
    first = fbm2h_sample.answers["truth"]["bag_first_ns"] / 1e9
    for k in range(len(p) - 1):
        s = result["details"]["segments_details"][str(k)]
        # Timing values have 9 decimals; epoch floats carry ~0.2 us: 1 us is enough.
        assert s["segment_time"] == pytest.approx(p[k + 1] - p[k], abs=1e-6)
        assert s["end_segment_time"] == pytest.approx(first + p[k + 1], abs=1e-6)
    assert "timing" in err


def test_auto_mode(fbm2h_sample: Any, capsys: pytest.CaptureFixture[str]) -> None:
    code, result, err = _score(
        capsys,
        str(fbm2h_sample.bag),
        "--goal",
        str(fbm2h_sample.goal),
        "--transform",
        str(fbm2h_sample.transform),
        "--reached",
        "auto",
    )
    assert code == 0, err
    _check_errors(result, fbm2h_sample)
    slack = fbm2h_sample.answers["tolerance"]["auto_reached"]["abs"]
    for k, stop in enumerate(fbm2h_sample.answers["truth"]["stops"]):
        end = result["details"]["segments_details"][str(k)]["end_segment_time"]
        # Detected at the true arrival, give or take the detector's window.
        assert stop["start"] - slack <= end <= stop["start"] + slack


def test_tf_source_gives_the_same_score(
    fbm2h_sample: Any, capsys: pytest.CaptureFixture[str]
) -> None:
    code, result, err = _score(
        capsys,
        str(fbm2h_sample.bag),
        "--transform",
        str(fbm2h_sample.transform),
        "--tf-frame",
        "robot_at_home",
    )
    assert code == 0, err
    _check_errors(result, fbm2h_sample)


def test_orientation_2015_option(fbm2h_sample: Any, capsys: pytest.CaptureFixture[str]) -> None:
    code, result, err = _score(
        capsys,
        str(fbm2h_sample.bag),
        "--transform",
        str(fbm2h_sample.transform),
        "--orientation-2015",
    )
    assert code == 0, err
    exp = fbm2h_sample.answers["expected"]
    o_tol = fbm2h_sample.answers["tolerance"]["orientation_error"]["abs"]
    errs = [result["details"]["segments_details"][str(k)]["orientation_error"] for k in range(5)]
    assert errs == pytest.approx([s["orientation_error_2015"] for s in exp["segments"]], abs=o_tol)
    # Waypoint 2 sits across the seam: 2015 reported a negative error there.
    assert errs[2] < 0
    assert result["orientation_accuracy"] == pytest.approx(
        exp["orientation_accuracy_2015"], abs=o_tol
    )
    assert "--orientation-2015" in err


def test_identity_transform_is_said_and_wrong_here(
    fbm2h_sample: Any, capsys: pytest.CaptureFixture[str]
) -> None:
    code, result, err = _score(capsys, str(fbm2h_sample.bag))
    assert code == 0
    assert "identity marker-to-robot transform" in err
    # The marker set is 13 cm from the odometric centre: with identity, waypoint 0 is off.
    exp = fbm2h_sample.answers["expected"]["segments"][0]["distance_error"]
    assert abs(result["details"]["segments_details"]["0"]["dinstance_error"] - exp) > 0.01


def test_yaml_output_has_listing_13_keys(
    fbm2h_sample: Any, capsys: pytest.CaptureFixture[str]
) -> None:
    code = main(
        ["score", "fbm2h", str(fbm2h_sample.bag), "--transform", str(fbm2h_sample.transform)]
    )
    out = capsys.readouterr().out
    assert code == 0
    data = yaml.safe_load(out)
    assert list(data) == [
        "position_accuracy",
        "orientation_accuracy",
        "execution_time",
        "hits",
        "timeout_segments",
        "details",
        # issue 28: the intervals and how they were obtained, after Listing 13's keys
        "position_accuracy_interval",
        "orientation_accuracy_interval",
        "uncertainty",
    ]
    assert list(data["details"]) == ["marker-robot transform", "segments_details"]
    assert list(data["details"]["segments_details"]) == [0, 1, 2, 3, 4]
    assert list(data["details"]["segments_details"][0]) == [
        "dinstance_error",
        "end_segment_time",
        "orientation_error",
        "refbox_timeout",
        "result_payload",
        "robot_pose",
        "segment_time",
        "start_segment_time",
        "target_pose",
        "timeout",
        # ertools' interval and validity keys after the listing's (issue 28)
        "dinstance_error_interval",
        "orientation_error_interval",
        "valid_fraction",
        "invalid_samples",
    ]
    assert data["hits"] is None
