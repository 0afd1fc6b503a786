"""Generated HOPF runs for the tests: a plan of goals (what happens in each) -> a timed RSBB
scenario with noisy mocap, written as a run bag by the simulator; and the replay of the script
(``rsbb_replay.hopf``) on that bag, the oracle of ``--rules 2019/2017/2017-11``.

Each goal: the first manual operation (0.4 s), the lookup 12 ms after its completion (the
``/item`` broadcast), ``Remove the positioner`` (0.4 s), the goal (requested 50 ms later, the
robot starts 0.2 s after the request, answers after 0.6-1.6 s). The answers are the truth plus
random errors (some beyond 1 m, some beyond pi). Kinds of goal:

``right``, ``wrong`` (class and instance wrong, large errors), ``int`` (x answered as an
integer), ``blank`` (a class with a trailing blank), ``timeout``, ``prep_timeout`` (the goal
times out before the robot starts), ``dropout`` (the positioner hidden when placed: the lookup
fails; 2019/2017: the referee is asked to move it, ``dropout2`` twice; November 2017: the lookup
succeeds once it is seen again), ``gap`` (the positioner unseen from 0.25 s before to 0.2 s
after the lookup: tf interpolates across), ``missing`` (no theta: the script dies), ``badnum``
(x is text: the script dies), and the stops, each ending the run: ``stop_mo1``, ``stop_lookup``,
``stop_mo3``, ``stop_mo2``, ``stop_prep``, ``stop_goal``, ``global_timeout`` (during a goal).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import yaml
from scipy.spatial.transform import Rotation

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
from tests.helpers.rsbb_replay import hopf as replay_hopf
from tests.helpers.rsbb_replay.fromlog import timeline_from_bag
from tests.helpers.rsbb_replay.world import ReplayResult, World, run_script

S = 1_000_000_000
MS = 1_000_000
T0 = 1_555_000_000 * S
TABLE = (1.0, 2.0, 0.75, 0.4)
GOAL_TIMEOUT_S = 4
NOISE = MocapNoise(sigma_m=2e-4, sigma_rad=5e-4)
VERSION = {"2019": "2bb8a41", "2017": "00e3106", "2017-11": "b5d91f4"}
STOPS = ("stop_mo1", "stop_lookup", "stop_mo3", "stop_mo2", "stop_prep", "stop_goal")


def items(n: int = 11) -> list[dict[str, Any]]:
    """``n`` items, classes a-c, each with its own offset on the positioner (some tilted)."""
    out = []
    for k in range(1, n + 1):
        cls = "abc"[(k - 1) % 3]
        yaw = -math.pi / 4 + 0.1 * k
        tilt = 0.05 if k % 4 == 0 else 0.0  # a tilted item: tf's yaw of its frame
        rot = [float(v) for v in Rotation.from_euler("ZX", [yaw, tilt]).as_quat()]
        out.append(
            {
                "class": cls,
                "description": f"Object {cls}{k}",
                "id": k,
                "instance": f"{cls}{k}",
                "rot": rot,
                "trans": [-0.14 + 0.01 * k, 0.02 * (k % 3), 0.03],
            }
        )
    return out


def params(with_items: bool = False) -> dict[str, Any]:
    out: dict[str, Any] = {"table_size": {"x": 1.0, "y": 1.5}, "goal_timeout": GOAL_TIMEOUT_S}
    if with_items:
        out["items"] = items()
    return out


def _quat(yaw: float) -> tuple[float, float, float, float]:
    return (0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2))


def _on_table(x: float, y: float, yaw: float) -> tuple[float, float, float, float]:
    tx, ty, tz, tyaw = TABLE
    c, s = math.cos(tyaw), math.sin(tyaw)
    return (tx + c * x - s * y, ty + s * x + c * y, tz + 0.02, tyaw + yaw)


def _place(item: dict[str, Any]) -> str:
    return (
        f"Place the positioner and the {item['description']} (id: {item['id']}, "
        f"instance: {item['instance']}) on the table"
    )


def _retry(item: dict[str, Any]) -> str:
    return (
        "The position of the positioner could not be acquired!\nPlace in a different "
        f"position the positioner and the {item['description']} (id: {item['id']}, "
        f"instance: {item['instance']}) on the table"
    )


@dataclass(frozen=True)
class HopfRun:
    """A generated run: its scenario, items and config."""

    scenario: RsbbScenario
    items: list[dict[str, Any]]
    params: dict[str, Any]
    version: str


def build(plan: Sequence[str], *, seed: int = 0, rules: str = "2019") -> HopfRun:
    """The scenario of ``plan`` (one kind per goal) for the script of ``rules``; a plan of
    fewer than ten goals without a stop ends with the referee's stop during the next goal's
    first manual operation (the script asks for ten)."""
    if len(plan) < 10 and not any(k in STOPS or k == "global_timeout" for k in plan):
        plan = [*plan, "stop_mo1"]
    rng = np.random.default_rng(seed)
    version = VERSION[rules]
    its = items()
    order = [int(k) for k in rng.permutation(len(its))[: len(plan)] + 1]
    by_id = {i["id"]: i for i in its}
    manual: list[ManualOperation] = []
    goals: list[Goal] = []
    casts: list[Broadcast] = []
    spans: list[tuple[int, int, tuple[float, float, float, float]]] = []
    t = T0 + 2 * S
    t_start = t - S
    end_kind, t_end = "end", 0
    for k, kind in enumerate(plan):
        item = by_id[order[k]]
        x, y, yaw = rng.uniform(0.1, 0.9), rng.uniform(0.1, 1.4), rng.uniform(-3.0, 3.0)
        pose = _on_table(x, y, yaw)
        placed = t + 400 * MS
        if kind == "stop_mo1":
            manual.append(ManualOperation(t + 100 * MS, None, _place(item)))
            end_kind, t_end = "stop", t + 300 * MS
            break
        manual.append(ManualOperation(t + 100 * MS, placed, _place(item)))
        lookup = placed + 12 * MS
        hidden = kind in ("dropout", "dropout2", "stop_lookup", "stop_mo3")
        if hidden and version == "b5d91f4" and kind != "stop_lookup":
            lookup = placed + 2500 * MS  # seen again: the unlimited attempts succeed
            spans.append((lookup - 300 * MS, lookup + 600 * MS, pose))
        elif hidden:
            if kind == "stop_lookup":
                end_kind, t_end = "stop", placed + 1500 * MS
                break
            tries = 2 if kind == "dropout2" else 1
            clock = placed
            for n in range(tries):
                request = clock + 3 * S + 5 * MS  # three failed 1 s attempts
                if kind == "stop_mo3":
                    manual.append(ManualOperation(request, None, _retry(item)))
                    end_kind, t_end = "stop", request + 300 * MS
                    break
                clock = request + 600 * MS
                manual.append(ManualOperation(request, clock, _retry(item), f"moved {n}"))
            if kind == "stop_mo3":
                break
            lookup = clock + 12 * MS
            spans.append((clock - 300 * MS, lookup + 600 * MS, pose))
        elif kind == "gap":
            spans.append((t + 100 * MS, lookup - 250 * MS, pose))
            spans.append((lookup + 200 * MS, lookup + 600 * MS, pose))
        else:
            spans.append((t + 100 * MS, lookup + 600 * MS, pose))
        trans, rot = item["trans"], item["rot"]
        casts.append(Broadcast(lookup, "/item", "/positioner_origin", tuple(trans), tuple(rot)))
        removed = lookup + 400 * MS
        if kind == "stop_mo2":
            manual.append(ManualOperation(lookup + 30 * MS, None, "Remove the positioner"))
            end_kind, t_end = "stop", lookup + 200 * MS
            break
        manual.append(ManualOperation(lookup + 30 * MS, removed, "Remove the positioner"))
        request = removed + 50 * MS
        start = request + 200 * MS
        if kind == "stop_prep":
            goals.append(Goal(request, None, None, "{}\n", "result"))
            end_kind, t_end = "stop", request + 100 * MS
            break
        if kind in ("stop_goal", "global_timeout"):
            goals.append(Goal(request, start, None, "{}\n", "result"))
            end_kind = "stop" if kind == "stop_goal" else "global_timeout"
            t_end = start + 500 * MS
            break
        if kind == "timeout":
            end = request + GOAL_TIMEOUT_S * S
            goals.append(Goal(request, start, end, "{}\n", "timeout"))
        elif kind == "prep_timeout":
            end = request + GOAL_TIMEOUT_S * S
            goals.append(Goal(request, None, end, "{}\n", "timeout"))
        else:
            end = start + round(rng.uniform(0.6, 1.6) * S)
            goals.append(Goal(request, start, end, "{}\n", "result", _answer(kind, item, rng)))
        t = end + 50 * MS
        t_end = t + 100 * MS
    table = [(t_start, t_end + S, TABLE)]
    if not spans:  # the run stopped before a positioner was seen: a glimpse at the start
        spans.append((t_start, t_start + 100 * MS, _on_table(0.5, 0.5, 0.0)))
    sc = RsbbScenario(
        code="HOPF",
        team="teamA",
        run=1,
        season="2017" if rules.startswith("2017") else "2019",
        t_connect_ns=T0,
        t_start_ns=t_start,
        t_end_ns=t_end,
        end=end_kind,
        t_disconnect_ns=t_end + S,
        manual_operations=tuple(manual),
        goals=tuple(goals),
        broadcasts=tuple(casts),
        saves=(Save(t_end, {}),),
        params=params(with_items=version == "b5d91f4"),
        bodies=(_body("table_origin", table, rng), _body("positioner_origin", spans, rng)),
    )
    return HopfRun(sc, its, params(with_items=version == "b5d91f4"), version)


def _answer(kind: str, item: dict[str, Any], rng: np.random.Generator) -> str:
    """The robot's answer: the truth is not known here, so a pose on the table (the script
    compares; the tests compare the script with ertools, not with the truth)."""
    x, y, theta = rng.uniform(0.0, 1.0), rng.uniform(0.0, 1.5), rng.uniform(-7.0, 7.0)
    if kind == "wrong":
        x += 1.5
    answer: dict[str, Any] = {
        "x": x,
        "y": y,
        "theta": theta,
        "class": item["class"] if kind != "wrong" else "zz",
        "instance": item["instance"] if kind != "wrong" else "zz1",
    }
    if kind == "int":
        answer["x"] = 1
    if kind == "blank":
        answer["class"] = item["class"] + " "
    if kind == "missing":
        del answer["theta"]
    if kind == "badnum":
        answer["x"] = "abc"
    return str(yaml.safe_dump(answer, default_flow_style=True, width=1000)).strip()


def _body(
    name: str, spans: list[tuple[int, int, tuple[float, float, float, float]]], rng: Any
) -> Body:
    times, xyz, quat = [], [], []
    for start, end, (x, y, z, yaw) in spans:
        t = frame_times(start, (end - start) / S, rate_hz=100.0)
        times.append(t)
        xyz.append(np.tile([x, y, z], (t.size, 1)))
        quat.append(np.tile(_quat(yaw), (t.size, 1)))
    pub = simulate_mocap(
        np.concatenate(times), np.concatenate(xyz), np.concatenate(quat), rng=rng, noise=NOISE
    )
    return Body(name, pub)


def write(folder: Path, run: HopfRun) -> tuple[Path, Path, Path]:
    """The run bag, its items file and its config, in ``folder`` (flat: the side files beside
    the bag)."""
    paths = write_rsbb_run(folder, run.scenario)
    bag_dir = paths.bag.parent
    items_path = bag_dir / "items_with_pose.yaml"
    items_path.write_text(yaml.safe_dump({"items": run.items}), encoding="utf-8")
    config = bag_dir / "HOPF.yaml"
    config.write_text(yaml.safe_dump(run.params), encoding="utf-8")
    return paths.bag, items_path, config


def replay(bag: Path, run: HopfRun) -> ReplayResult:
    """The script at ``run.version`` replayed on the bag (the oracle)."""
    tl = timeline_from_bag(bag, run.params, {"items": run.items})
    return run_script(World(tl), lambda w: replay_hopf.execute(w, run.version))
