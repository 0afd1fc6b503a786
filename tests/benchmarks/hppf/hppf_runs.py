"""Generated HPPF runs for the tests: a plan of passes (what happens in each) -> a timed RSBB
scenario with noisy mocap, written as a run bag; and the 2019 script replayed on it
(``rsbb_replay.hppf``), the oracle of ``--rules 2019``.

Each pass: the person's entry (0.4 s), the check lookup 12 ms after it (a ``/person``
broadcast), the goal (requested 50 ms later, started 0.2 s after the request, answered 0.6-1.4
s later), the ground-truth lookup 12 ms after the answer. Kinds of pass:

``right``, ``wrong`` (another name), ``case`` (the name in capitals: right for the script),
``blank`` (a trailing blank: wrong for the script), ``int`` (x an integer), ``timeout``,
``prep_timeout``, ``dropout`` (the cap hidden at the entry: three failed checks, the referee
asked again), ``restart`` (the cap hidden after the answer: three failed lookups, the script
restarts the goal with a new draw), ``gap`` (the cap unseen 0.25 s before to 0.2 s after the
lookup: tf interpolates across), ``missing`` (no theta: the script dies), ``badname`` (a name
that is a number: the script dies), and the stops, each ending the run: ``stop_enter``,
``stop_check``, ``stop_retry``, ``stop_prep``, ``stop_goal``, ``stop_truth`` (during the
lookup after the answer), ``global_timeout`` (during a goal).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from ertools.simulator.mocap import MocapNoise, frame_times, simulate_mocap
from ertools.simulator.rsbb import write_rsbb_run
from ertools.simulator.rsbb_scenario import (
    Body,
    Broadcast,
    Goal,
    ManualOperation,
    RsbbScenario,
    Save,
)
from tests.helpers.rsbb_replay import hppf as replay_hppf
from tests.helpers.rsbb_replay.fromlog import timeline_from_bag
from tests.helpers.rsbb_replay.world import ReplayResult, World, run_script

S = 1_000_000_000
MS = 1_000_000
T0 = 1_555_000_000 * S
PEOPLE = ["Joe", "Peter", "Alice", "Michael", "Brad"]
GOAL_TIMEOUT_S = 3.0
NOISE = MocapNoise(sigma_m=2e-4, sigma_rad=5e-4)
STOPS = ("stop_enter", "stop_check", "stop_retry", "stop_prep", "stop_goal", "stop_truth")
IDENTITY = ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0))
ENTER = (
    "{} should enter the target area wearing a cap with MoCap markers, and place him/herself "
    "in an arbitrary position."
)
RETRY = (
    "Could not get {}'s pose. Make sure (s)he is inside the designated area and wearing the "
    "markerset cap."
)


def params(people: Sequence[str] = PEOPLE) -> dict[str, Any]:
    return {"people": list(people), "goal_timeout": GOAL_TIMEOUT_S}


@dataclass(frozen=True)
class HppfRun:
    """A generated run: its scenario and config."""

    scenario: RsbbScenario
    params: dict[str, Any]


def build(plan: Sequence[str], *, seed: int = 0, people: Sequence[str] = PEOPLE) -> HppfRun:
    """The scenario of ``plan`` (one kind per pass); a plan that neither stops nor presents
    every person ends with the referee's stop during the next entry."""
    done = sum(k not in ("restart",) and k not in STOPS for k in plan)
    if done < len(people) and not any(k in STOPS or k == "global_timeout" for k in plan):
        plan = [*plan, "stop_enter"]
    rng = np.random.default_rng(seed)
    left = list(people)
    manual: list[ManualOperation] = []
    goals: list[Goal] = []
    casts: list[Broadcast] = []
    spans: list[tuple[int, int, tuple[float, float]]] = []
    t = T0 + 2 * S
    t_start = t - S
    end_kind, t_end = "end", 0

    def cast(at: int) -> None:
        casts.append(Broadcast(at, "/person", "/actor_markerset", *IDENTITY))

    for kind in plan:
        person = left.pop(int(rng.integers(len(left))))
        where = (float(rng.uniform(-2.0, 2.0)), float(rng.uniform(-2.0, 2.0)))
        entered = t + 500 * MS
        if kind == "stop_enter":
            manual.append(ManualOperation(t + 100 * MS, None, ENTER.format(person)))
            end_kind, t_end = "stop", t + 300 * MS
            break
        manual.append(ManualOperation(t + 100 * MS, entered, ENTER.format(person)))
        seen_from = t + 100 * MS
        clock = entered
        if kind in ("dropout", "stop_check", "stop_retry"):
            if kind == "stop_check":
                end_kind, t_end = "stop", entered + 1500 * MS
                break
            retry = entered + 3 * S + 5 * MS
            if kind == "stop_retry":
                manual.append(ManualOperation(retry, None, RETRY.format(person)))
                end_kind, t_end = "stop", retry + 300 * MS
                break
            clock = retry + 600 * MS
            manual.append(ManualOperation(retry, clock, RETRY.format(person), "ok"))
            seen_from = clock - 300 * MS
        check = clock + 12 * MS
        cast(check)
        request = check + 50 * MS
        start = request + 200 * MS
        if kind == "stop_prep":
            goals.append(Goal(request, None, None, "{}\n", "result"))
            spans.append((seen_from, request + 200 * MS, where))
            end_kind, t_end = "stop", request + 100 * MS
            break
        if kind in ("stop_goal", "global_timeout"):
            goals.append(Goal(request, start, None, "{}\n", "result"))
            spans.append((seen_from, start + S, where))
            end_kind = "stop" if kind == "stop_goal" else "global_timeout"
            t_end = start + 500 * MS
            break
        if kind in ("timeout", "prep_timeout"):
            end = request + round(GOAL_TIMEOUT_S * S)
            goals.append(
                Goal(request, start if kind == "timeout" else None, end, "{}\n", "timeout")
            )
            spans.append((seen_from, end + 600 * MS, where))
            t = end + 50 * MS
            t_end = t + 100 * MS
            continue
        end = start + round(rng.uniform(0.6, 1.4) * S)
        goals.append(Goal(request, start, end, "{}\n", "result", _answer(kind, person, where, rng)))
        if kind in ("restart", "stop_truth"):
            spans.append((seen_from, check + 100 * MS, where))  # then hidden: lookups fail
            if kind == "stop_truth":
                end_kind, t_end = "stop", end + 1500 * MS
                break
            left.append(person)
            t = end + 3 * S + 50 * MS
            t_end = t + 100 * MS
            continue
        truth = end + 12 * MS
        cast(truth)
        if kind == "gap":
            spans.append((seen_from, truth - 250 * MS, where))
            spans.append((truth + 200 * MS, truth + 600 * MS, where))
        else:
            spans.append((seen_from, truth + 600 * MS, where))
        t = truth + 650 * MS
        t_end = t + 100 * MS
        if kind in ("missing", "badname"):
            end_kind, t_end = "stop", t + 500 * MS  # the script died: the referee stops
            break
    if not spans:
        spans.append((t_start, t_start + 100 * MS, (0.0, 0.0)))
    sc = RsbbScenario(
        code="HPPF",
        team="teamA",
        run=1,
        season="2019",
        t_connect_ns=T0,
        t_start_ns=t_start,
        t_end_ns=t_end,
        end=end_kind,
        t_disconnect_ns=t_end + S,
        manual_operations=tuple(manual),
        goals=tuple(goals),
        broadcasts=tuple(casts),
        saves=(Save(t_end, {}),),
        params=params(people),
        bodies=(_body(spans, rng),),
    )
    return HppfRun(sc, params(people))


