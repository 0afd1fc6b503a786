"""A hand-computed FBM1 benchmark: rotated and translated table and board, two items.

Table (origin) at world (2, 1, 0.75) turned +90 deg. Run 1: board at (0.3, 0.2) in the table
turned 30 deg, item 1 sits 0.1 m along the board's x: the item is at
(0.3 + 0.1 cos 30, 0.2 + 0.1 sin 30) = (0.386603, 0.25), yaw 30 deg. Run 2: board at
(-0.1, 0.5) turned -45 deg, item 2 sits 0.2 m along the board's y turned +90 deg: the item is
at (-0.1 + 0.2 sin 45, 0.5 + 0.2 cos 45) = (0.041421, 0.641421), yaw 45 deg.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
import yaml
from scipy.spatial.transform import Rotation

from ertools.benchmarks.base import BenchmarkResult
from ertools.benchmarks.fbm1.config import Fbm1Options, GtOptions, ScoreRules
from ertools.benchmarks.fbm1.pipeline import score_fbm1
from ertools.benchmarks.fbm1.result import Fbm1Result
from ertools.benchmarks.fbm1.runs import runs_from_states
from ertools.cli.main import main
from ertools.configs._yaml import parse_yaml
from ertools.configs.items import ItemList, parse_items
from ertools.states import Machine
from ertools.streams import PoseStream
from tests.benchmarks.fbm1.fbm1_testkit import (
    ANSWER_S,
    EXEC_S,
    ITEMS_YAML,
    RunSpec,
    bodies,
    state_streams,
    write_bag,
    write_items,
)
from tests.helpers.yaml_rounding import assert_yaml_of

RUNS = [
    RunSpec(
        "Place item 1 (a1) on the table",
        "{item_class: a, item_instance: a1, x: 0.4, y: 0.25, theta: 35}",
        (0.3, 0.2, 0.03),
        30.0,
    ),
    RunSpec(
        "Place item 2 (b1) on the table",
        "{item_class: b, item_instance: b9, x: 0.04, y: 0.7, theta: -130}",
        (-0.1, 0.5, 0.03),
        -45.0,
    ),
]

# Ground truth by hand (see the module docstring).
GT1 = (0.3 + 0.1 * math.cos(math.radians(30)), 0.2 + 0.1 * math.sin(math.radians(30)), 30.0)
GT2 = (-0.1 + 0.2 * math.sin(math.radians(45)), 0.5 + 0.2 * math.cos(math.radians(45)), 45.0)
# Run 1: t = |(0.4, 0.25) - GT1|, dtheta = 5 deg.
T1 = math.hypot(0.4 - GT1[0], 0.25 - GT1[1])
SCORE1 = 1 - T1 / 2 - (5 / 180) / 2
# Run 2: t = |(0.04, 0.7) - GT2|, dtheta = -130 - 45 = -175 deg.
T2 = math.hypot(0.04 - GT2[0], 0.7 - GT2[1])
SCORE2 = 1 - T2 / 2 - (175 / 180) / 2
# Noiseless mocap and exact transforms: only float rounding (1e-12) separates the numbers.
TOL = 1e-9


def _items() -> ItemList:
    return parse_items(parse_yaml(ITEMS_YAML), "items.yaml")


def _score(options: Fbm1Options | None = None) -> Fbm1Result:
    streams = state_streams(RUNS)
    found = runs_from_states(
        streams[Machine.BMBOX], streams[Machine.REFBOX], streams[Machine.CLIENT]
    )
    origin, board = bodies(RUNS)
    return score_fbm1(origin, board, found, _items(), options)


def test_hand_computed_ground_truth_and_scores() -> None:
    result = _score()
    r1, r2 = result.runs
    assert (r1.gt.x, r1.gt.y, r1.gt.yaw_deg) == pytest.approx(GT1, abs=TOL)
    assert (r2.gt.x, r2.gt.y, r2.gt.yaw_deg) == pytest.approx(GT2, abs=TOL)
    assert r1.errors.theta_error_deg == pytest.approx(5.0, abs=TOL)
    assert r2.errors.theta_error_deg == pytest.approx(-175.0, abs=TOL)
    assert r1.pose_score == pytest.approx(SCORE1, abs=TOL)
    assert r2.pose_score == pytest.approx(SCORE2, abs=TOL)
    assert (r1.class_ok, r1.instance_ok, r2.class_ok, r2.instance_ok) == (True, True, True, False)
    totals = result.totals
    assert totals.class_accuracy == 1.0
    assert totals.instance_accuracy == 0.5
    assert totals.pose_score == pytest.approx((SCORE1 + SCORE2) / 2, abs=TOL)
    # 2015 execution time: goal acknowledged (EXECUTING_GOAL) -> BmBox back to READY.
    assert totals.execution_time == pytest.approx(2 * (6.1 - EXEC_S), abs=1e-9)
    assert not result.failures


@pytest.mark.parametrize("method", ["goal", "result"])
def test_2015_single_lookup_methods_agree_on_a_still_board(method: str) -> None:
    result = _score(Fbm1Options(gt=GtOptions(method=method)))
    r1 = result.runs[0]
    assert r1.gt.samples == 1
    assert (r1.gt.x, r1.gt.y, r1.gt.yaw_deg) == pytest.approx(GT1, abs=TOL)


def test_accuracy_over_10_divides_accuracy_by_ten_at_home() -> None:
    result = _score(Fbm1Options(rules=ScoreRules(accuracy_over_10=True)))
    totals = result.totals
    assert totals.class_accuracy == pytest.approx(2 / 10)
    assert totals.instance_accuracy == pytest.approx(1 / 10)
    assert totals.pose_score == pytest.approx((SCORE1 + SCORE2) / 2, abs=TOL)


@pytest.mark.slow
def test_hand_case_through_a_bag_and_the_cli(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    bag = write_bag(tmp_path / "hand.bag", RUNS)
    items = write_items(tmp_path / "items.yaml")
    code = main(["score", "fbm1h", str(bag), "--items", str(items), "--format", "json"])
    out, err = capsys.readouterr()
    assert code == 0, err

    data = json.loads(out)
    assert data["benchmark"] == "fbm1h"
    # Through the bag the poses pass float64 serialisation and the 0.3 ms record latency;
    # the board is still, so the numbers stay exact to float rounding.
    assert data["runs"]["1"]["ground_truth"]["x"] == pytest.approx(GT1[0], abs=TOL)
    assert data["runs"]["2"]["ground_truth"]["theta"] == pytest.approx(GT2[2], abs=TOL)
    assert data["pose_score"] == pytest.approx((SCORE1 + SCORE2) / 2, abs=TOL)
    assert data["instance_accuracy"] == 0.5
    # The state messages of the bag are recorded at the transition times exactly.
    assert data["execution_time"] == pytest.approx(2 * (6.1 - EXEC_S), abs=1e-6)
    assert data["logged_2015_score"] == {"class_accuracy": 0.5}
    assert "pose" in err and "  1 1:a1" in err  # the per-run table is on stderr
    assert ANSWER_S < 6.1


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_moving_the_whole_world_changes_nothing(seed: int) -> None:
    """A rigid motion of the mocap world (both bodies) leaves every table-frame number as is."""

    rng = np.random.default_rng(seed)
    rot = Rotation.from_rotvec(rng.normal(0, 1.0, 3))
    shift = rng.uniform(-5, 5, 3)

    def moved(s: PoseStream) -> PoseStream:
        r = rot * Rotation.from_quat(s.quat_xyzw)
        return PoseStream(s.t_ns, rot.apply(s.xyz) + shift, r.as_quat(), s.frame_id)

    streams = state_streams(RUNS)
    found = runs_from_states(
        streams[Machine.BMBOX], streams[Machine.REFBOX], streams[Machine.CLIENT]
    )
    origin, board = bodies(RUNS)
    base = score_fbm1(origin, board, found, _items())
    other = score_fbm1(moved(origin), moved(board), found, _items())
    for a, b in zip(base.runs, other.runs, strict=True):
        # Float rounding through one more rotation: 1e-9 m / deg.
        assert (b.gt.x, b.gt.y, b.gt.yaw_deg) == pytest.approx(
            (a.gt.x, a.gt.y, a.gt.yaw_deg), abs=1e-9
        )
    assert other.totals.pose_score == pytest.approx(base.totals.pose_score, abs=1e-9)


def test_result_protocol_and_formats() -> None:
    result = _score()
    assert isinstance(result, BenchmarkResult)
    data = yaml.safe_load(result.to_yaml())
    assert_yaml_of(data, result.to_dict())  # floats written to 9 decimals
    # the hand-computed score as YAML writes it: 9 decimals (0.7320016638025953 in JSON)
    assert data["pose_score"] == round((SCORE1 + SCORE2) / 2, 9)
    # The 2015 score first, in the order its node's yaml.dump wrote it.
    assert list(data)[:4] == ["class_accuracy", "execution_time", "instance_accuracy", "pose_score"]
    rows = result.tables()["runs"]
    assert [r["run"] for r in rows] == [1, 2]
    assert rows[1]["pose_score"] == pytest.approx(SCORE2, abs=TOL)
    assert rows[0]["gt_theta_deg"] == pytest.approx(30.0, abs=TOL)
