"""``ertools score hppf --rules 2019`` against the 2019 script replayed statement by statement
(``tests/rsbb_replay/hppf.py``) on generated run bags: the same score field for field.

Tolerance 1e-12 on numbers: both read the same log (the lookups' moments are the logged
broadcasts' stamps, the goal times the RefBox's messages) and do the same float operations.
The ``% Recognized persons`` text, the position texts, booleans and nulls exactly.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest

from ertools.benchmarks import registry
from ertools.benchmarks.scoring import score_execution
from tests.benchmarks.hppf.hppf_runs import STOPS, build, replay, write
from tests.helpers.rsbb_fields import same

pytestmark = pytest.mark.slow  # writes and reads run bags

PLANS = {
    "complete": ["right", "wrong", "case", "int", "right"],
    "names": ["blank", "right", "wrong"],
    "timeouts": ["timeout", "right", "prep_timeout", "right", "right"],
    "dropouts": ["dropout", "right", "gap", "dropout"],
    "restarts": ["restart", "right", "restart", "restart", "wrong", "right", "right"],
    "missing": ["right", "missing"],
    "badname": ["case", "badname"],
    "global_timeout": ["right", "global_timeout"],
}
PLANS.update({stop: ["right", "timeout", stop] for stop in STOPS})
PLANS["stop_first"] = ["stop_enter"]


def _score(bag: Path, config: Path, rules: str) -> Any:
    bench = registry.get("hppf")
    values = {"config": config, "rules": rules, "draws": 0}
    return score_execution(bench, [bag], values).result


@pytest.mark.parametrize("plan", sorted(PLANS))
def test_rules_2019_equal_the_replayed_script(tmp_path: Path, plan: str) -> None:
    run = build(PLANS[plan], seed=len(plan))
    bag, config = write(tmp_path, run)
    oracle = replay(bag, run)
    result = _score(bag, config, "2019")
    same(result.score, oracle.score)
    assert (result.crashed is not None) == (oracle.crashed is not None)


@pytest.mark.parametrize("seed", range(6))
def test_random_plans_equal_the_replayed_script(tmp_path: Path, seed: int) -> None:
    rng = np.random.default_rng(seed)
    kinds = ["right", "wrong", "case", "blank", "int", "timeout", "prep_timeout", "dropout", "gap"]
    plan = [str(rng.choice(kinds)) for _ in range(int(rng.integers(1, 6)))]
    if rng.random() < 0.3:
        plan.insert(int(rng.integers(len(plan) + 1)), "restart")
    if rng.random() < 0.5 and sum(k != "restart" for k in plan) < 5:
        plan.append(str(rng.choice(STOPS)))
    run = build(plan, seed=200 + seed)
    bag, config = write(tmp_path, run)
    same(_score(bag, config, "2019").score, replay(bag, run).score)


def test_the_comparison_sees_a_difference(tmp_path: Path) -> None:
    run = build(PLANS["names"], seed=5)
    bag, config = write(tmp_path, run)
    oracle = replay(bag, run)
    with pytest.raises(AssertionError):
        same(_score(bag, config, "ertools").score, oracle.score)


def test_the_plans_take_the_script_down_its_paths(tmp_path: Path) -> None:
    run = build(PLANS["restarts"], seed=3)
    bag, config = write(tmp_path, run)
    oracle = replay(bag, run)
    result = _score(bag, config, "2019")
    assert [p.status for p in result.passes].count("restarted") == 3
    assert set(oracle.score) >= {f"goal_{i}" for i in range(5)}
    assert oracle.score["% Recognized persons"] == result.score["% Recognized persons"]
