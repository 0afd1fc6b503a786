"""Scenario ``hopf``: a HOPF (FBM1@Home 2019) run on the RSBB, ten items on a turned table.

The table (marker set ``table_origin``) stands still, turned 0.4 rad; for each goal the referee
places the positioner (``positioner_origin``) and an item on it (first manual operation,
naming the item drawn), the script looks the item up (its ``/item`` broadcast, 12 ms after
the placement was confirmed), the referee removes the positioner (second manual operation:
the positioner leaves the tracked area), the goal is sent and the robot answers class,
instance and the item's (x, y, theta) in the table frame (theta in radians, as in 2019).

What happens (goals numbered from 1, as the script's ``i``):

- goal 3: the positioner's markers are hidden when it is placed (a mocap dropout): the
  script's three 1 s attempts fail, it asks the referee to move the positioner (``The
  position of the positioner could not be acquired!...``), the lookup after that succeeds;
- goal 4: right class, wrong instance; goal 5: times out (the config's ``goal_timeout`` is
  3 s here, to keep the log short);
- goal 6: theta 3.0 rad off; goal 7: 1.08 m off and the wrong class (the 2019 script's pose
  score goes below 0.5 - 0.54; ertools clips the translation at 1 m);
- goal 9: the class answered with a trailing blank (``"a "``): wrong for the script, right for
  ertools (names compared without blanks);
- goal 10: the referee stops the benchmark while the robot works on it.

To keep the bag small (~0.4 MB) the table is published only while the positioner stands on it
(the RSBB's mocap streamed it throughout): the lookups and the noise estimate need no more.

The run is written in the RSBB layout: ``rsbb_logs/HOPF/simbot/run_1_<date>.bag``,
``results/HOPF/simbot/result_run_1_<date>.yaml``, ``rsbb_etc/objects_informations/
items_with_pose.yaml`` and ``rsbb_bmbox/scripts/benchmark_configs/HOPF.yaml``, so that
``ertools score hopf BAG`` finds its side files. The live score (and the result file) are the
2019 script's score computed here as the RSBB did, the item's pose from the published mocap at
the ``/item`` broadcast (tf's interpolation): ``--rules 2019`` agrees with it field for field.

Answers (``expected``; in ``<folder>.answers.yaml`` beside the layout folder, not in it),
computed here from the noiseless truth in the plane (the table, the
positioner and the item turn about z only): per goal the item's pose in the table frame
(table^-1 * positioner * item), the answer, the errors, t, r and the pose score under the 2019
script's rules (t unclipped, one wrap step, exact names) and ertools' (t clipped at 1 m,
full wrap, names stripped); the totals: 2019 divides by the 10 goals begun, ertools by the 9
whose outcome is known (the stopped goal is not counted).
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from ertools.atomic import write_text
from ertools.simulator.answers import RunAnswers, tol, write_layout_answers
from ertools.simulator.mocap import MocapNoise, frame_times, simulate_mocap
from ertools.simulator.rsbb import TF_STAMP_LAG_NS, write_rsbb_run
from ertools.simulator.rsbb_scenario import (
    Body,
    Broadcast,
    Goal,
    ManualOperation,
    Save,
    stopped_run,
)
from ertools.simulator.tf_lookup import Link
from ertools.simulator.tf_lookup import lookup as tf_lookup

S = 1_000_000_000
MS = 1_000_000
T0 = 1_555_000_000 * S  # 2019-04-11 16:26:40 UTC
TEAM = "simbot"
GOAL_TIMEOUT_S = 3
PARAMS = {"table_size": {"x": 1.0, "y": 1.5}, "goal_timeout": GOAL_TIMEOUT_S}
TABLE = (1.0, 2.0, 0.75, 0.4)  # x, y, z, yaw in the testbed frame
ITEM_OFFSET = (-0.14, 0.0, 0.0, -math.pi / 4)  # the item on the positioner: x, y, z, yaw
NOISE = MocapNoise(sigma_m=2e-4, sigma_rad=5e-4)
#: Per goal: the positioner on the table (x, y, yaw), the answer's errors (dx, dy, dtheta),
#: what happens. Goal 3's second placement (after the dropout) is PLACE_AGAIN.
PLAN: tuple[tuple[tuple[float, float, float], tuple[float, float, float], str], ...] = (
    ((0.30, 0.40, 0.2), (0.01, -0.02, 0.05), "right"),
    ((0.70, 0.30, -0.6), (0.03, 0.01, -0.1), "right"),
    ((0.50, 1.00, 1.0), (0.0, 0.02, 0.02), "dropout"),
    ((0.20, 1.20, 0.0), (-0.05, 0.04, 0.3), "instance"),
    ((0.80, 0.90, 2.0), (0.0, 0.0, 0.0), "timeout"),
    ((0.40, 0.60, -1.5), (0.02, 0.0, 3.0), "right"),
    ((0.60, 0.50, 0.7), (0.6, -0.9, 0.0), "class"),
    ((0.30, 1.30, -0.3), (0.0, 0.0, 0.0), "right"),
    ((0.75, 0.20, 0.9), (0.1, 0.1, -0.2), "blank"),
    ((0.45, 0.75, 0.1), (0.0, 0.0, 0.0), "stop"),
)
PLACE_AGAIN = (0.55, 0.95, 1.1)
ORDER = (3, 7, 1, 10, 5, 2, 11, 6, 4, 9)  # the items drawn (ids)
DROPOUT_S = 3.5  # goal 3: the positioner hidden this long after it was placed
ANSWER_S = (0.9, 0.7, 1.1, 0.8, 0.0, 1.0, 0.6, 0.7, 1.2, 0.0)  # the robot's time per goal
STOP_AFTER_S = 0.7  # goal 10: the referee's stop, after the robot started


def _items() -> list[dict[str, Any]]:
    """Eleven items, classes a-c, as the December 2017 file had them (one positioner
    transform for all)."""
    out = []
    yaw = ITEM_OFFSET[3]
    for k in range(1, 12):
        cls = "abc"[(k - 1) // 4]
        out.append(
            {
                "class": cls,
                "description": f"Red object {cls}{k}",
                "id": k,
                "instance": f"{cls}{k}",
                "rot": [0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2)],
                "trans": [ITEM_OFFSET[0], ITEM_OFFSET[1], ITEM_OFFSET[2]],
            }
        )
    return out


def _place_text(item: dict[str, Any]) -> str:
    return (
        f"Place the positioner and the {item['description']} (id: {item['id']}, "
        f"instance: {item['instance']}) on the table"
    )


def _world(on_table: tuple[float, float, float]) -> tuple[float, float, float, float]:
    """The positioner (x, y, z, yaw) in the testbed frame, placed on the table."""
    tx, ty, tz, tyaw = TABLE
    c, s = math.cos(tyaw), math.sin(tyaw)
    x, y, yaw = on_table
    return (tx + c * x - s * y, ty + s * x + c * y, tz + 0.02, tyaw + yaw)


def _truth(on_table: tuple[float, float, float]) -> tuple[float, float, float]:
    """The item (x, y, yaw) in the table frame: the positioner's pose composed with the
    item's offset, in the plane."""
    x, y, yaw = on_table
    ox, oy, _, oyaw = ITEM_OFFSET
    c, s = math.cos(yaw), math.sin(yaw)
    return (x + c * ox - s * oy, y + s * ox + c * oy, yaw + oyaw)


