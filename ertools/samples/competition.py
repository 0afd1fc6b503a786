"""A sample competition: one day of logs at one venue, as the organisers' folders hold them.

``python -m ertools.samples --competition DIR`` writes, for Friday 2015-11-20 (UTC)::

    gtlogger/log_mocap_2015-11-20-08-59-58_<n>.bag   the GT (mocap) logger, split every hour
                                                    (rosbag record --split --duration 1h); the
                                                    last file is still ``.bag.active``: the
                                                    folder was copied at 13:45 while it recorded
    bmmanager/log_<benchmark>_<date>_0.bag          one per execution: the BmBox/RefBox/Client
                                                    state topics (and /rosout), no mocap
    robots/<team>/<BENCH>_<YYYYmmddHHMM>_<team>.bag  the robots' own logs (rockin_logger names)
    usb_keys/...                                    a robot log copied twice (a duplicate)
    configs/fbm1h/fbm1h.yaml                        the day's item list (seed Listing 9)
    configs/fbm2h/fbm2h_goal.yaml                   the goal (Listing 10)
    configs/fbm2h/transforms/transform-<team>.yaml  marker-to-robot transforms (Listing 11)
    configs/fbm3w/fbm3w.yaml                        runs_specifications and d_min (Listing 14)
    competition.yaml                                the organiser's manifest (docs/rescore.md)
    answers.json                                    what a correct rescoring must find

:data:`SCHEDULE` lists the 13 executions (FBM1H, FBM2H, FBM3W by five teams) at times a real
schedule would have. Each execution is simulated by its scenario module's ``simulate()`` with its
own seed and the team's knobs (how far it stops from waypoints, its answers, its path accuracy,
its marker mount), so the expected scores come from the simulated truth exactly as
``sample_bags/``'s answers do, never from ``ertools.benchmarks``.

What goes wrong, on purpose (``answers.json`` ``problems``):

- the benchmark log of b-it-bots' second FBM3W is truncated (the manager's laptop lost power):
  readable up to the cut, unscoreable;
- skuba's FBM2H has no ``transform-skuba.yaml``: unscoreable;
- homer's robot PC stamped its poses :data:`CLOCK_OFF_S` ahead of the logging laptop's record
  times in its second FBM2H (a clock offset the header/record check sees);
- the GT logger's last file is ``.bag.active`` (unindexed; read by scanning);
- one robot log is copied to ``usb_keys/`` (the same recording twice);
- homer's test drive at 08:30, before the GT logger started: a robot log no execution explains;
- robotto lost its USB key after its second FBM3W: that execution has no robot log (and so
  nothing names its team but the schedule);
- socrob's FBM2H at 09:59:31 straddles the GT logger's 09:59:58 split: two GT files.
"""

from __future__ import annotations

import datetime as dt
import json
import shutil
import tempfile
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from ertools.atomic import replace_folder
from ertools.benchmarks.fbm1 import sample as fbm1
from ertools.benchmarks.fbm2h import sample as fbm2h
from ertools.errors import UsageError
from ertools.samples.competition_files import (
    GtWindow,
    organiser_manifest,
    robot_poses,
    write_benchmark_log,
    write_gt_file,
    write_robot_log,
)
from ertools.samples.competition_schedule import (
    CLOCK_OFF,
    COPIED,
    MISSING_TRANSFORM,
    NO_ROBOT_LOG,
    SCHEDULE,
    TRUNCATED,
    Slot,
    simulate_slot,
)
from ertools.samples.competition_scores import expected_score, expected_trajectory
from ertools.samples.timeline_folder import make_active
from ertools.simulator.answers import EPOCH_2015, log_name, to_plain
from ertools.simulator.mocap import pose_topic
from ertools.simulator.simulated import SimulatedRun
from ertools.simulator.statemachine import state_messages
from ertools.states import BmBoxState, Machine

NS = 1_000_000_000
DEFAULT_SEED = 2015_11_20
GT_START_NS = EPOCH_2015 - 3600 * NS - 2 * NS  # the GT logger started at 08:59:58
GT_FILES = 5  # 08:59:58 ... 13:59:58
COPY_NS = EPOCH_2015 + (3 * 3600 + 45 * 60) * NS  # 13:45:00: the folder was copied
CLOCK_OFF_S = 4.0
TRUNCATE_AT = 0.6
ROBOT_LEAD_S = 15.0  # teams start their logger this long before the benchmark's recorder...
ROBOT_TAIL_S = 8.0  # ... and stop it this long after
TEST_DRIVE_NS = EPOCH_2015 - 90 * 60 * NS + 10 * NS  # 08:30:10, before the GT logger


