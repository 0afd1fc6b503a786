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

The task runs are shortened (tens of seconds, not ten minutes). ``season2019.answers.yaml``
beside the folder (not in it: an organiser's folder holds no answers, and rescore would list it
as unused) holds the leaderboards a correct rescore gives, computed here from the plans:
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
from ertools.simulator.answers import answers_path, tol
from ertools.simulator.rsbb import write_rsbb_run

S = 1_000_000_000
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


def description(hgmf: ModuleType, referee: ModuleType) -> dict[str, Any]:
    """``benchmarks_description.yaml``: the referee-scored benchmarks and their items, then
    HGMF (scripted, no referee items)."""
    entry = {"code": hgmf.CODE, "desc": hgmf.DESCRIPTION_NAME, "scripted": True}
    entry["global_timeout"] = 600.0
    return {"benchmarks_description": [*referee.description_entries(), entry]}


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


def generate(outdir: Path, *, seed: int) -> list[Path]:
    """Write the season folder into ``outdir`` and its answers beside it
    (:func:`~ertools.simulator.answers.answers_path` of ``outdir``)."""
    hgmf = simulator(HGMF)
    written: list[Path] = []
    config = hgmf.write_config(outdir, OBJECTS)
    written.append(config)
    path = outdir / "rsbb_etc" / "config" / "benchmarks_description.yaml"
    path.parent.mkdir(parents=True, exist_ok=True)
    (referee,) = registry.sample_parts()
    write_text(path, yaml.safe_dump(description(hgmf, referee), sort_keys=False, width=100))
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
    runs, referee_boards = referee.write_runs(outdir, T0 + 2 * 3600 * S, TEAMS)
    written += runs
    boards |= referee_boards
    answers_file = answers_path(outdir)
    write_text(
        answers_file,
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
    written.append(answers_file)
    return written
