"""``ertools rescore PATH... --init FILE``: a draft manifest from what the logs hold.

Every execution found, its benchmark, time and guessed team (with where the name came from),
each benchmark's file inputs and each team's per-team inputs. A file is filled in when one
under PATH has the name the input suggests (``transform-homer.yaml`` for homer's
``transform``, ``fbm2h_goal.yaml`` or ``goal.yaml`` for fbm2h's ``goal``, ``fbm3w.yaml`` for
fbm3w's first file input), marked ``guessed``; what is still missing is a commented ``TODO``
line, so the draft validates as it is (those executions are then unscoreable, saying why) and
the organiser fills in blanks rather than starting from nothing. Inputs come from the registry's
declarations only.
"""

from __future__ import annotations

import json
import os
import re
import textwrap
from collections.abc import Sequence
from datetime import UTC, datetime
from pathlib import Path

from ertools.benchmarks import registry
from ertools.benchmarks.base import Input
from ertools.rescore.found import Found, robot_benchmarks
from ertools.timeutil import NS_PER_S

CONFIG_SUFFIXES = (".yaml", ".yml")


def _utc(ns: int) -> str:
    return datetime.fromtimestamp(ns / NS_PER_S, tz=UTC).strftime("%Y-%m-%d %H:%M:%S UTC")


def config_files(paths: Sequence[Path]) -> list[Path]:
    """The YAML files under ``paths`` (the candidates for file inputs), sorted."""
    out: set[Path] = set()
    for path in paths:
        if path.is_file() and path.suffix.lower() in CONFIG_SUFFIXES:
            out.add(path.resolve())
        elif path.is_dir():
            out |= {
                p.resolve()
                for p in path.rglob("*")
                if p.is_file() and p.suffix.lower() in CONFIG_SUFFIXES
            }
    return sorted(out)


def _stem(path: Path) -> str:
    return path.stem.lower()


def guess(
    files: Sequence[Path], benchmark: str, declared: Input, first: bool, team: str | None = None
) -> list[Path]:
    """The files whose name suggests ``declared``'s value (for ``team``, per-team)."""
    name = declared.name.lower()
    if team is not None:
        wanted = {f"{name}-{team.lower()}", f"{name}_{team.lower()}"}
    else:
        wanted = {f"{benchmark}_{name}", f"{benchmark}-{name}", name}
        if first:
            wanted.add(benchmark)
    return [f for f in files if _stem(f) in wanted]


def _rel(path: Path, base: Path) -> str:
    # a manifest's relative paths stay inside its folder (manifest.py refuses `../`)
    rel = os.path.relpath(path, base)
    return str(path.resolve()) if rel.split(os.sep)[0] == ".." else rel


def _yaml(value: str) -> str:
    """``value`` as a YAML string: plain when that reads back the same, else quoted (a JSON
    string is a YAML string)."""
    plain = re.fullmatch(r"[A-Za-z_./][A-Za-z0-9_./-]*", value) is not None
    if plain and value.lower() not in ("true", "false", "yes", "no", "on", "off", "null", "~"):
        return value
    return json.dumps(value)


