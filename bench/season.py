"""A generated season for `make bench`: several competition days, more teams, >= 100 executions.

Built on the sample competition (:mod:`ertools.samples.competition`): the same simulators
(``simulate`` of the FBM1, FBM2H and FBM3W ``sample`` modules), the same file writers (GT
logger split every hour, one benchmark-manager log per execution, one robot log per execution)
and the same folder layout, but ``DAYS`` days of ``SLOTS_PER_DAY`` executions each (FBM1H,
FBM2H, FBM3W in turn, every 13 minutes from 09:05 UTC) by ten teams, and nothing broken on
purpose: the benchmark measures throughput, the sample competition tests the problems.

    season/day<k>/gtlogger/log_mocap_<date>-08-59-58_<n>.bag
    season/day<k>/bmmanager/log_<benchmark>_<stamp>_0.bag
    season/day<k>/robots/<team>/<BENCH>_<YYYYmmddHHMM>_<team>.bag
    season/configs/...                      one set for the season (items, goal, shapes,
                                            transforms of every team)
    season/season.json                      every execution: id, day, benchmark, team,
                                            start, files and inputs

Deterministic (seeded); written once and kept in build/bench/season (generation is never timed).
"""

from __future__ import annotations

import datetime as dt
import json
import math
import shutil
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ertools.benchmarks.fbm1 import sample as fbm1
from ertools.benchmarks.fbm2h import sample as fbm2h
from ertools.benchmarks.fbm3w import sample as fbm3w
from ertools.samples.competition_files import (
    GtWindow,
    robot_poses,
    write_benchmark_log,
    write_gt_file,
    write_robot_log,
)
from ertools.simulator.answers import EPOCH_2015, log_name
from ertools.simulator.simulated import SimulatedRun

NS = 1_000_000_000
SEED = 2015_11_18
DAYS = 3
SLOTS_PER_DAY = 36  # 3 x 36 = 108 executions
SLOT_S = 13 * 60
FIRST_SLOT_S = (9 * 60 + 5) * 60  # 09:05 UTC
GT_LOGGER_S = 8 * 3600 + 59 * 60 + 58  # the GT logger starts at 08:59:58
MIDNIGHT_0 = EPOCH_2015 - 10 * 3600 * NS - 2 * 86400 * NS  # 2015-11-18 00:00 UTC
ROBOT_LEAD_S, ROBOT_TAIL_S = 15.0, 8.0
BENCHMARKS = ("fbm2h", "fbm1h", "fbm3w")
HOME_TEAMS = ("homer", "socrob", "skuba", "pumas", "tobi")
INPUT_KEY = {"fbm1h": "items", "fbm2h": "goal", "fbm3w": "config"}
WORK_TEAMS = ("b-it-bots", "robotto", "smartbots", "lar", "swarmlab")