# The organiser's manifest, written beside the logs (ertools rescore DIR --config DIR/MANIFEST).
MANIFEST = "competition.yaml"


def _gt_windows() -> list[GtWindow]:
    """The GT logger's split files: hour after hour from 08:59:58, the last cut at the copy."""
    out = []
    for i in range(GT_FILES):
        a = GT_START_NS + i * 3600 * NS
        b = min(a + 3600 * NS, COPY_NS)
        name = log_name("mocap", GT_START_NS, index=i)
        out.append(GtWindow(f"gtlogger/{name}", a, b, GT_START_NS))
    return out


def _robot_name(slot_or_bench: str, start_ns: int, team: str) -> str:
    stamp = dt.datetime.fromtimestamp(start_ns // NS, tz=dt.UTC)
    return f"robots/{team}/{slot_or_bench.upper()}_{stamp:%Y%m%d%H%M}_{team}.bag"


def _state_span(sim: SimulatedRun) -> tuple[int, int]:
    msgs = state_messages(sim.transitions, end_ns=sim.state_end_ns)
    return (
        min(int(m.t_ns[0]) for m in msgs.values() if len(m)),
        max(int(m.t_ns[-1]) for m in msgs.values() if len(m)),
    )


def generate_competition(outdir: Path, *, seed: int = DEFAULT_SEED) -> list[Path]:
    """Write the sample competition into ``outdir`` (which must be empty or absent).

    Returns every path written (files), ``answers.json`` last.
    """
    outdir.mkdir(parents=True, exist_ok=True)
    if any(outdir.iterdir()):
        raise UsageError(f"{outdir} is not empty: the sample competition needs an empty folder")
    rng = np.random.default_rng(seed)
    seeds = [int(s) for s in rng.integers(0, 2**31 - 1, size=len(SCHEDULE) + 2)]
    items = fbm1.item_list(np.random.default_rng(seeds[-1]))
    sims = [simulate_slot(s, seeds[i], items) for i, s in enumerate(SCHEDULE)]
    written: list[Path] = []

    # -- configs, as the organisers kept them: one per benchmark, one transform per team
    configs: dict[str, str] = {}
    for slot, sim in zip(SCHEDULE, sims, strict=True):
        for name, text in sim.configs.items():
            if name.startswith("transform-"):
                if slot.team == MISSING_TRANSFORM:
                    continue
                rel = f"configs/{slot.benchmark}/transforms/{name}"
            else:
                rel = f"configs/{slot.benchmark}/{name}"
            if configs.setdefault(rel, text) != text:  # one team, one marker mount
                raise AssertionError(f"{rel}: two executions disagree on its content")
    for rel, text in sorted(configs.items()):
        path = outdir / rel
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text, encoding="utf-8")
        written.append(path)

    # -- the GT logger
    windows = _gt_windows()
    gt_spans: dict[str, tuple[int, int]] = {}
    for w in windows:
        gt_spans[w.rel] = write_gt_file(outdir / w.rel, w, sims)
    last = windows[-1].rel
    active = make_active(outdir / last)
    gt_spans[str(active.relative_to(outdir))] = gt_spans.pop(last)
    written += [outdir / r for r in gt_spans]
    # file -> its [start, end) record-time window
    gt_windows = dict(zip(gt_spans, ((w.start_ns, w.end_ns) for w in windows), strict=True))
    fbm2h_gt = [s.bodies[fbm2h.BODY] for s in sims if s.benchmark == "fbm2h"]

    def gt_over(a: int, b: int) -> list[str]:
        """The GT files whose (closed) spans meet [a, b], as the timeline pairs them."""
        return [rel for rel, (s0, s1) in gt_spans.items() if s0 <= b and a <= s1]

    # -- the benchmark manager's logs and the robots' logs
    executions: list[dict[str, Any]] = []
    robot_logs: list[dict[str, Any]] = []
    rlog_rng = np.random.default_rng(seeds[-2])
    for slot, sim in zip(SCHEDULE, sims, strict=True):
        rel = f"bmmanager/{log_name(sim.namespace, sim.start_ns)}"
        span = write_benchmark_log(
            outdir / rel, sim, chunk_size=16 * 1024 if slot.id == TRUNCATED else 768 * 1024
        )
        written.append(outdir / rel)
        robot_rel = None
        if slot.id != NO_ROBOT_LOG:
            r_start = sim.start_ns - round(ROBOT_LEAD_S * NS)
            r_end = sim.end_ns + round(ROBOT_TAIL_S * NS)
            robot_rel = _robot_name(slot.benchmark, r_start, slot.team)
            offset = round(CLOCK_OFF_S * NS) if slot.id == CLOCK_OFF else 0
            poses = robot_poses(sim, r_start, r_end, rlog_rng)
            write_robot_log(outdir / robot_rel, slot.team, r_start, r_end, poses, offset)
            written.append(outdir / robot_rel)
            entry: dict[str, Any] = {
                "path": robot_rel,
                "team": slot.team,
                "benchmark": slot.benchmark,
                "execution": slot.id,
                "start_ns": r_start,
                "end_ns": r_end,
                "gt_files": gt_over(r_start, r_end),
                # the robot's recorder stores each pose 2 ms after the robot stamped it
                "header_minus_record_s": None if poses is None else (offset - 2_000_000) / NS,
                "trajectory": None,
            }
            if poses is not None:
                score, tolerance = expected_trajectory(
                    poses, offset, fbm2h_gt, [gt_windows[g] for g in entry["gt_files"]]
                )
                entry["trajectory"] = {
                    "robot_topic": f"/rockin/{slot.team}/marker_pose",
                    "gt_topic": pose_topic(fbm2h.NAMESPACE, fbm2h.BODY),
                    "offset_s": -offset / NS,
                    "score": score,
                    "tolerance": tolerance,
                }
            robot_logs.append(entry)
        gt = gt_over(*span)
        executions.append(
            _execution_answer(
                slot, sim, seeds[SCHEDULE.index(slot)], rel, span, gt, robot_rel, configs
            )
        )

    # -- what goes wrong
    trunc = next(e for e in executions if e["id"] == TRUNCATED)["bmbox_log"]
    data = (outdir / trunc).read_bytes()
    (outdir / trunc).write_bytes(data[: int(len(data) * TRUNCATE_AT)])
    copied = next(r for r in robot_logs if r["execution"] == COPIED)["path"]
    copy_rel = "usb_keys/" + Path(copied).name
    (outdir / copy_rel).parent.mkdir(parents=True)
    shutil.copyfile(outdir / copied, outdir / copy_rel)
    written.append(outdir / copy_rel)
    test_rel = _robot_name("fbm2h", TEST_DRIVE_NS, "homer")
    test_end = TEST_DRIVE_NS + 110 * NS
    test_poses = robot_poses(None, TEST_DRIVE_NS, test_end, rlog_rng)
    write_robot_log(outdir / test_rel, "homer", TEST_DRIVE_NS, test_end, test_poses, 0)
    written.append(outdir / test_rel)
    robot_logs.append(
        {
            "path": test_rel,
            "team": "homer",
            "benchmark": "fbm2h",
            "execution": None,
            "start_ns": TEST_DRIVE_NS,
            "end_ns": test_end,
            "gt_files": gt_over(TEST_DRIVE_NS, test_end),
            "header_minus_record_s": -0.002,
            "trajectory": None,  # no GT at all
        }
    )

    answers = {
        "generator": {
            "scenario": "competition",
            "seed": seed,
            "day": "2015-11-20",
            "venue": "simulated RoCKIn 2015 venue (Lisbon)",
            "seeds": seeds[: len(SCHEDULE)],
        },
        "teams": sorted({s.team for s in SCHEDULE}),
        "gt_logger": [
            {"path": rel, "start_ns": a, "end_ns": b} for rel, (a, b) in gt_spans.items()
        ],
        "executions": executions,
        "robot_logs": robot_logs,
        "copies": {copy_rel: copied},
        "manifest": MANIFEST,
        "problems": [
            {"path": trunc, "kind": "truncated", "execution": TRUNCATED},
            {"path": str(active.relative_to(outdir)), "kind": "active"},
            {"path": copy_rel, "kind": "duplicate", "of": copied},
            {
                "path": next(r for r in robot_logs if r["execution"] == CLOCK_OFF)["path"],
                "kind": "clock-offset",
                "offset_s": CLOCK_OFF_S,
            },
            {"path": test_rel, "kind": "unpaired"},
            {
                "path": f"configs/fbm2h/transforms/transform-{MISSING_TRANSFORM}.yaml",
                "kind": "missing-input",
                "input": "transform",
                "team": MISSING_TRANSFORM,
            },
            {
                "path": next(e for e in executions if e["id"] == NO_ROBOT_LOG)["bmbox_log"],
                "kind": "no-team",
                "execution": NO_ROBOT_LOG,
            },
        ],
    }
    manifest = outdir / MANIFEST
    manifest.write_text(organiser_manifest(executions, NO_ROBOT_LOG), encoding="utf-8")
    written.append(manifest)
    out = outdir / "answers.json"
    out.write_text(json.dumps(to_plain(answers), indent=1) + "\n", encoding="utf-8")
    written.append(out)
    return written


