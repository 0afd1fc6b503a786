"""Scenario ``hppf``: an HPPF (FBM4@Home 2019) run on the RSBB, five people to recognise.

For each goal a person enters the area wearing the cap with markers (``actor_markerset``;
first manual operation, naming the person drawn), the script checks that the cap is tracked
(a ``/person`` broadcast 12 ms after the entry), sends the goal, and looks the cap up again
12 ms after the answer (the ground truth). What happens (goals numbered from 0, as the
script's):

- goal 0, Joe: answered ``"joe "`` (a trailing blank): not recognised by the script
  (``lower()`` keeps the blank), recognised by ertools (names compared without blanks);
- goal 1, Alice: the cap's markers are hidden when she enters (a mocap dropout): three failed
  checks, the referee is asked again (``Could not get Alice's pose...``), then answered;
- goal 2, first Brad: answered, but the cap is lost after the answer (three failed lookups): the
  script restarts the goal, Brad goes back to the list, and the new draw brings Peter, who is
  answered;
- goal 3, Michael: the goal times out (``goal_timeout`` 3 s here, to keep the log short);
- goal 4, Brad again: the referee stops the benchmark while the robot works on it.

The run is written in the RSBB layout: ``rsbb_logs/HPPF/simbot/run_1_<date>.bag``,
``results/HPPF/simbot/result_run_1_<date>.yaml`` and
``rsbb_bmbox/scripts/benchmark_configs/HPPF.yaml``. The cap is published only while a person
stands in the area. The live score and the result file are the 2019 script's score computed
here as the RSBB did, the cap's pose from the published mocap at the ``/person`` broadcast
after the answer: ``--rules 2019`` agrees with them field for field.

Answers (``expected``; in ``<folder>.answers.yaml`` beside the layout folder, not in it),
from the noiseless truth: each goal's position error (the answer
minus where the person stands), the name right under both readings, and the totals: Distance
error over the three goals detected, Recognized persons and its percentage over the five
people (``40.0%`` for the script, ``60.0%`` for ertools), execution_time (the restarted
goal's time taken out).
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from ertools.atomic import write_text
from ertools.frozen_dataclass import frozen_dataclass
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
from ertools.simulator.tf_lookup import Link, lookup

S = 1_000_000_000
MS = 1_000_000
T0 = 1_555_003_600 * S  # 2019-04-11 17:26:40 UTC
TEAM = "simbot"
GOAL_TIMEOUT_S = 3.0
PEOPLE = ["Joe", "Peter", "Alice", "Michael", "Brad"]
PARAMS = {"people": PEOPLE, "goal_timeout": GOAL_TIMEOUT_S}
NOISE = MocapNoise(sigma_m=2e-4, sigma_rad=5e-4)
IDENTITY = ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0))
ENTER = (
    "{} should enter the target area wearing a cap with MoCap markers, and place him/herself "
    "in an arbitrary position."
)
RETRY = (
    "Could not get {}'s pose. Make sure (s)he is inside the designated area and wearing the "
    "markerset cap."
)
#: The passes: goal number, person, where (x, y; two decimals, far from the texts' rounding),
#: the answer's error (dx, dy), the name answered, what happens.
PASSES = (
    (0, "Joe", (1.2, -0.8), (0.12, 0.05), "joe ", "right"),
    (1, "Alice", (-0.5, 1.1), (-0.07, 0.2), "Alice", "dropout"),
    (2, "Brad", (0.3, 0.4), (0.1, 0.1), "Brad", "restart"),
    (2, "Peter", (2.1, 0.6), (0.0, -0.31), "peter", "right"),
    (3, "Michael", (-1.4, -1.3), (0.0, 0.0), "", "timeout"),
    (4, "Brad", (0.9, -1.7), (0.0, 0.0), "", "stop"),
)
ANSWER_S = 0.9  # the robot's time per answered goal
STOP_AFTER_S = 0.7


def _body(spans: list[tuple[int, int, tuple[float, float]]], rng: Any) -> Body:
    times, xyz = [], []
    for start, end, (x, y) in spans:
        t = frame_times(start, (end - start) / S)
        times.append(t)
        xyz.append(np.tile([x, y, 1.75], (t.size, 1)))
    t_all = np.concatenate(times)
    quat = np.tile([0.0, 0.0, 0.0, 1.0], (t_all.size, 1))
    return Body(
        "actor_markerset", simulate_mocap(t_all, np.concatenate(xyz), quat, rng=rng, noise=NOISE)
    )


def _to_sec(ns: int) -> float:
    secs, nsecs = divmod(int(ns), S)
    return float(secs) + float(nsecs) / 1e9


def _text(xy: tuple[float, float]) -> str:
    return f"({xy[0]:.2f}, {xy[1]:.2f})"


@frozen_dataclass
class _Events:
    """The run's events and saves, and the answers' noiseless truth."""

    manual: list[ManualOperation]
    goals: list[Goal]
    casts: list[Broadcast]
    spans: list[tuple[int, int, tuple[float, float]]]
    saves: list[Save]
    score: dict[str, Any]
    truth_rows: list[dict[str, Any]]
    errors: list[float]
    recognized: dict[str, int]
    exec_ns: int
    t_start: int
    stop_ns: int


def _track(body: Body) -> Link:
    """The cap's ``/tf`` link as the bag holds it (the tf copy's stamps and arrivals)."""
    pub = body.published
    return Link(pub.t_header_ns + TF_STAMP_LAG_NS, pub.xyz, pub.quat_xyzw)


def _events(cap: Link | None) -> _Events:
    """The passes in order. The live score takes the cap's pose as tf gave it at the
    ``/person`` broadcast after the answer (``cap``; None: where the person stands)."""
    manual: list[ManualOperation] = []
    goals: list[Goal] = []
    casts: list[Broadcast] = []
    spans: list[tuple[int, int, tuple[float, float]]] = []
    saves: list[Save] = []
    score: dict[str, Any] = {}
    truth_rows: list[dict[str, Any]] = []
    errors: list[float] = []
    live_errors: list[float] = []
    recognized = {"2019": 0, "ertools": 0}
    exec_ns = 0
    t = T0 + 2 * S
    t_start = t - S
    stop_ns = 0
    for index, person, where, err, name, what in PASSES:
        g = f"goal_{index}"
        score[g] = {}
        entered = t + 500 * MS
        manual.append(ManualOperation(t + 100 * MS, entered, ENTER.format(person)))
        seen_from, clock = t + 100 * MS, entered
        if what == "dropout":
            retry = entered + 3 * S + 5 * MS
            clock = retry + 600 * MS
            manual.append(ManualOperation(retry, clock, RETRY.format(person), "ok"))
            seen_from = clock - 300 * MS
        check = clock + 12 * MS
        casts.append(Broadcast(check, "/person", "/actor_markerset", *IDENTITY))
        request = check + 50 * MS
        start = request + 200 * MS
        row: dict[str, Any] = {
            "goal": index,
            "person": person,
            "where": list(where),
            "happens": what,
        }
        if what == "timeout":
            end = request + round(GOAL_TIMEOUT_S * S)
            goals.append(Goal(request, start, end, "{}\n", "timeout"))
            spans.append((seen_from, end + 300 * MS, where))
            exec_ns += end - start
            score[g] = {
                "segment_time [s]": _to_sec(end - start),
                "timeout": True,
                "completed": False,
                "detected": False,
            }
            score["execution_time"] = _to_sec(exec_ns)
            saves.append(Save(end + 2 * MS, _copy(score)))
            truth_rows.append({**row, "segment_time": _to_sec(end - start)})
            t = end + 350 * MS
            continue
        if what == "stop":
            goals.append(Goal(request, start, None, "{}\n", "result"))
            stop_ns = start + round(STOP_AFTER_S * S)
            spans.append((seen_from, stop_ns + 300 * MS, where))
            exec_ns += stop_ns - start
            score[g] = {
                "segment_time [s]": _to_sec(stop_ns - start),
                "timeout": None,
                "completed": False,
                "detected": False,
            }
            score["execution_time"] = _to_sec(exec_ns)
            saves.append(Save(stop_ns + 2 * MS, _copy(score)))
            truth_rows.append({**row, "segment_time": _to_sec(stop_ns - start)})
            break
        end = start + round(ANSWER_S * S)
        said = (where[0] + err[0], where[1] + err[1])
        answer = {"x": said[0], "y": said[1], "theta": 0.5, "person_name": name}
        goals.append(Goal(request, start, end, "{}\n", "result", _flow(answer)))
        if what == "restart":  # the cap lost after the answer: the lookups fail, goal again
            spans.append((seen_from, check + 200 * MS, where))
            truth_rows.append({**row, "restarted": True})
            t = end + 3 * S + 50 * MS
            continue
        truth = end + 12 * MS
        casts.append(Broadcast(truth, "/person", "/actor_markerset", *IDENTITY))
        spans.append((seen_from, truth + 300 * MS, where))
        exec_ns += end - start
        error = math.hypot(err[0], err[1])
        errors.append(error)
        seen = where
        if cap is not None:
            at = lookup(cap, truth, IDENTITY)
            seen = (at.xyz[0], at.xyz[1])
        x_err, y_err = said[0] - seen[0], said[1] - seen[1]
        live_errors.append(math.sqrt(x_err**2 + y_err**2))  # l. 196 of the script
        ok_2019 = name.lower() == person.lower()
        ok = name.strip().lower() == person.lower()
        recognized["2019"] += ok_2019
        recognized["ertools"] += ok
        score[g] = {
            "segment_time [s]": _to_sec(end - start),
            "timeout": False,
            "completed": True,
            "detected": True,
            "recognized": ok_2019,
            "position_error": live_errors[-1],
            "ground-truth person position": _text(seen),
            "robot-estimated person position": _text(said),
        }
        score["Recognized persons"] = recognized["2019"]
        score["% Recognized persons"] = f"{round(recognized['2019'] / len(PEOPLE) * 100, 2)}%"
        score["Distance error"] = sum(live_errors) / len(live_errors)
        score["execution_time"] = _to_sec(exec_ns)
        saves.append(Save(truth + 2 * MS, _copy(score)))
        truth_rows.append(
            {**row, "position_error": error, "recognized_2019": ok_2019, "recognized": ok}
        )
        t = truth + 350 * MS
    return _Events(
        manual,
        goals,
        casts,
        spans,
        saves,
        score,
        truth_rows,
        errors,
        recognized,
        exec_ns,
        t_start,
        stop_ns,
    )


def generate(outdir: Path, *, seed: int) -> list[Path]:
    """Write the run (bag, result file, config) into ``outdir`` and its answers beside it
    (:func:`~ertools.simulator.answers.write_layout_answers`)."""
    rng = np.random.default_rng(seed)
    cap = _body(_events(None).spans, rng)  # the spans do not depend on the cap's noise
    ev = _events(_track(cap))
    manual, goals, casts, saves, score = ev.manual, ev.goals, ev.casts, ev.saves, ev.score
    truth_rows, errors, recognized, exec_ns = ev.truth_rows, ev.errors, ev.recognized, ev.exec_ns
    t_start, stop_ns = ev.t_start, ev.stop_ns
    sc = stopped_run(
        "HPPF",
        TEAM,
        (T0, t_start, stop_ns),
        manual_operations=manual,
        goals=goals,
        broadcasts=casts,
        saves=(*saves, Save(stop_ns + 5 * MS, _copy(score))),
        params=PARAMS,
        bodies=(cap,),
    )
    paths = write_rsbb_run(outdir, sc, compression="bz2")
    config = outdir / "rsbb_bmbox" / "scripts" / "benchmark_configs" / "HPPF.yaml"
    config.parent.mkdir(parents=True, exist_ok=True)
    write_text(config, yaml.safe_dump(PARAMS, default_flow_style=None))
    n = len(PEOPLE)
    run = RunAnswers(
        paths.bag,
        parameters={"team": TEAM, "people": PEOPLE, "sigma_m": NOISE.sigma_m},
        truth={"passes": truth_rows},
        expected={
            "ertools": {
                "Recognized persons": recognized["ertools"],
                "% Recognized persons": f"{round(recognized['ertools'] / n * 100, 2)}%",
                "Distance error": sum(errors) / len(errors),
                "execution_time": _to_sec(exec_ns),
            },
            "rules_2019": {
                "Recognized persons": recognized["2019"],
                "% Recognized persons": f"{round(recognized['2019'] / n * 100, 2)}%",
                "Distance error": sum(errors) / len(errors),
                "execution_time": _to_sec(exec_ns),
            },
        },
        tolerance={
            "position": tol(
                1e-3,
                "the cap's mocap noise, 0.2 mm per axis, moves a position error by 0.2 mm "
                "(sigma): 1 mm is 5 sigma; lookup time: none, the person stands still around "
                "the /person lookup",
            ),
            "execution_time": tol(1e-9, "the RefBox's messages are written at the given times"),
        },
    )
    # beside the layout, not in it: rescore would list it as a file that is not a log
    answers = write_layout_answers(outdir, [run], benchmark="hppf", scenario="hppf", seed=seed)
    return [paths.bag, paths.result, config, answers]


def _flow(answer: dict[str, Any]) -> str:
    return str(yaml.safe_dump(answer, default_flow_style=True, width=1000)).strip()


def _copy(score: dict[str, Any]) -> dict[str, Any]:
    return yaml.safe_load(yaml.safe_dump(score))  # type: ignore[no-any-return]
