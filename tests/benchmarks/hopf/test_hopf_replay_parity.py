"""``ertools score hopf --rules 2019/2017/2017-11`` against the script replayed statement by
statement (``tests/rsbb_replay/hopf.py``) on generated run bags: the same score field for field.

Tolerance 1e-12 on numbers: both read the same log (the lookups' moments are the logged
broadcasts' stamps, the goal times the RefBox's messages) and do the same float operations;
what may differ is the order of a few additions in tf's composition (a few ulps of 1 m).
Strings, booleans and nulls exactly; the keys exactly.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest

from ertools.benchmarks import registry
from ertools.benchmarks.scoring import score_execution
from tests.benchmarks.hopf.hopf_runs import STOPS, build, replay, write
from tests.helpers.rsbb_fields import same

pytestmark = pytest.mark.slow  # writes and reads run bags (~1 s each)

PLANS = {
    "normal": ["right", "wrong", "int", "right", "blank"],
    "timeouts": ["timeout", "right", "prep_timeout", "wrong"],
    "dropouts": ["dropout", "right", "gap", "dropout2", "right"],
    "ten": [
        "right",
        "wrong",
        "right",
        "timeout",
        "right",
        "int",
        "wrong",
        "right",
        "blank",
        "right",
    ],
    "missing": ["right", "missing", "right"],
    "badnum": ["wrong", "badnum", "right"],
}
PLANS.update({stop: ["right", "timeout", stop] for stop in STOPS})
PLANS["global_timeout"] = ["wrong", "global_timeout"]
PLANS["stop_first"] = ["stop_mo1"]


def _score(bag: Path, items: Path, config: Path, rules: str) -> Any:
    bench = registry.get("hopf")
    values = {"items": items, "config": config, "rules": rules, "draws": 0}
    return score_execution(bench, [bag], values).result


@pytest.mark.parametrize("rules", ["2019", "2017", "2017-11"])
@pytest.mark.parametrize("plan", sorted(PLANS))
def test_rules_equal_the_replayed_script(tmp_path: Path, plan: str, rules: str) -> None:
    kinds = PLANS[plan]
    if rules == "2017-11" and "stop_mo3" in kinds:
        pytest.skip("n/a: November 2017 never asked to move the positioner")
    run = build(kinds, seed=len(plan) + len(rules), rules=rules)
    bag, items, config = write(tmp_path, run)
    oracle = replay(bag, run)
    result = _score(bag, items, config, rules)
    same(result.score, oracle.score)
    assert (result.crashed is not None) == (oracle.crashed is not None)


@pytest.mark.parametrize("seed", range(6))
def test_random_plans_equal_the_replayed_script(tmp_path: Path, seed: int) -> None:
    # plans drawn at random: any mix of the goal kinds, a stop or not at the end
    rng = np.random.default_rng(seed)
    kinds = ["right", "wrong", "int", "blank", "timeout", "prep_timeout", "dropout", "gap"]
    plan = [str(rng.choice(kinds)) for _ in range(int(rng.integers(1, 11)))]
    if rng.random() < 0.5 and len(plan) < 10:
        plan.append(str(rng.choice(STOPS)))
    run = build(plan, seed=100 + seed)
    bag, items, config = write(tmp_path, run)
    oracle = replay(bag, run)
    same(_score(bag, items, config, "2019").score, oracle.score)


def test_the_comparison_sees_a_difference(tmp_path: Path) -> None:
    # the oracle of one version against another's rules, and ertools' reading against the
    # script: each differs somewhere, so the parity above is no tautology
    run = build(PLANS["ten"], seed=7, rules="2017")
    bag, items, config = write(tmp_path, run)
    oracle = replay(bag, run)
    assert "manual_operation_1" in oracle.score["goal_1"]
    for rules in ("2019", "ertools"):
        with pytest.raises(AssertionError):
            same(_score(bag, items, config, rules).score, oracle.score)


def test_the_plans_take_the_script_down_its_paths(tmp_path: Path) -> None:
    run = build(PLANS["missing"], seed=1)
    bag, items, config = write(tmp_path, run)
    oracle = replay(bag, run)
    assert oracle.crashed is not None and oracle.crashed.startswith("KeyError")
    # the last save: goal 2's goal fields, goal 1's totals
    assert set(oracle.score["goal_2"]) == {"timeout", "completed", "segment_time"}
    run = build(PLANS["dropouts"], seed=2)
    bag, items, config = write(tmp_path / "d", run)
    result = _score(bag, items, config, "2019")
    assert [len(it.retries) for it in result_iterations(bag, items, config)] == [1, 0, 0, 2, 0, 0]
    assert result.score["goal_1"]["completed"] is True


def result_iterations(bag: Path, items: Path, config: Path) -> Any:
    bench = registry.get("hopf")
    opts = bench.make_options({"items": items, "config": config, "draws": 0})
    logs = bench.load([bag], opts)
    return bench.find_runs(logs, opts).iterations