def _quat(yaw: float) -> tuple[float, float, float, float]:
    return (0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2))


def _body(
    name: str, spans: list[tuple[int, int, tuple[float, float, float, float]]], rng: Any
) -> Body:
    """A body tracked only during ``spans`` (start, end, pose), still in each."""
    times, xyz, quat = [], [], []
    for start, end, (x, y, z, yaw) in spans:
        t = frame_times(start, (end - start) / S)
        times.append(t)
        xyz.append(np.tile([x, y, z], (t.size, 1)))
        quat.append(np.tile(_quat(yaw), (t.size, 1)))
    pub = simulate_mocap(
        np.concatenate(times), np.concatenate(xyz), np.concatenate(quat), rng=rng, noise=NOISE
    )
    return Body(name, pub)


def _one_wrap(w: float) -> float:
    if w > math.pi:
        w -= 2 * math.pi
    if w < -math.pi:
        w += 2 * math.pi
    return w


def _full_wrap(w: float) -> float:
    return (w + math.pi) % (2 * math.pi) - math.pi


def _terms(err: tuple[float, float, float], *, clip: bool, full: bool) -> dict[str, float]:
    w = _full_wrap(err[2]) if full else _one_wrap(err[2])
    t = math.hypot(err[0], err[1])
    t = min(t, 1.0) if clip else t
    r = min(abs(w) / math.pi, 1.0)
    return {"t": t, "r": r, "w": w, "pose_score": 1 - t / 2 - r / 2}


