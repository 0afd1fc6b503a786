"""HPPF by ertools' reading and by the 2019 script, numbers worked out by hand on a noiseless
run: the cap stands at (1, 2) throughout; people Joe and Ann.

- goal 0, Joe: answered ``"JOE "`` at (1.3, 2.4): 0.5 m off; the script lower-cases but keeps
  the blank (not recognised), ertools strips it (recognised);
- goal 1, Ann: answered without theta at (1.6, 2.8): 1.0 m off; the 2019 script dies on the
  missing key, ertools scores it (recognised).

ertools: Recognized persons 2, ``100.0%``, Distance error (0.5 + 1.0) / 2 = 0.75. The script:
its last save, goal 1's segment time and goal 0's totals: 0, ``0.0%``, 0.5.
"""

from __future__ import annotations

import json
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

IDENTITY = ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0))
ANSWERS = (
    "{x: 1.3, y: 2.4, theta: 0.0, person_name: 'JOE '}",
    "{x: 1.6, y: 2.8, person_name: Ann}",
)


def _enter(name: str) -> str:
    return (
        f"{name} should enter the target area wearing a cap with MoCap markers, and place "
        "him/herself in an arbitrary position."
    )


def _run(gap: bool = False) -> Any:
    """Goal k from 10k s: entered at +1 s, checked at +1.01 s, sent at +1.5 s, started at +2 s,
    answered at +4 s, looked up at +4.01 s."""
    manual, goals, casts = [], [], []
    for k, (name, answer) in enumerate(zip(("Joe", "Ann"), ANSWERS, strict=True)):
        base = 10.0 * (k + 1)
        manual.append(ManualOperation(at(base + 0.5), at(base + 1.0), _enter(name)))
        casts += [
            Broadcast(at(base + 1.01), "/person", "/actor_markerset", *IDENTITY),
            Broadcast(at(base + 4.01), "/person", "/actor_markerset", *IDENTITY),
        ]
        goals.append(Goal(at(base + 1.5), at(base + 2.0), at(base + 4.0), "{}\n", "result", answer))
    losses = (TrackingLoss(at(13.8), repeat_frames=0, gap_frames=48),) if gap else ()
    return replace(
        hnf_scenario(),
        code="HPPF",
        t_start_ns=at(2.0),
        t_end_ns=at(30.0),
        end="stop",
        t_disconnect_ns=at(31.0),
        manual_operations=tuple(manual),
        goals=tuple(goals),
        broadcasts=tuple(casts),
        saves=(Save(at(30.0), {}),),
        params={"people": ["Joe", "Ann"], "goal_timeout": 120.0},
        bodies=(still_body("actor_markerset", (1.0, 2.0, 1.7), 35.0, losses),),
        referee_score=None,
    )


def _files(folder: Path, gap: bool = False) -> tuple[Path, Path]:
    bag = write_rsbb_run(folder, _run(gap)).bag
    config = folder / "HPPF.yaml"
    config.write_text(yaml.safe_dump({"people": ["Joe", "Ann"], "goal_timeout": 120.0}))
    return bag, config


def _score(bag: Path, config: Path, **values: Any) -> Any:
    bench = registry.get("hppf")
    return score_execution(bench, [bag], {"config": config, "draws": 0, **values}).result


def test_ertools_and_the_script_by_hand(tmp_path: Path) -> None:
    bag, config = _files(tmp_path)
    result = _score(bag, config)
    s = result.score
    assert s["goal_0"]["position_error"] == pytest.approx(0.5, abs=1e-9)
    assert s["goal_0"]["recognized"] is True
    assert s["goal_1"]["position_error"] == pytest.approx(1.0, abs=1e-9)
    assert s["goal_1"]["answer_problem"] == "no theta"
    assert (s["Recognized persons"], s["% Recognized persons"]) == (2, "100.0%")
    assert s["Distance error"] == pytest.approx(0.75, abs=1e-9)
    assert s["execution_time"] == pytest.approx(4.0, abs=1e-12)
    assert {d.rule.key for d in result.deviations} == {"hppf.names", "hppf.answer-fields"}
    script = _score(bag, config, rules="2019")
    s = script.score
    assert script.crashed is not None and "no theta" in script.crashed
    assert s["goal_1"] == {"segment_time [s]": 2.0}
    assert (s["Recognized persons"], s["% Recognized persons"]) == (0, "0.0%")
    assert s["Distance error"] == pytest.approx(0.5, abs=1e-9)
    assert s["execution_time"] == 2.0
    assert _score(bag, config, exact_names=True).score["goal_0"]["recognized"] is False


def test_a_tracking_gap_leaves_the_goal_without_ground_truth(tmp_path: Path) -> None:
    bag, config = _files(tmp_path, gap=True)
    result = _score(bag, config)
    g0 = result.score["goal_0"]
    assert g0["status"] == "unscoreable" and g0["position_error"] is None
    assert "tracking gap of 0.4" in g0["unscoreable_reason"]
    assert result.score["Distance error"] == pytest.approx(1.0, abs=1e-9)  # goal 1 alone
    assert result.score["Recognized persons"] == 2  # the names do not need the mocap
    assert "hppf.gt-gaps" in {d.rule.key for d in result.deviations}
    s = _score(bag, config, gt_gaps="interpolate").score
    assert s["goal_0"]["position_error"] == pytest.approx(0.5, abs=1e-9)


def test_the_options_on_the_command_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    bag, config = _files(tmp_path, gap=True)
    argv = ["score", "hppf", str(bag), "--config", str(config), "--draws", "0", "--format", "json"]
    assert main([*argv, "--exact-names", "--gt-gaps", "interpolate"]) == 0
    out = capsys.readouterr()
    score = json.loads(out.out)
    assert score["goal_0"]["recognized"] is False
    assert score["goal_0"]["position_error"] == pytest.approx(0.5, abs=1e-9)
    printed = [ln for ln in out.err.splitlines() if "differs from 2019" in ln]
    assert len(printed) == 1 and "[hppf.answer-fields]" in printed[0]
