"""Scenario ``season2019``: an ERL @Home 2019 season folder in the RSBB's layout, two teams.

The folder is what an RSBB machine's output and configuration hold (docs/rsbb.md, "What an
RSBB run writes"): ``rsbb_logs/<CODE>/<team>/run_<n>_<date>.bag``,
``results/<CODE>/<team>/result_run_<n>_<date>.yaml``, ``rsbb_etc/config/
benchmarks_description.yaml`` (the referee items, in ertools' own words) and
``rsbb_bmbox/scripts/benchmark_configs/HGMF.yaml``. Teams ``simbot`` and ``homebot`` each ran:

- HGMF (FBM6, scripted): simbot puts its three objects 2, 4 and 3 cm from their targets;
  homebot 5 and 7 cm, one goal timed out (written by HGMF's own simulator, its package's
  ``sample`` module, reached through :func:`ertools.benchmarks.registry.scenarios`);
- HGTKMH (task benchmark 1, referee-scored): both 5 achievements and 1 penalty, homebot 5 s
  faster: the time decides;
- HWV (task benchmark 2): simbot 3 achievements; homebot 4, but it hit a visitor: disqualified;
- HCFGAC (task benchmark 3): both 6 achievements; simbot 8 s faster but it dropped an object
  (2 penalties against homebot's 1): the penalties decide;
- STB (the scripted test benchmark, two goals): simbot only, its referee items in its result
  file.

The task runs are shortened (tens of seconds, not ten minutes). ``answers.yaml`` at the
folder's root holds the leaderboards a correct rescore gives, computed here from the plans:
HGMF's average distances from the noiseless truth, the task benchmarks' tallies and times
(the GUI's stop button is sampled at 10 Hz from 0.36 s after the connect: the times are the
planned ones exactly), ranked by the ERL rule (most achievements, then fewest penalties, then
least time; a disqualified run unranked).
"""

from __future__ import annotations

from pathlib import Path
from types import ModuleType
from typing import Any

import yaml

from ertools.atomic import write_text
from ertools.benchmarks import registry
from ertools.errors import UsageError
from ertools.simulator.answers import tol
from ertools.simulator.rsbb import write_rsbb_run
from ertools.simulator.rsbb_scenario import Goal, RsbbScenario, Save
from ertools.simulator.rsbb_task import COMPLETED, STOPPED, TaskScenario, write_task_run

S = 1_000_000_000
MS = 1_000_000
# Saturday 13 April 2019, 10:00:00 UTC: the day after the HGMF sample's run (no two sample
# files share a name).
T0 = 1_555_149_600 * S
# The folder of sample_bags/ that HGMF's scenario writes: its simulator builds the season's
# HGMF runs too.
HGMF = "hgmf"
TEAMS = ("simbot", "homebot")
OBJECTS = (
    {"id": 1, "description": "mug"},
    {"id": 2, "description": "box"},
    {"id": 3, "description": "can"},
)

# The referee items, group by group (benchmarks_description.yaml's layout; ertools' words).
ITEMS: dict[str, tuple[tuple[str, tuple[tuple[str, str], ...]], ...]] = {
    "HGTKMH": (
        (
            "Achievements",
            (
                ("bool", "finds the door whose state changed"),
                ("uint", "finds each moved piece of furniture"),
                ("uint", "finds each changed object"),
                ("bool", "carries out the command of phase 2"),
            ),
        ),
        (
            "Penalized Behaviors",
            (
                ("uint", "needs the gesture or speech repeated"),
                ("uint", "bumps into the furniture"),
                ("uint", "stops working"),
            ),
        ),
        (
            "Disqualifying Behaviors",
            (("uint", "hits a person"), ("uint", "damages the test bed")),
        ),
    ),
    "HWV": (
        (
            "Achievements",
            tuple(
                ("bool", f"{what} the {who}")
                for what in ("answers the door and recognises", "behaves as expected with")
                for who in ("doctor", "deli man", "postman", "unknown visitor")
            ),
        ),
        (
            "Penalized Behaviors",
            (("uint", "raises a false alarm"), ("uint", "bumps into the furniture")),
        ),
        ("Disqualifying Behaviors", (("uint", "hits a visitor"),)),
    ),
    "HCFGAC": (
        (
            "Achievements",
            (
                ("bool", "enters the room where Granny Annie waits"),
                ("bool", "understands her command"),
                ("uint", "operates each right device"),
                ("uint", "finds each right object"),
                ("uint", "brings her each right object"),
            ),
        ),
        (
            "Penalized Behaviors",
            (
                ("uint", "bumps into the furniture"),
                ("uint", "drops an object"),
                ("uint", "stops working"),
            ),
        ),
        (
            "Disqualifying Behaviors",
            (
                ("uint", "hits a person"),
                ("uint", "damages an object it was asked to handle"),
                ("uint", "damages the test bed"),
            ),
        ),
    ),
    "STB": (
        ("Penalized Behaviors", (("uint", "bumps into the furniture or people"),)),
        ("Disqualifying Behaviors", (("uint", "hits people or the furniture"),)),
    ),
}
NAMES = {
    "HGTKMH": "Task Benchmark 1: Getting to know my home",
    "HWV": "Task Benchmark 2: Welcoming visitors",
    "HCFGAC": "Task Benchmark 3: Catering for Granny Annie's comfort",
    "HGMF": "Functionality Benchmark 6: Grasping and Manipulation Functionality",
    "STB": "Test Benchmark: Simple Test Benchmark",
}