def _answer_text(answer: dict[str, Any]) -> str:
    return str(yaml.safe_dump(answer, default_flow_style=True, width=1000)).strip()


def _live_saves(
    per_goal: list[dict[str, Any]],
    done: list[tuple[dict[str, Any], dict[str, Any], int, int, int]],
    table: Link,
    positioner: Link,
) -> list[Save]:
    """The 2019 script's saves after each goal (fbm1_objects_perception.py l. 230-320): the
    item's pose as tf gave it at the ``/item`` broadcast, from the published mocap."""
    score: dict[str, Any] = {}
    sums = {"class": 0.0, "instance": 0.0, "pose": 0.0}
    saves: list[Save] = []
    exec_ns = 0  # a sum of genpy Durations, in seconds when saved
    for entry, (item, answer, when, end, seg) in zip(per_goal, done, strict=True):
        i = entry["goal"]
        timeout = entry["timeout"]
        g: dict[str, Any] = {
            "timeout": timeout,
            "completed": "answer" in entry,
            "segment_time": entry["segment_time"],
        }
        score[f"goal_{i}"] = g
        exec_ns += seg
        if "answer" in entry:
            at = tf_lookup(positioner, when, (item["trans"], item["rot"]), table)
            truth = (at.xyz[0], at.xyz[1], at.yaw)
            errors = (answer["x"] - truth[0], answer["y"] - truth[1], answer["theta"] - truth[2])
            s19 = _terms(errors, clip=False, full=False)
            cls_ok = answer["class"] == item["class"]
            inst_ok = answer["instance"] == item["instance"]
            sums["class"] += cls_ok
            sums["instance"] += inst_ok
            sums["pose"] += s19["pose_score"]
            g.update(
                {
                    "item_acquired": {
                        "pose": list(truth),
                        "pose_units": ["m", "m", "rad"],
                        "class": item["class"],
                        "instance": item["instance"],
                    },
                    "item_received": {
                        "pose": [answer["x"], answer["y"], answer["theta"]],
                        "pose_units": ["m", "m", "rad"],
                        "class": answer["class"],
                        "instance": answer["instance"],
                    },
                    "partial_score": {
                        "pose_score": s19["pose_score"],
                        "pose_error_translation_score": s19["t"],
                        "pose_error_translation_score_unit": "pure number",
                        "pose_error_rotation_score": s19["r"],
                        "pose_error_rotation_score_unit": "pure number",
                        "pose_error": [errors[0], errors[1], s19["w"]],
                        "pose_error_units": ["m", "m", "rad"],
                        "is_class_correct": cls_ok,
                        "is_instance_correct": inst_ok,
                    },
                }
            )
        score["class_accuracy"] = sums["class"] / i
        score["instance_accuracy"] = sums["instance"] / i
        score["pose_score"] = sums["pose"] / i
        score["execution_time"] = _to_sec(exec_ns)
        saves.append(Save(end + 2 * MS, _copy(score)))
    return saves


def _track(body: Body) -> Link:
    """The body's ``/tf`` link as the bag holds it (the tf copy's stamps and arrivals)."""
    pub = body.published
    return Link(pub.t_header_ns + TF_STAMP_LAG_NS, pub.xyz, pub.quat_xyzw)


