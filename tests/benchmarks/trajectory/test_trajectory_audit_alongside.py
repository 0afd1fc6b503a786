"""The clock audit searches on a second core while the score associates: the result is the one
of the serial run to the bit, the audit finds the generator's offset, and its errors (or the
score's, while it runs) reach the caller with no thread left behind."""

from __future__ import annotations

import json
import threading
import time
from typing import Any

import numpy as np
import pytest

from ertools import cores as cores_module
from ertools.benchmarks.common.inputs import IntervalSettings
from ertools.benchmarks.trajectory import comparison
from ertools.benchmarks.trajectory.comparison import score_streams
from ertools.benchmarks.trajectory.config import TrajectoryConfig
from ertools.errors import ClockError
from ertools.geometry import quat_from_yaw
from ertools.streams import PoseStream

MS = 1_000_000
T0 = 1_700_000_000 * 1_000_000_000
LAG_NS = 40 * MS  # the robot's clock behind the GT's: the offset to add is +40 ms
DRAWS = IntervalSettings(draws=60)


def path(t_s: np.ndarray) -> np.ndarray:
    """Where the marker is at ``t_s`` seconds (a smooth loop, ~0.7 m/s)."""
    return np.column_stack(
        [2.0 * np.sin(0.5 * t_s), 1.5 * np.cos(0.3 * t_s), 0.2 + 0.05 * np.sin(t_s)]
    )