# Each team's item values, in the order of ITEMS, and its executing time (s).
TASKS: dict[str, dict[str, tuple[tuple[int, ...], float]]] = {
    "HGTKMH": {
        "simbot": ((1, 2, 1, 1, 1, 0, 0, 0, 0), 40.0),
        "homebot": ((1, 3, 1, 0, 0, 1, 0, 0, 0), 35.0),
    },
    "HWV": {
        "simbot": ((1, 1, 0, 1, 0, 0, 0, 0, 0, 0, 0), 50.0),
        "homebot": ((1, 1, 1, 1, 0, 0, 0, 0, 0, 1, 1), 45.0),
    },
    "HCFGAC": {
        "simbot": ((1, 1, 2, 1, 1, 1, 1, 0, 0, 0, 0), 50.0),
        "homebot": ((1, 1, 1, 2, 1, 0, 0, 1, 0, 0, 0), 58.0),
    },
}
# How each task benchmark's runs end (the zone's state text after the last span).
ENDS = {"HGTKMH": COMPLETED, "HWV": STOPPED, "HCFGAC": COMPLETED}


def description() -> dict[str, Any]:
    """``benchmarks_description.yaml``: the benchmarks of the folder and their items."""
    entries = []
    for code in ("STB", "HGTKMH", "HWV", "HCFGAC", "HGMF"):
        entry: dict[str, Any] = {
            "code": code,
            "desc": NAMES[code],
            "scripted": code in ("STB", "HGMF"),
        }
        entry["global_timeout" if entry["scripted"] else "timeout"] = 600.0
        if code in ITEMS:
            entry["scoring"] = [
                {group: [{"type": kind, "desc": desc} for kind, desc in items]}
                for group, items in ITEMS[code]
            ]
        entries.append(entry)
    return {"benchmarks_description": entries}


def referee_items(code: str, values: tuple[int, ...]) -> tuple[dict[str, Any], ...]:
    """The items as the RefBox sends them (``group_name``, ``desc``, ``type``, value)."""
    flat = [(g, kind, desc) for g, items in ITEMS[code] for kind, desc in items]
    return tuple(
        {"group_name": g, "desc": desc, "type": kind, "current_value": v}
        for (g, kind, desc), v in zip(flat, values, strict=True)
    )


def tally(code: str, values: tuple[int, ...]) -> tuple[int, int, bool]:
    """(achievements, penalties, disqualified): a bool item counts 0 or 1, a count its value."""
    flat = [(g, kind) for g, items in ITEMS[code] for kind, _ in items]
    a = sum(v for (g, _), v in zip(flat, values, strict=True) if g == "Achievements")
    p = sum(v for (g, _), v in zip(flat, values, strict=True) if g == "Penalized Behaviors")
    d = any(v for (g, _), v in zip(flat, values, strict=True) if g == "Disqualifying Behaviors")
    return a, p, d


def simulator(folder: str) -> ModuleType:
    """The ``sample`` module of the benchmark whose scenario writes ``folder``, through the
    registry (its plans and ``build``: the season's runs are the benchmark's own simulation).

    Raises:
        UsageError: no registered benchmark writes ``folder``.
    """
    for scenario in registry.scenarios():
        if scenario.folder == folder:
            return scenario.load()
    raise UsageError(f"season2019: no registered benchmark simulates {folder!r} runs")


def hgmf_plans(hgmf: ModuleType) -> dict[str, tuple[Any, ...]]:
    """Each team's HGMF goals (HGMF's ``GoalPlan``: object, start, target, where it ends)."""
    plan = hgmf.GoalPlan
    return {
        "simbot": (
            plan(1, (0.30, 0.40), (0.62, 1.05), (0.64, 1.05)),
            plan(2, (0.70, 0.30), (0.40, 0.90), (0.40, 0.94)),
            plan(3, (0.25, 1.10), (0.70, 0.50), (0.70, 0.53)),
        ),
        "homebot": (
            plan(3, (0.30, 0.40), (0.62, 1.05), (0.67, 1.05)),
            plan(1, (0.70, 0.30), (0.40, 0.90), None, lift=False),
            plan(2, (0.25, 1.10), (0.70, 0.50), (0.70, 0.57)),
        ),
    }