def generate(outdir: Path, *, seed: int) -> list[Path]:
    """Write the run (bag, result file, side files) into ``outdir`` and its answers beside it
    (:func:`~ertools.simulator.answers.write_layout_answers`)."""
    rng = np.random.default_rng(seed)
    items = {i["id"]: i for i in _items()}
    manual: list[ManualOperation] = []
    goals: list[Goal] = []
    broadcasts: list[Broadcast] = []
    spans: list[tuple[int, int, tuple[float, float, float, float]]] = []
    per_goal: list[dict[str, Any]] = []
    done: list[tuple[dict[str, Any], dict[str, Any], int, int, int]] = []  # ..., lookup, end, seg
    exec_ns = 0
    t = T0 + 2 * S
    t_start = t - S
    stop_ns = 0
    for k, (on_table, err, what) in enumerate(PLAN):
        i = k + 1
        item = items[ORDER[k]]
        place = _place_text(item)
        placed = t + 500 * MS
        manual.append(ManualOperation(t + 100 * MS, placed, place))
        if what == "dropout":
            # hidden from the placement; three attempts of 1 s fail; the referee moves it
            retry = placed + 3 * S + 4 * MS
            again = retry + 800 * MS
            spans.append((retry + 300 * MS, again + 600 * MS, _world(PLACE_AGAIN)))
            manual.append(
                ManualOperation(
                    retry,
                    again,
                    "The position of the positioner could not be acquired!\nPlace in a "
                    f"different position the positioner and the {item['description']} "
                    f"(id: {item['id']}, instance: {item['instance']}) on the table",
                    "moved",
                )
            )
            placed, on_table = again, PLACE_AGAIN
        else:
            spans.append((t + 100 * MS, placed + 600 * MS, _world(on_table)))
        lookup = placed + 12 * MS
        ox, oy, oz, oyaw = ITEM_OFFSET
        broadcasts.append(
            Broadcast(lookup, "/item", "/positioner_origin", (ox, oy, oz), _quat(oyaw))
        )
        removed = lookup + 430 * MS
        manual.append(ManualOperation(lookup + 30 * MS, removed, "Remove the positioner"))
        request = removed + 50 * MS
        start = request + 200 * MS
        truth = _truth(on_table)
        answer_class = item["class"]
        if what == "class":
            answer_class = "b" if item["class"] != "b" else "c"
        elif what == "blank":
            answer_class = item["class"] + " "
        answer = {
            "x": truth[0] + err[0],
            "y": truth[1] + err[1],
            "theta": truth[2] + err[2],
            "class": answer_class,
            "instance": item["instance"] if what != "instance" else "a99",
        }
        entry: dict[str, Any] = {"goal": i, "item": item["id"], "happens": what}
        if what == "timeout":
            end = request + GOAL_TIMEOUT_S * S
            goals.append(Goal(request, start, end, "{}\n", "timeout"))
            timeout, completed = True, False
        elif what == "stop":
            stop_ns = start + round(STOP_AFTER_S * S)
            goals.append(Goal(request, start, None, "{}\n", "result"))
            end = stop_ns
            timeout, completed = None, False
        else:
            end = start + round(ANSWER_S[k] * S)
            goals.append(Goal(request, start, end, "{}\n", "result", _answer_text(answer)))
            timeout, completed = False, True
        seg = end - start
        exec_ns += seg
        entry.update({"truth": list(truth), "segment_time": _to_sec(seg), "timeout": timeout})
        if completed:
            errors = (answer["x"] - truth[0], answer["y"] - truth[1], answer["theta"] - truth[2])
            s19 = _terms(errors, clip=False, full=False)
            now = _terms(errors, clip=True, full=True)
            inst_ok = answer["instance"] == item["instance"]
            entry.update(
                {
                    "answer": [answer["x"], answer["y"], answer["theta"]],
                    "class_ok_2019": answer["class"] == item["class"],
                    "instance_ok_2019": inst_ok,
                    "class_ok": answer["class"].strip() == item["class"],
                    "instance_ok": inst_ok,
                    "pose_score_2019": s19["pose_score"],
                    "pose_score": now["pose_score"],
                    "translation": now["t"],
                    "rotation": now["r"],
                }
            )
        per_goal.append(entry)
        done.append((item, answer, lookup, end, seg))
        if what == "stop":
            break
        t = end + 50 * MS
    table_spans = [(a, b, (TABLE[0], TABLE[1], TABLE[2], TABLE[3])) for a, b, _ in spans]
    table_body = _body("table_origin", table_spans, rng)
    positioner = _body("positioner_origin", spans, rng)
    saves = _live_saves(per_goal, done, _track(table_body), _track(positioner))
    score = saves[-1].score
    saves.append(Save(stop_ns + 5 * MS, _copy(score)))
    sc = stopped_run(
        "HOPF",
        TEAM,
        (T0, t_start, stop_ns),
        manual_operations=manual,
        goals=goals,
        broadcasts=broadcasts,
        saves=saves,
        params=PARAMS,
        bodies=(table_body, positioner),
    )
    paths = write_rsbb_run(outdir, sc, compression="bz2")
    items_path = outdir / "rsbb_etc" / "objects_informations" / "items_with_pose.yaml"
    config_path = outdir / "rsbb_bmbox" / "scripts" / "benchmark_configs" / "HOPF.yaml"
    for path, data in ((items_path, {"items": list(items.values())}), (config_path, PARAMS)):
        path.parent.mkdir(parents=True, exist_ok=True)
        write_text(path, yaml.safe_dump(data, default_flow_style=None))
    run = RunAnswers(
        paths.bag,
        parameters={
            "team": TEAM,
            "table": list(TABLE),
            "item_offset": list(ITEM_OFFSET),
            "sigma_m": NOISE.sigma_m,
            "sigma_rad": NOISE.sigma_rad,
            "goal_timeout": GOAL_TIMEOUT_S,
        },
        truth={"order": list(ORDER), "goals": per_goal},
        expected=_expected(per_goal, exec_ns),
        tolerance={
            "pose": tol(
                2e-3,
                "mocap noise of the two bodies (0.2 mm per axis each: 0.3 mm; 0.5 mrad of yaw "
                "each: 0.7 mrad; the table's yaw noise over the item's up to 1.4 m from its "
                "origin: 0.7 mm), about 1 mm in all: 2 mm is over 2.5 sigma of the worst goal; "
                "lookup time: none, both bodies stand still around the /item lookup",
            ),
            "execution_time": tol(1e-9, "the RefBox's messages are written at the given times"),
            "accuracy": tol(1e-12, "counts divided by counts"),
        },
    )
    # beside the layout, not in it: rescore would list it as a file that is not a log
    answers = write_layout_answers(outdir, [run], benchmark="hopf", scenario="hopf", seed=seed)
    return [paths.bag, paths.result, items_path, config_path, answers]