def _execution_answer(
    slot: Slot,
    sim: SimulatedRun,
    seed: int,
    bmbox_log: str,
    span: tuple[int, int],
    gt: list[str],
    robot_log: str | None,
    configs: dict[str, str],
) -> dict[str, Any]:
    inputs: dict[str, str] = {}
    for name in sim.configs:
        if name.startswith("transform-"):
            rel = f"configs/{slot.benchmark}/transforms/{name}"
            key = "transform"
        else:
            rel = f"configs/{slot.benchmark}/{name}"
            key = {"fbm1h": "items", "fbm2h": "goal", "fbm3w": "config"}[slot.benchmark]
        inputs[key] = rel
    status, reason = "scored", None
    if slot.id == TRUNCATED:
        status, reason = "unscoreable", f"benchmark log truncated at {TRUNCATE_AT:.0%} of its bytes"
    elif "transform" in inputs and inputs["transform"] not in configs:
        status, reason = "unscoreable", f"no marker-to-robot transform for team {slot.team}"
    states = _state_span(sim)
    score, tolerance = expected_score(sim)
    # The score the live 2015 BmBox sent (its TRANSMITTING_SCORE payload), as a reader of the
    # log finds it; a truncated log lost it with its end.
    sent = [
        t.payload
        for t in sim.transitions
        if t.machine is Machine.BMBOX and t.state == BmBoxState.TRANSMITTING_SCORE and t.payload
    ]
    live = yaml.safe_load(sent[0]) if sent and slot.id != TRUNCATED else None
    return {
        "id": slot.id,
        "benchmark": slot.benchmark,
        "namespace": sim.namespace,
        "team": slot.team,
        "attempt": slot.attempt,
        "seed": seed,
        "start_ns": span[0],
        "end_ns": span[1],
        "states": {"start_ns": states[0], "end_ns": states[1]},
        "bmbox_log": bmbox_log,
        "truncated": slot.id == TRUNCATED,
        "gt_files": gt,
        "robot_log": robot_log,
        "inputs": inputs,
        "status": status,
        "reason": reason,
        "score": score,
        "tolerance": tolerance,
        "live_score": live,
        "parameters": sim.parameters,
    }


def write_competition(outdir: Path, *, seed: int = DEFAULT_SEED) -> list[Path]:
    """:func:`generate_competition` into ``outdir`` as a whole or not at all: written into a
    hidden sibling first, then renamed, so that an interrupted run never leaves a folder that
    looks complete. Returns every path written, under ``outdir``."""
    outdir.parent.mkdir(parents=True, exist_ok=True)
    # a folder of a unique name: two runs at once each build their own
    partial = Path(
        tempfile.mkdtemp(dir=outdir.parent, prefix=f".{outdir.name}.", suffix=".partial")
    )
    try:
        paths = generate_competition(partial, seed=seed)
    except BaseException:
        shutil.rmtree(partial, ignore_errors=True)
        raise
    replace_folder(partial, outdir)
    return [outdir / p.relative_to(partial) for p in paths]