def _stb(root: Path, team: str, t0: int) -> list[Path]:
    """The simple test benchmark: two goals the robot completes; its result file holds the
    referee's items (no score of its own)."""
    items = referee_items("STB", (1, 0))
    goals = tuple(
        Goal(
            t0 + (3 + 10 * k) * S,
            t0 + (4 + 10 * k) * S,
            t0 + (8 + 10 * k) * S,
            "{}\n",
            "result",
            "{}",
        )
        for k in range(2)
    )
    sc = RsbbScenario(
        code="STB",
        team=team,
        run=1,
        season="2019",
        t_connect_ns=t0 + S // 2,
        t_start_ns=t0 + 2 * S,
        t_end_ns=t0 + 22 * S,
        end="end",
        t_disconnect_ns=t0 + 24 * S,
        goals=goals,
        saves=(Save(t0 + 22 * S, {}),),
        params={"goal_timeout": 30.0},
        referee_score=items,
    )
    paths = write_rsbb_run(root, sc, compression="bz2")
    return [paths.bag, paths.result]


def generate(outdir: Path, *, seed: int) -> list[Path]:
    """Write the season folder into ``outdir`` and its answers (``answers.yaml``)."""
    hgmf = simulator(HGMF)
    written: list[Path] = []
    config = hgmf.write_config(outdir, OBJECTS)
    written.append(config)
    path = outdir / "rsbb_etc" / "config" / "benchmarks_description.yaml"
    path.parent.mkdir(parents=True, exist_ok=True)
    write_text(path, yaml.safe_dump(description(), sort_keys=False, width=100))
    written.append(path)
    boards: dict[str, Any] = {}
    hgmf_rows = []
    plans = hgmf_plans(hgmf)
    for k, team in enumerate(TEAMS):
        plan = hgmf.RunPlan(team, 1, T0 + k * 3600 * S, plans[team], objects=OBJECTS, seed=seed + k)
        scenario, truth = hgmf.build(plan)
        paths = write_rsbb_run(outdir, scenario, compression="bz2")
        written += [paths.bag, paths.result]
        answers = hgmf.expected(truth, len(OBJECTS))
        hgmf_rows.append(
            {
                "team": team,
                "Avg distance error": answers["ertools"]["Avg distance error"],
                "Objects grasped": answers["ertools"]["Objects grasped"],
                "rules_2019": answers["rules_2019"],
            }
        )
    boards["hgmf"] = sorted(hgmf_rows, key=lambda r: r["Avg distance error"])
    for c, code in enumerate(TASKS):
        rows: list[dict[str, Any]] = []
        for k, team in enumerate(TEAMS):
            values, seconds = TASKS[code][team]
            t0 = T0 + (2 + c) * 3600 * S + k * 600 * S
            start = t0 + 2 * S
            sc = TaskScenario(
                code,
                team,
                1,
                t0,
                ((start, start + round(seconds * S)),),
                ENDS[code],
                start + round(seconds * S) + 2 * S,
                start + round(seconds * S) + 4 * S,
                referee_items(code, values),
            )
            written.append(write_task_run(outdir, sc, compression="bz2"))
            a, p, d = tally(code, values)
            rows.append(
                {
                    "team": team,
                    "achievements": a,
                    "penalized_behaviors": p,
                    "execution_time": seconds,
                    "disqualified": d,
                }
            )
        ranked = sorted(
            (r for r in rows if not r["disqualified"]),
            key=lambda r: (-r["achievements"], r["penalized_behaviors"], r["execution_time"]),
        )
        boards[code.lower()] = {
            "ranked": ranked,
            "unranked": [r["team"] for r in rows if r["disqualified"]],
        }
    written += _stb(outdir, TEAMS[0], T0 + 5 * 3600 * S)
    a, p, _ = tally("STB", (1, 0))
    boards["stb"] = {
        "ranked": [
            {"team": TEAMS[0], "achievements": a, "penalized_behaviors": p, "execution_time": 20.0}
        ],
        "unranked": [],
    }
    answers_path = outdir / "answers.yaml"
    write_text(
        answers_path,
        yaml.safe_dump(
            {
                "benchmark": "season2019",
                "generator": {"scenario": "season2019", "seed": int(seed)},
                "expected": {"leaderboards": boards},
                "tolerance": {
                    "Avg distance error": tol(2e-3, "HGMF's: mocap noise, see sample_bags/hgmf"),
                    "execution_time": tol(
                        1e-9, "the GUI's 10 Hz ticks fall on the planned moments"
                    ),
                },
            },
            sort_keys=False,
            width=100,
        ),
    )
    written.append(answers_path)
    return written