def _to_sec(ns: int) -> float:
    secs, nsecs = divmod(int(ns), S)
    return float(secs) + float(nsecs) / 1e9


def _copy(score: dict[str, Any]) -> dict[str, Any]:
    return yaml.safe_load(yaml.safe_dump(score))  # type: ignore[no-any-return]


def _expected(per_goal: list[dict[str, Any]], exec_ns: int) -> dict[str, Any]:
    """The totals under both rules, from the noiseless truth."""
    known = [g for g in per_goal if g["timeout"] is not None]
    scored = [g for g in known if "pose_score" in g]
    n = len(known)
    return {
        "ertools": {
            "class_accuracy": sum(g["class_ok"] for g in scored) / n,
            "instance_accuracy": sum(g["instance_ok"] for g in scored) / n,
            "pose_score": sum(g["pose_score"] for g in scored) / n,
            "execution_time": _to_sec(exec_ns),
            "counted": n,
        },
        "rules_2019": {  # divided by the goals begun
            "class_accuracy": sum(g["class_ok_2019"] for g in scored) / len(per_goal),
            "instance_accuracy": sum(g["instance_ok_2019"] for g in scored) / len(per_goal),
            "pose_score": sum(g["pose_score_2019"] for g in scored) / len(per_goal),
            "execution_time": _to_sec(exec_ns),
            "counted": len(per_goal),
        },
    }