def streams() -> tuple[PoseStream, PoseStream]:
    """GT at 120 Hz for 60 s; the robot at 10 Hz inside it, stamped LAG_NS early, with 2 mm of
    noise on each axis."""
    t_gt = T0 + np.arange(0, 60 * 120, dtype=np.int64) * (1_000_000_000 // 120)
    s_gt = (t_gt - T0) / 1e9
    gt = PoseStream(t_gt, path(s_gt), quat_from_yaw(0.3 * s_gt), "world", "body")
    true = T0 + 2_000 * MS + np.arange(0, 550, dtype=np.int64) * 100 * MS
    s_true = (true - T0) / 1e9
    noise = np.random.default_rng(7).normal(0.0, 0.002, (len(true), 3))
    robot = PoseStream(
        true - LAG_NS, path(s_true) + noise, quat_from_yaw(0.3 * s_true), "world", "robot"
    )
    return gt, robot


def scored(monkeypatch: pytest.MonkeyPatch, cores: int, **config: Any) -> tuple[str, list[int]]:
    """The result's JSON with ``cores`` cores, and the threads the audit's search ran on."""
    monkeypatch.setattr(cores_module, "workers", lambda: cores)
    searched = comparison.search_offset
    ran_on: list[int] = []

    def spy(*args: Any, **kwargs: Any) -> Any:
        ran_on.append(threading.get_ident())
        return searched(*args, **kwargs)

    monkeypatch.setattr(comparison, "search_offset", spy)
    gt, robot = streams()
    result = score_streams(robot, gt, TrajectoryConfig(**config), intervals=DRAWS)
    monkeypatch.setattr(comparison, "search_offset", searched)
    assert [t for t in threading.enumerate() if t.name == "ertools-alongside"] == []
    return json.dumps(result.to_dict(), sort_keys=True), ran_on


@pytest.mark.parametrize(
    "config",
    [
        {},  # the audit's mean distance at no offset from the score's pairs
        {"association": "hold"},  # measured by the audit itself
        {"offset_ns": LAG_NS},
        {"auto_offset": True, "apply_offset": True},  # the audit first: serial
    ],
    ids=["default", "hold", "offset", "apply"],
)
def test_threaded_and_serial_give_the_same_result(
    monkeypatch: pytest.MonkeyPatch, config: dict[str, Any]
) -> None:
    threaded, on = scored(monkeypatch, 2, **config)
    serial, serial_on = scored(monkeypatch, 1, **config)
    assert threaded == serial
    me = threading.get_ident()
    assert serial_on == [me]
    assert on == [me] if config.get("apply_offset") else on != [me]
    audit = json.loads(threaded)["clock_audit"]
    # the generator's lag, found to a millisecond (2 mm of noise at ~0.7 m/s)
    assert audit["estimated_offset"] == pytest.approx(LAG_NS / 1e9, abs=1e-3)


def test_the_mean_distance_at_no_offset_is_the_generators(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    document, _ = scored(monkeypatch, 2)
    _, robot = streams()
    # each robot pose against the marker's true place at its stamp (the GT's 120 Hz linear
    # interpolation of the loop errs by < 0.01 mm)
    want = np.linalg.norm(robot.xyz - path((robot.t_ns - T0) / 1e9), axis=1).mean()
    got = json.loads(document)["clock_audit"]["mean_error_at_zero"]
    assert got == pytest.approx(want, abs=1e-5)
    assert got > 0.02  # 40 ms at ~0.7 m/s: not the noise alone (3.4 mm)


def test_an_error_of_the_audit_reaches_the_caller(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(cores_module, "workers", lambda: 2)
    ran_on: list[int] = []

    def failing(*args: Any, **kwargs: Any) -> Any:
        ran_on.append(threading.get_ident())
        raise ClockError("the audit's own error")

    monkeypatch.setattr(comparison, "search_offset", failing)
    gt, robot = streams()
    with pytest.raises(ClockError, match=r"^the audit's own error$"):
        score_streams(robot, gt, TrajectoryConfig(), intervals=DRAWS)
    assert ran_on != [threading.get_ident()]
    assert [t for t in threading.enumerate() if t.name == "ertools-alongside"] == []


def test_the_scores_error_while_the_audit_runs(monkeypatch: pytest.MonkeyPatch) -> None:
    """Robot poses after the GT's end: the score stops with the serial run's ClockError, the
    audit (slowed down: still running when the score raises) finished and gone."""
    searched = comparison.search_offset
    finished: list[int] = []

    def slow(*args: Any, **kwargs: Any) -> Any:
        time.sleep(0.2)
        got = searched(*args, **kwargs)
        finished.append(threading.get_ident())
        return got

    monkeypatch.setattr(comparison, "search_offset", slow)
    gt, robot = streams()
    late = PoseStream(robot.t_ns + 30 * 1_000 * MS, robot.xyz, robot.quat_xyzw, "world", "robot")
    said = []
    for cores in (2, 1):
        monkeypatch.setattr(cores_module, "workers", lambda cores=cores: cores)
        with pytest.raises(ClockError) as caught:
            score_streams(late, gt, TrajectoryConfig(), intervals=DRAWS)
        said.append(str(caught.value))
        assert [t for t in threading.enumerate() if t.name == "ertools-alongside"] == []
    assert said[0] == said[1]
    assert "lie outside the GT" in said[0] and "--allow-partial" in said[0]
    me = threading.get_ident()
    assert finished[0] != me and finished[1] == me


@pytest.mark.parametrize(
    "config",
    [
        {},
        {"association": "hold"},
        {"association": "nearest"},
        {"association": "nearest", "t_max_diff": 0.01},
    ],
    ids=["default", "hold", "nearest", "evo"],
)
def test_the_intervals_prepared_during_the_audit_are_the_serial_ones(
    monkeypatch: pytest.MonkeyPatch, config: dict[str, Any]
) -> None:
    """The statistics and the intervals' part the audit does not decide, computed while the
    audit runs, give the result of computing them afterwards, to the bit; evo's pairs (which
    may repeat robot poses) are left to afterwards."""
    monkeypatch.setattr(cores_module, "workers", lambda: 2)
    prepare = comparison.prepare_intervals
    calls: list[int] = []

    def spy(*args: Any, **kwargs: Any) -> Any:
        calls.append(1)
        return prepare(*args, **kwargs)

    monkeypatch.setattr(comparison, "prepare_intervals", spy)
    gt, robot = streams()
    early = score_streams(robot, gt, TrajectoryConfig(**config), intervals=DRAWS)
    assert calls == ([] if "t_max_diff" in config else [1])
    monkeypatch.setattr(comparison, "_prepared", lambda *args: None)
    late = score_streams(robot, gt, TrajectoryConfig(**config), intervals=DRAWS)
    assert json.dumps(early.to_dict(), sort_keys=True) == json.dumps(late.to_dict(), sort_keys=True)
    assert early.to_dict()["position_error_interval"] is not None


def test_an_error_while_preparing_is_met_where_it_always_was(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """A failure of the early part is not raised during the audit: the comparison computes the
    intervals afterwards, as a serial run does (here: with the same numbers)."""
    monkeypatch.setattr(cores_module, "workers", lambda: 2)

    def failing(*args: Any, **kwargs: Any) -> Any:
        raise ValueError("not during the audit")

    gt, robot = streams()
    want = score_streams(robot, gt, TrajectoryConfig(), intervals=DRAWS).to_dict()
    monkeypatch.setattr(comparison, "prepare_intervals", failing)
    got = score_streams(robot, gt, TrajectoryConfig(), intervals=DRAWS).to_dict()
    assert json.dumps(got, sort_keys=True) == json.dumps(want, sort_keys=True)