def _answer(kind: str, person: str, where: tuple[float, float], rng: np.random.Generator) -> str:
    x, y = where[0] + rng.normal(0.0, 0.3), where[1] + rng.normal(0.0, 0.3)
    name = {"wrong": "Nobody", "case": person.upper(), "blank": person + " "}.get(kind, person)
    answer: dict[str, Any] = {"x": x, "y": y, "theta": float(rng.uniform(-3, 3))}
    answer["person_name"] = 5 if kind == "badname" else name
    if kind == "int":
        answer["x"] = 1
    if kind == "missing":
        del answer["theta"]
    return str(yaml.safe_dump(answer, default_flow_style=True, width=1000)).strip()


def _body(spans: list[tuple[int, int, tuple[float, float]]], rng: Any) -> Body:
    times, xyz = [], []
    for start, end, (x, y) in spans:
        t = frame_times(start, (end - start) / S, rate_hz=100.0)
        times.append(t)
        xyz.append(np.tile([x, y, 1.7], (t.size, 1)))
    t_all = np.concatenate(times)
    quat = np.tile([0.0, 0.0, 0.0, 1.0], (t_all.size, 1))
    pub = simulate_mocap(t_all, np.concatenate(xyz), quat, rng=rng, noise=NOISE)
    return Body("actor_markerset", pub)


def write(folder: Path, run: HppfRun) -> tuple[Path, Path]:
    """The run bag and its config beside it."""
    paths = write_rsbb_run(folder, run.scenario)
    config = paths.bag.parent / "HPPF.yaml"
    config.write_text(yaml.safe_dump(run.params), encoding="utf-8")
    return paths.bag, config


def replay(bag: Path, run: HppfRun) -> ReplayResult:
    """The 2019 script replayed on the bag (the oracle)."""
    tl = timeline_from_bag(bag, run.params, {})
    return run_script(World(tl), replay_hppf.execute)