@dataclass(frozen=True)
class Slot:
    day: int
    index: int
    benchmark: str
    team: str
    start_ns: int

    @property
    def id(self) -> str:
        stamp = dt.datetime.fromtimestamp(self.start_ns // NS, tz=dt.UTC)
        return f"{self.benchmark}-{self.team}-{stamp:%Y%m%dT%H%M%S}"


def schedule(days: int = DAYS, per_day: int = SLOTS_PER_DAY) -> list[Slot]:
    """Every execution of the season: benchmarks in turn, each team of the benchmark's
    league in turn, a slot every 13 minutes."""
    out = []
    turns = {b: 0 for b in BENCHMARKS}
    for day in range(days):
        for i in range(per_day):
            bench = BENCHMARKS[i % len(BENCHMARKS)]
            teams = WORK_TEAMS if bench == "fbm3w" else HOME_TEAMS
            team = teams[turns[bench] % len(teams)]
            turns[bench] += 1
            start = MIDNIGHT_0 + day * 86400 * NS + (FIRST_SLOT_S + i * SLOT_S) * NS
            out.append(Slot(day, i, bench, team, start))
    return out


def _knobs(seed: int) -> dict[str, Any]:
    """Each team's skill, drawn once for the season."""
    rng = np.random.default_rng(seed)
    knobs: dict[str, Any] = {}
    for team in HOME_TEAMS:
        knobs[f"fbm1h/{team}"] = (
            float(rng.uniform(0.5, 2.0)),
            tuple(int(k) for k in sorted(rng.choice(np.arange(1, 7), size=2, replace=False))),
        )
        knobs[f"fbm2h/{team}"] = (
            float(rng.uniform(0.5, 1.6)),
            tuple(float(v) for v in rng.uniform(-0.1, 0.1, 3)),
            (0.0, 0.0, float(rng.uniform(-math.pi, math.pi))),
        )
    for team in WORK_TEAMS:
        knobs[f"fbm3w/{team}"] = float(rng.uniform(0.8, 2.2))
    return knobs


def simulate(
    slot: Slot, seed: int, knobs: dict[str, Any], items: list[dict[str, Any]]
) -> SimulatedRun:
    if slot.benchmark == "fbm1h":
        scale, wrong = knobs[f"fbm1h/{slot.team}"]
        return fbm1.simulate(
            seed,
            start_ns=slot.start_ns,
            answer_errors=fbm1.answer_errors(scale, wrong),
            items=items,
        )
    if slot.benchmark == "fbm2h":
        scale, t, rpy = knobs[f"fbm2h/{slot.team}"]
        return fbm2h.simulate(
            seed,
            start_ns=slot.start_ns,
            team=slot.team,
            stop_errors=tuple((a * scale, b * scale, c * scale) for a, b, c in fbm2h.STOP_ERRORS),
            marker_to_robot_t=t,
            marker_to_robot_rpy=rpy,
            transform_stamp="2015-11-17_18:00:00",  # one acquisition for the season
        )
    scale = knobs[f"fbm3w/{slot.team}"]
    return fbm3w.simulate(
        seed, start_ns=slot.start_ns, amplitude=tuple(a * scale for a in fbm3w.AMPLITUDE)
    )


def _robot_rel(day_dir: str, bench: str, start_ns: int, team: str) -> str:
    stamp = dt.datetime.fromtimestamp(start_ns // NS, tz=dt.UTC)
    return f"{day_dir}/robots/{team}/{bench.upper()}_{stamp:%Y%m%d%H%M}_{team}.bag"


def generate_season(
    outdir: Path, *, days: int = DAYS, per_day: int = SLOTS_PER_DAY, seed: int = SEED
) -> dict[str, Any]:
    """Write the season into ``outdir`` (replaced as a whole); returns ``season.json``'s data."""
    partial = outdir.with_name(outdir.name + ".partial")
    shutil.rmtree(partial, ignore_errors=True)
    partial.mkdir(parents=True)
    slots = schedule(days, per_day)
    rng = np.random.default_rng(seed)
    seeds = [int(s) for s in rng.integers(0, 2**31 - 1, size=len(slots) + 3)]
    items = fbm1.item_list(np.random.default_rng(seeds[-1]))
    knobs = _knobs(seeds[-2])
    rlog_rng = np.random.default_rng(seeds[-3])
    configs: dict[str, str] = {}
    executions: list[dict[str, Any]] = []
    gt_files: list[dict[str, Any]] = []
    for day in range(days):
        day_slots = [s for s in slots if s.day == day]
        day_dir = f"day{day + 1}"
        # Simulated a day at a time: a day's GT files need every execution of the day.
        sims = [simulate(s, seeds[slots.index(s)], knobs, items) for s in day_slots]
        for slot, sim in zip(day_slots, sims, strict=True):
            for name, text in sim.configs.items():
                folder = "transforms/" if name.startswith("transform-") else ""
                rel = f"configs/{slot.benchmark}/{folder}{name}"
                if configs.setdefault(rel, text) != text:
                    raise AssertionError(f"{rel}: two executions disagree on its content")
        logger_start = MIDNIGHT_0 + day * 86400 * NS + GT_LOGGER_S * NS
        last_end = max(s.end_ns for s in sims) + round(ROBOT_TAIL_S * NS)
        hours = math.ceil((last_end - logger_start) / (3600 * NS))
        windows = []
        for i in range(hours):
            a = logger_start + i * 3600 * NS
            rel = f"{day_dir}/gtlogger/{log_name('mocap', logger_start, index=i)}"
            windows.append(GtWindow(rel, a, a + 3600 * NS, logger_start))
        for w in windows:
            (partial / w.rel).parent.mkdir(parents=True, exist_ok=True)
            span = write_gt_file(partial / w.rel, w, sims)
            gt_files.append({"path": w.rel, "start_ns": span[0], "end_ns": span[1]})
        for slot, sim in zip(day_slots, sims, strict=True):
            rel = f"{day_dir}/bmmanager/{log_name(sim.namespace, sim.start_ns)}"
            (partial / rel).parent.mkdir(parents=True, exist_ok=True)
            span = write_benchmark_log(partial / rel, sim, chunk_size=768 * 1024)
            r_start = sim.start_ns - round(ROBOT_LEAD_S * NS)
            r_end = sim.end_ns + round(ROBOT_TAIL_S * NS)
            robot_rel = _robot_rel(day_dir, slot.benchmark, r_start, slot.team)
            (partial / robot_rel).parent.mkdir(parents=True, exist_ok=True)
            poses = robot_poses(sim, r_start, r_end, rlog_rng)
            write_robot_log(partial / robot_rel, slot.team, r_start, r_end, poses, 0)
            # The manifest's inputs, named as the sample competition's answers name them.
            inputs = {
                ("transform" if n.startswith("transform-") else INPUT_KEY[slot.benchmark]): (
                    f"configs/{slot.benchmark}/"
                    f"{'transforms/' if n.startswith('transform-') else ''}{n}"
                )
                for n in sim.configs
            }
            executions.append(
                {
                    "id": slot.id,
                    "day": day + 1,
                    "benchmark": slot.benchmark,
                    "team": slot.team,
                    "start_ns": span[0],
                    "end_ns": span[1],
                    "bmbox_log": rel,
                    "robot_log": robot_rel,
                    "gt_files": [
                        w.rel for w in windows if w.start_ns <= span[1] and span[0] < w.end_ns
                    ],
                    "inputs": inputs,
                }
            )
    for rel, text in sorted(configs.items()):
        (partial / rel).parent.mkdir(parents=True, exist_ok=True)
        (partial / rel).write_text(text, encoding="utf-8")
    season = {
        "seed": seed,
        "days": days,
        "teams": {"home": list(HOME_TEAMS), "work": list(WORK_TEAMS)},
        "configs": sorted(configs),
        "gt_files": gt_files,
        "executions": executions,
    }
    (partial / "season.json").write_text(json.dumps(season, indent=1, default=_plain) + "\n")
    shutil.rmtree(outdir, ignore_errors=True)
    partial.rename(outdir)
    return season


def _plain(value: Any) -> Any:
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, tuple):
        return list(value)
    raise TypeError(f"not JSON: {type(value).__name__}")


if __name__ == "__main__":
    import argparse

    parser = argparse.ArgumentParser(description=__doc__.split("\n", 1)[0])
    parser.add_argument("out", type=Path)
    parser.add_argument("--days", type=int, default=DAYS)
    parser.add_argument("--per-day", type=int, default=SLOTS_PER_DAY)
    args = parser.parse_args()
    data = generate_season(args.out, days=args.days, per_day=args.per_day)
    print(f"{len(data['executions'])} executions over {args.days} day(s) in {args.out}")
