"""HOPF by ertools' reading, numbers worked out by hand on a noiseless run.

The table stands at the testbed origin facing x, the positioner at (0.5, 0.6) facing x; every
item sits 0.1 m ahead of the positioner: the truth is (0.6, 0.6, 0) in the table frame. Goals:

1. answered 1.5 m off in x, theta 0: t = 1.5 (2019) or 1 (clipped): pose score 0.25 / 0.5;
2. answered on the spot, theta 4 pi - 0.1: one wrap step leaves 2 pi - 0.1 (r = 1, pose
   score 0.5); a full wrap -0.1 (r = 0.1 / pi, pose score 1 - 0.05 / pi);
3. answered on the spot, class " a" (a blank): wrong for the script, right for ertools;
4. timed out;
5. answered without theta: the 2019 script dies; ertools scores its pose 0, class and
   instance right;
then the referee stops during the sixth goal's first manual operation.
"""

from __future__ import annotations

import json
import math
from dataclasses import replace
from pathlib import Path
from typing import Any

import pytest
import yaml

from ertools.benchmarks import registry
from ertools.benchmarks.scoring import score_execution
from ertools.cli.main import main
from ertools.simulator.mocap import TrackingLoss
from ertools.simulator.rsbb import write_rsbb_run
from ertools.simulator.rsbb_scenario import Broadcast, Goal, ManualOperation, Save
from tests.helpers.rsbb_replay.scenarios import at, hnf_scenario, still_body

pytestmark = pytest.mark.slow  # writes and reads a run bag

ITEMS = [
    {
        "id": k,
        "class": "a",
        "instance": f"i{k}",
        "description": f"thing {k}",
        "trans": [0.1, 0.0, 0.0],
        "rot": [0.0, 0.0, 0.0, 1.0],
    }
    for k in range(1, 12)
]
PARAMS = {"table_size": {"x": 1.0, "y": 1.5}, "goal_timeout": 120}
ANSWERS = [
    "{x: 2.1, y: 0.6, theta: 0.0, class: a, instance: i1}",
    "{x: 0.6, y: 0.6, theta: %r, class: a, instance: i2}" % (4 * math.pi - 0.1),
    "{x: 0.6, y: 0.6, theta: 0.0, class: ' a', instance: i3}",
    None,
    "{x: 0.6, y: 0.6, class: a, instance: i5}",
]


def _place(k: int) -> str:
    return f"Place the positioner and the thing {k} (id: {k}, instance: i{k}) on the table"


def _run(gap_at_goal: int | None = None) -> Any:
    """Goal k (from 1) from 10k s: placed at +1 s, looked up at +1.01 s, removed at +2 s, sent at
    +2.5 s, started at +3 s, answered at +5 s (goal 4 times out at +9 s)."""
    manual, goals, casts = [], [], []
    identity_item = ((0.1, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0))
    for k in range(1, 6):
        base = 10.0 * k
        manual += [
            ManualOperation(at(base + 0.5), at(base + 1.0), _place(k)),
            ManualOperation(at(base + 1.5), at(base + 2.0), "Remove the positioner"),
        ]
        casts.append(Broadcast(at(base + 1.01), "/item", "/positioner_origin", *identity_item))
        if ANSWERS[k - 1] is None:
            goals.append(Goal(at(base + 2.5), at(base + 3.0), at(base + 9.0), "{}\n", "timeout"))
        else:
            goals.append(
                Goal(
                    at(base + 2.5), at(base + 3.0), at(base + 5.0), "{}\n", "result", ANSWERS[k - 1]
                )
            )
    manual.append(ManualOperation(at(60.5), None, _place(6)))
    losses: tuple[TrackingLoss, ...] = ()
    if gap_at_goal is not None:  # the positioner unseen 0.3 s around the lookup
        losses = (TrackingLoss(at(10.0 * gap_at_goal + 0.8), repeat_frames=0, gap_frames=48),)
    return replace(
        hnf_scenario(),
        code="HOPF",
        t_start_ns=at(2.0),
        t_end_ns=at(61.0),
        end="stop",
        t_disconnect_ns=at(62.0),
        manual_operations=tuple(manual),
        goals=tuple(goals),
        broadcasts=tuple(casts),
        saves=(Save(at(61.0), {}),),
        params=PARAMS,
        bodies=(
            still_body("table_origin", (0.0, 0.0, 0.0), 65.0),
            still_body("positioner_origin", (0.5, 0.6, 0.0), 65.0, losses),
        ),
        referee_score=None,
    )