def draft_text(found: Found, paths: Sequence[Path], target: Path, command: Sequence[str]) -> str:
    """The draft manifest for the executions ``found`` under ``paths``, written at ``target``."""
    base = target.resolve().parent
    files = config_files(paths)
    executions = found.discovery.executions
    known = set(registry.names())
    lines = [
        f"# Drafted by `{' '.join(command)}`",
        f"# from {len(executions)} benchmark execution(s) found in the logs. Fill in the TODO",
        "# lines, check the guessed files, then:",
        f"#   ertools rescore {' '.join(str(p) for p in paths)} --config {target.name} --out "
        "results/",
        "# Format: docs/rescore.md. Relative paths are from this file's folder.",
        "version: 1",
        'title: ""  # TODO: the competition, as the results page shows it',
        "benchmarks:",
    ]
    by_benchmark: dict[str, list[str]] = {}
    for e in executions:
        teams = by_benchmark.setdefault(e.benchmark, [])
        if e.team is not None and e.team not in teams:
            teams.append(e.team)
    for name in [n for n in registry.names() if n in by_benchmark] + sorted(
        set(by_benchmark) - known
    ):
        if name not in known:
            lines.append(f"  # {name}: found in the logs, but no registered benchmark scores it")
            continue
        bench = registry.get(name)
        count = sum(e.benchmark == name for e in executions)
        teams = sorted(by_benchmark[name])
        lines.append(f"  {name}:  # {bench.title}: {count} execution(s); teams {', '.join(teams)}")
        lines.append("    inputs:")
        file_inputs = [i for i in bench.inputs if i.kind in ("path", "paths") and not i.per_team]
        for k, declared in enumerate(file_inputs):
            hits = guess(files, name, declared, first=k == 0)
            if hits:
                note = "guessed from its name: check" + (
                    f" (also: {', '.join(_rel(h, base) for h in hits[1:])})" if hits[1:] else ""
                )
                lines.append(f"      {declared.name}: {_yaml(_rel(hits[0], base))}  # {note}")
            else:
                lines.append(f"      # {declared.name}:   # {declared.help}")
        others = [
            i.name for i in bench.inputs if i.kind not in ("path", "paths") and not i.per_team
        ]
        if others:
            text = f"also: {', '.join(others)} (`ertools score {name} --help`: the options)"
            lines += [f"      # {part}" for part in textwrap.wrap(text, 88)]
        per_team = [i for i in bench.inputs if i.per_team and i.kind in ("path", "paths")]
        if per_team and teams:
            lines.append("    teams:")
            for team in teams:
                entries = []
                for declared in per_team:
                    hits = guess(files, name, declared, first=False, team=team)
                    if hits:
                        entries.append(
                            f"        {declared.name}: {_yaml(_rel(hits[0], base))}  "
                            "# guessed from its name: check"
                        )
                    else:
                        entries.append(
                            f"        # {declared.name}:   # TODO: no {declared.name}-{team}.yaml "
                            f"found; until given, {team}'s {name} executions are unscoreable"
                        )
                if any(not x.lstrip().startswith("#") for x in entries):
                    lines.append(f"      {_yaml(team)}:")
                    lines += entries
                else:  # left out until found: its executions are unscoreable, saying why
                    lines.append(f"      # {_yaml(team)}:")
                    lines += entries
    robot_logs = sum(e.robot_log is not None for e in executions)
    for name in robot_benchmarks() if robot_logs else ():
        bench = registry.get(name)
        lines.append(f"  {name}:  # {bench.title}: the {robot_logs} robot log(s) against the GT")
        lines.append("    inputs: {}")
        text = (
            f"e.g. {', '.join(i.name for i in bench.inputs)} (`ertools score {name} --help`: "
            "the options; a GT topic when the GT files hold several)"
        )
        lines += [f"      # {part}" for part in textwrap.wrap(text, 88)]
    unnamed = [e for e in executions if e.team is None and e.benchmark in known]
    lines.append("executions:" + ("" if unnamed else " []"))
    for e in unnamed:
        bags = [_rel(Path(p).resolve(), base) for p in (e.bmbox_log, *e.gt_files)]
        lines += [
            f"  # {e.benchmark} at {_utc(e.start_ns)}: nothing in the logs names its team.",
            "  # TODO: uncomment and name it:",
            f"  # - benchmark: {e.benchmark}",
            "  #   team: TODO",
            f"  #   bags: {json.dumps(bags)}",
        ]
    lines += ["", "# The executions found (benchmark log, team and where its name came from):"]
    for e in executions:
        team = f"{e.team} (from {e.team_source})" if e.team else "no team"
        lines.append(f"#   {_utc(e.start_ns)}  {e.benchmark:<6} {team:<28} {e.bmbox_log}")
        for problem in e.problems:
            lines.append(f"#       {problem}")
    return "\n".join(lines) + "\n"
