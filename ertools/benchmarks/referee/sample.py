"""The referee-scored benchmarks' part of the ``season2019`` sample (composed by
:mod:`ertools.samples.season`): their items in ertools' words, each team's values and times,
the runs (the generic RSBB task-run writer of :mod:`ertools.simulator.rsbb_task`) and the
leaderboards the ERL rule gives, computed here from the plans (most achievements, then fewest
penalties, then least time; a disqualified run unranked)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from ertools.simulator.rsbb import write_rsbb_run
from ertools.simulator.rsbb_scenario import Goal, RsbbScenario, Save
from ertools.simulator.rsbb_task import COMPLETED, STOPPED, TaskScenario, write_task_run

S = 1_000_000_000
#: The description's order of the referee-scored benchmarks (the scripted test one first).
ORDER = ("STB", "HGTKMH", "HWV", "HCFGAC")
#: The ones a referee scores alone (no script).
SCRIPTED = ("STB",)

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


def description_entries() -> list[dict[str, Any]]:
    """Their entries of ``benchmarks_description.yaml``, in :data:`ORDER`."""
    entries = []
    for code in ORDER:
        entry: dict[str, Any] = {"code": code, "desc": NAMES[code], "scripted": code in SCRIPTED}
        entry["global_timeout" if entry["scripted"] else "timeout"] = 600.0
        entry["scoring"] = [
            {group: [{"type": kind, "desc": desc} for kind, desc in items]}
            for group, items in ITEMS[code]
        ]
        entries.append(entry)
    return entries


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


def stb_run(root: Path, team: str, t0: int) -> list[Path]:
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


def write_runs(outdir: Path, t0: int, teams: tuple[str, ...]) -> tuple[list[Path], dict[str, Any]]:
    """The task benchmarks' runs (one hour apart from ``t0``, the teams ten minutes apart) and
    the STB's (``teams[0]`` alone, three hours after the last): the paths written and each
    benchmark's leaderboard, by registry name."""
    written: list[Path] = []
    boards: dict[str, Any] = {}
    for c, code in enumerate(TASKS):
        rows: list[dict[str, Any]] = []
        for k, team in enumerate(teams):
            values, seconds = TASKS[code][team]
            start_at = t0 + c * 3600 * S + k * 600 * S
            start = start_at + 2 * S
            sc = TaskScenario(
                code,
                team,
                1,
                start_at,
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
    written += stb_run(outdir, teams[0], t0 + 3 * 3600 * S)
    a, p, _ = tally("STB", (1, 0))
    boards["stb"] = {
        "ranked": [
            {"team": teams[0], "achievements": a, "penalized_behaviors": p, "execution_time": 20.0}
        ],
        "unranked": [],
    }
    return written, boards