@pytest.fixture(scope="module")
def run_files(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    folder = tmp_path_factory.mktemp("hopf_hand")
    bag = write_rsbb_run(folder, _run()).bag
    items = folder / "items_with_pose.yaml"
    items.write_text(yaml.safe_dump({"items": ITEMS}), encoding="utf-8")
    return bag, items


def _score(bag: Path, items: Path, **values: Any) -> Any:
    bench = registry.get("hopf")
    return score_execution(bench, [bag], {"items": items, "draws": 0, **values}).result


def test_ertools_reading_by_hand(run_files: tuple[Path, Path]) -> None:
    result = _score(*run_files)
    s = result.score
    ps = [s[f"goal_{k}"].get("partial_score", {}).get("pose_score") for k in range(1, 6)]
    # goal 1: t clipped at 1, r 0; goal 2: r = 0.1 / pi; goal 3: on the spot; goal 5: no theta
    assert ps[0] == pytest.approx(0.5, abs=1e-9)
    assert ps[1] == pytest.approx(1 - 0.05 / math.pi, abs=1e-9)
    assert ps[2] == pytest.approx(1.0, abs=1e-9)
    assert ps[3] is None and s["goal_4"]["status"] == "timeout"
    assert ps[4] == 0.0 and s["goal_5"]["answer_problem"] == "no theta"
    assert s["goal_3"]["partial_score"]["is_class_correct"] is True
    # five goals with a known outcome; classes right in 1, 2, 3, 5; instances likewise
    assert s["class_accuracy"] == pytest.approx(4 / 5, abs=1e-15)
    assert s["instance_accuracy"] == pytest.approx(4 / 5, abs=1e-15)
    total = (0.5 + (1 - 0.05 / math.pi) + 1.0 + 0.0) / 5
    assert s["pose_score"] == pytest.approx(total, abs=1e-9)
    # goals 1-3 and 5 took 2 s, goal 4 6 s
    assert s["execution_time"] == pytest.approx(14.0, abs=1e-9)
    keys = {d.rule.key for d in result.deviations}
    assert keys == {
        "hopf.translation-clip",
        "hopf.theta-wrap",
        "hopf.names",
        "hopf.stopped-goal",
        "hopf.answer-fields",
    }


def test_each_option_restores_the_script(run_files: tuple[Path, Path]) -> None:
    s = _score(*run_files, clip_translation="none").score
    assert s["goal_1"]["partial_score"]["pose_score"] == pytest.approx(0.25, abs=1e-9)
    s = _score(*run_files, single_wrap=True).score
    assert s["goal_2"]["partial_score"]["pose_score"] == pytest.approx(0.5, abs=1e-9)
    s = _score(*run_files, exact_names=True).score
    assert s["goal_3"]["partial_score"]["is_class_correct"] is False
    assert s["class_accuracy"] == pytest.approx(3 / 5, abs=1e-15)
    # the script's divisor: the six goals begun would be 6, but the sixth never reached its
    # totals: the goals up to the last scored, 5
    s = _score(*run_files, stopped_goals="2019").score
    assert s["class_accuracy"] == pytest.approx(4 / 5, abs=1e-15)


def test_the_2019_script_dies_on_goal_5(run_files: tuple[Path, Path]) -> None:
    result = _score(*run_files, rules="2019")
    s = result.score
    assert result.crashed is not None and "no theta" in result.crashed
    assert s["goal_5"] == {"timeout": False, "completed": True, "segment_time": 2.0}
    # the totals of goal 4: classes right in 1 and 2 of 4 goals begun
    assert s["class_accuracy"] == pytest.approx(2 / 4, abs=1e-15)
    assert s["pose_score"] == pytest.approx((0.25 + 0.5 + 1.0) / 4, abs=1e-9)
    assert s["execution_time"] == pytest.approx(12.0, abs=1e-12)
    assert "goal_6" not in s


def test_a_tracking_gap_leaves_the_goal_without_ground_truth(tmp_path: Path) -> None:
    bag = write_rsbb_run(tmp_path, _run(gap_at_goal=1)).bag
    items = tmp_path / "items_with_pose.yaml"
    items.write_text(yaml.safe_dump({"items": ITEMS}), encoding="utf-8")
    result = _score(bag, items)
    g1 = result.score["goal_1"]
    assert g1["status"] == "unscoreable" and "tracking gap of 0.4" in g1["unscoreable_reason"]
    assert result.failures and "goal 1" in result.failures[0]
    assert "hopf.gt-gaps" in {d.rule.key for d in result.deviations}
    # four goals counted (1 left out): classes right in 2, 3, 5
    assert result.score["class_accuracy"] == pytest.approx(3 / 4, abs=1e-15)
    # tf interpolated across the gap (the positioner did not move): goal 1 scored as by the script
    s = _score(bag, items, gt_gaps="interpolate").score
    assert s["goal_1"]["partial_score"]["pose_score"] == pytest.approx(0.5, abs=1e-9)
    assert _score(bag, items, max_gap=1.0).score["goal_1"]["status"] == "scored"


def test_the_options_on_the_command_line(
    run_files: tuple[Path, Path], capsys: pytest.CaptureFixture[str]
) -> None:
    # each rule's option as typed restores the script's behaviour: the deviation lines go
    bag, items = run_files
    base = ["score", "hopf", str(bag), "--items", str(items), "--draws", "0", "--format", "json"]
    restore = [
        "--clip-translation",
        "none",
        "--single-wrap",
        "--exact-names",
        "--stopped-goals",
        "2019",
        "--gt-gaps",
        "interpolate",
    ]
    assert main([*base, *restore]) == 0
    out = capsys.readouterr()
    score = json.loads(out.out)
    assert score["goal_1"]["partial_score"]["pose_score"] == pytest.approx(0.25, abs=1e-9)
    assert score["goal_2"]["partial_score"]["pose_score"] == pytest.approx(0.5, abs=1e-9)
    printed = [ln for ln in out.err.splitlines() if "differs from 2019" in ln]
    # what no single option restores: the answer without theta (only --rules 2019)
    assert len(printed) == 1 and "[hopf.answer-fields]" in printed[0]
