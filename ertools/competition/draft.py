"""``ertools rescore PATH... --init FILE``: a draft manifest from what the logs hold.

Every execution found, its benchmark, time and guessed team (with where the name came from),
each benchmark's file inputs and each team's per-team inputs. A file is filled in when one
under PATH has the name the input suggests (``transform-homer.yaml`` for homer's
``transform``, ``fbm2h_goal.yaml`` or ``goal.yaml`` for fbm2h's ``goal``, ``fbm3w.yaml`` for
fbm3w's first file input), marked ``guessed``; what is still missing is a commented ``TODO``
line, so the draft validates as it is (those executions are then unscoreable, saying why) and
the organiser fills in blanks rather than starting from nothing. Inputs come from the registry's
declarations only. GT-only recordings are listed under ``executions:`` with the values scoring
them (and an input file found beside them); the draft ends with every file under PATH and its
place (:mod:`ertools.competition.ledger`).
"""

from __future__ import annotations

import json
import os
import re
import textwrap
from collections.abc import Mapping, Sequence
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

from ertools.benchmarks import registry
from ertools.benchmarks.base import Input
from ertools.competition.discover import Execution
from ertools.competition.found import Found, robot_benchmarks, run_root, run_side_file
from ertools.competition.ledger import Claim, place_files, root_of
from ertools.competition.site_text import TEAM_UNKNOWN
from ertools.io.formats import regular_files
from ertools.rsbb.layout import FileKind
from ertools.timelines.build import rsbb_run
from ertools.timeutil import NS_PER_S

CONFIG_SUFFIXES = (".yaml", ".yml")


def _utc(ns: int) -> str:
    return datetime.fromtimestamp(ns / NS_PER_S, tz=UTC).strftime("%Y-%m-%d %H:%M:%S UTC")


def config_files(paths: Sequence[Path]) -> list[Path]:
    """The YAML files under ``paths`` (the candidates for file inputs), sorted."""
    # a folder that cannot be listed is one of the timeline scan's problems already
    found, _problems = regular_files(paths)
    return sorted({p.resolve() for p in found if p.suffix.lower() in CONFIG_SUFFIXES})


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
    executions = found.executions
    claims: list[Claim] = []  # every file's place, for the list at the end
    known = set(registry.names())
    lines = [
        f"# Drafted by `{' '.join(command)}`",
        f"# from {len(executions)} benchmark execution(s) found in the logs. Fill in the TODO",
        "# lines, check the guessed files, then:",
        # the draft's path as given, as the PATHs are: the line runs where `--init` ran
        f"#   ertools rescore {' '.join(str(p) for p in paths)} --config {target} --out results/",
        "# Format: docs/rescore.md. Relative paths are from this file's folder.",
        "version: 1",
        'title: ""  # TODO: the competition, as the results page shows it',
        "benchmarks:",
    ]
    # side files that differ between the runs' layouts, by run bag: given per execution
    run_values: dict[str, dict[str, Path]] = {}
    # runs whose layout has none of a side file several other folders have: not listed (so
    # unscoreable until the organiser names it), by run bag: the input and the candidates
    unsure_runs: dict[str, list[str]] = {}
    by_benchmark: dict[str, list[str]] = {}

    def per_run(benchmark: str, name: str, team: str | None = None) -> str | None:
        """The draft's note when ``name`` is given run by run (recorded above), else None."""
        split, unsure = rsbb_split(found, benchmark, name, team)
        if not (split or unsure):
            return None
        for log, path in split.items():
            run_values.setdefault(log, {})[name] = path
        for log, cands in unsure.items():
            unsure_runs.setdefault(log, []).append(_candidates(name, cands, base))
        return f"# {name}: {_split_note(split, unsure, base)}"

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
        mine = [e for e in executions if e.benchmark == name]
        # an input every execution gives itself (an RSBB run's result file) is not the
        # benchmark's: it is listed with each execution below
        file_inputs = [
            i
            for i in file_inputs
            if not mine or not all(i.name in found.values.get(e.bmbox_log, {}) for e in mine)
        ]
        for k, declared in enumerate(file_inputs):
            if (note := per_run(name, declared.name)) is not None:
                lines.append(f"      {note}")
                continue
            side = rsbb_side(found, name, declared.name)
            if side is not None:
                lines.append(
                    f"      {declared.name}: {_yaml(_rel(side, base))}  # in the RSBB layout"
                )
                claims.append(Claim(str(side), "input", f"benchmarks.{name}.inputs"))
                continue
            hits = guess(files, name, declared, first=k == 0)
            if hits:
                note = "guessed from its name: check" + (
                    f" (also: {', '.join(_rel(h, base) for h in hits[1:])})" if hits[1:] else ""
                )
                lines.append(f"      {declared.name}: {_yaml(_rel(hits[0], base))}  # {note}")
                claims.append(Claim(str(hits[0]), "input", f"benchmarks.{name}.inputs"))
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
                    if (note := per_run(name, declared.name, team)) is not None:
                        entries.append(f"        {note}")
                        continue
                    side = rsbb_side(found, name, declared.name, team)
                    # the run's own layout first: a name elsewhere (another season) is a guess
                    hits = [side] if side is not None else []
                    how = (
                        "the runs', in their RSBB layout"
                        if side is not None
                        else "guessed from its name: check"
                    )
                    hits = hits or guess(files, name, declared, first=False, team=team)
                    if hits:
                        entries.append(
                            f"        {declared.name}: {_yaml(_rel(hits[0], base))}  # {how}"
                        )
                        claims.append(Claim(str(hits[0]), "input", f"benchmarks.{name}.teams"))
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

    # GT-only recordings (scored with their own values: a timing file...) are listed, so the
    # organiser sees how each is scored; others with no team get a commented entry to name them.
    def own(e: Execution) -> dict[str, Any]:
        return {**found.values.get(e.bmbox_log, {}), **run_values.get(_key(e.bmbox_log), {})}

    def is_listed(e: Execution) -> bool:
        key = _key(e.bmbox_log)
        return key not in unsure_runs and (e.bmbox_log in found.values or key in run_values)

    listed = [e for e in executions if is_listed(e)]
    unnamed = [e for e in executions if e.team is None and not is_listed(e)]
    lines.append("executions:" + ("" if unnamed or listed else " []"))
    for e in listed:
        lines += _listed_entry(e, own(e), files, base, claims)
    for e in unnamed:
        bags = [_rel(Path(p).resolve(), base) for p in (e.bmbox_log, *e.gt_files)]
        lines += [
            f"  # {e.benchmark} at {_utc(e.start_ns)}: nothing in the logs names its team: it is",
            f'  # scored and shown as "{TEAM_UNKNOWN}", out of the leaderboards.',
            "  # TODO: uncomment and name it:",
            f"  # - benchmark: {e.benchmark}",
            "  #   team: TODO",
            f"  #   bags: {json.dumps(bags)}",
        ]
    for e in executions:
        if (todo := unsure_runs.get(_key(e.bmbox_log))) is None:
            continue
        bags = [_rel(Path(p).resolve(), base) for p in (e.bmbox_log, *e.gt_files)]
        lines += [
            f"  # {e.benchmark} at {_utc(e.start_ns)}: its RSBB layout lacks side files that "
            "several folders hold: unscoreable until named. TODO: uncomment, name them:",
            f"  # - benchmark: {e.benchmark}",
            f"  #   team: {e.team}",
            f"  #   bags: {json.dumps(bags)}",
            "  #   inputs:",
        ]
        for key, value in own(e).items():
            if isinstance(value, Path):
                lines.append(f"  #     {key}: {_yaml(_rel(value, base))}")
                claims.append(Claim(str(value), "input", e.id))
        lines += [f"  #     {line}" for line in todo]
    lines += ["", "# The executions found (benchmark log, team and where its name came from):"]
    for e in executions:
        team = f"{e.team} (from {e.team_source})" if e.team else "no team"
        lines.append(
            f"#   {_utc(e.start_ns)}  {e.benchmark:<6} {team:<28} {_rel_text(e.bmbox_log, base)}"
        )
        for problem in e.problems:
            lines.append(f"#       {_rel_text(problem, base)}")
    lines += _file_lines(found, executions, claims, base)
    return "\n".join(lines) + "\n"


def rsbb_side(found: Found, benchmark: str, name: str, team: str | None = None) -> Path | None:
    """The side file the RSBB layout holds for ``benchmark``'s input ``name`` (``config``,
    ``items``, ``transform`` of ``team``, ``description``), None when it holds none."""
    folder = found.timeline.rsbb
    if folder is None:
        return None
    if name == "description":
        kind = FileKind.DESCRIPTION.value
        roots = [run_root(r) for r in folder.runs if r.code.lower() == benchmark]
        descriptions = [Path(p).resolve() for k, p in folder.files if k == kind]
        own = [d for d in descriptions if any(r is not None and r in d.parents for r in roots)]
        return next(iter(own or descriptions), None)
    if name not in ("config", "items", "transform"):
        return None
    for run in folder.runs:
        if run.code.lower() != benchmark or (team is not None and run.team != team):
            continue
        value = getattr(run, name)
        if value is not None:
            return Path(value).resolve()
    return None


def rsbb_split(
    found: Found, benchmark: str, name: str, team: str | None = None
) -> tuple[dict[str, Path], dict[str, tuple[Path, ...]]]:
    """Each run's side file for ``benchmark``'s input ``name`` (of ``team``'s runs, per-team)
    by its run bag, and the runs whose file cannot be told (several elsewhere, none in its
    layout), when one slot for all of them would be wrong; else two empty mappings."""
    folder = found.timeline.rsbb
    if folder is None:
        return {}, {}
    sure: dict[str, Path] = {}
    unsure: dict[str, tuple[Path, ...]] = {}
    for run in folder.runs:
        if run.bag is None or run.code.lower() != benchmark:
            continue
        if team is not None and run.team != team:
            continue
        side = run_side_file(folder, run, name)
        if isinstance(side, tuple):
            unsure[_key(run.bag)] = side
        elif side is not None:
            sure[_key(run.bag)] = side
    if unsure or len(set(sure.values())) > 1:
        return sure, unsure
    return {}, {}


def _split_note(
    split: Mapping[str, Path], unsure: Mapping[str, tuple[Path, ...]], base: Path
) -> str:
    files = sorted({_rel(p, base) for p in split.values()})
    note = f"each run its own layout's ({', '.join(files)}): under executions: below"
    for bag, candidates in unsure.items():
        named = ", ".join(_rel(c, base) for c in candidates)
        note += f"; TODO: {_rel(Path(bag), base)}: none in its layout, several elsewhere ({named})"
    return note


def _candidates(name: str, candidates: Sequence[Path], base: Path) -> str:
    return f"{name}: TODO  # one of {', '.join(_rel(c, base) for c in candidates)}"


def _key(bag: str) -> str:
    return str(Path(bag).resolve())


def _rel_text(text: str, base: Path) -> str:
    """``text`` with the absolute paths under ``base`` relative to it (the draft's folder)."""
    prefix = str(base).rstrip("/") + "/"
    return text.replace(prefix, "")


def _beside(files: Sequence[Path], log: Path, declared: Input) -> list[Path]:
    """The YAML files in ``log``'s folder whose name has ``declared``'s name as a word
    (``fbm2h_test_optitrackless_goal.yaml`` for ``goal``)."""
    word = declared.name.lower()
    return [f for f in files if f.parent == log.parent and word in re.split(r"[_\-.]", _stem(f))]


def _listed_entry(
    e: Execution,
    values: Mapping[str, Any],
    files: Sequence[Path],
    base: Path,
    claims: list[Claim],
) -> list[str]:
    """An ``executions:`` entry for a GT-only recording, with the values scoring it."""
    bench = registry.get(e.benchmark)
    log = Path(e.bmbox_log).resolve()
    bags = [_rel(Path(p).resolve(), base) for p in (e.bmbox_log, *e.gt_files)]
    what = (
        "its RSBB run bag, and the result file its script wrote"
        if rsbb_run(e.bmbox_log) is not None
        else "the GT logger's log alone (no state topics)"
    )
    out = [
        f"  # {bench.title} at {_utc(e.start_ns)}: {what}",
        f"  - benchmark: {e.benchmark}",
        f"    team: {_yaml(e.team) if e.team else 'null  # TODO: ' + TEAM_UNKNOWN}",
        f"    bags: {json.dumps(bags)}",
        "    inputs:",
    ]
    for key, value in values.items():
        if isinstance(value, tuple):
            words = [_rel(v, base) if isinstance(v, Path) else str(v) for v in value]
            out.append(f"      {key}: {json.dumps(words)}  # found beside the log")
            claims += [Claim(str(v), "input", e.id) for v in value if isinstance(v, Path)]
        elif isinstance(value, Path):
            out.append(f"      {key}: {_yaml(_rel(value, base))}  # the run's, in the RSBB layout")
            claims.append(Claim(str(value), "input", e.id))
        else:
            out.append(f"      {key}: {_yaml(str(value))}  # the GT alone: runs found from motion")
    for declared in bench.inputs:
        if declared.kind != "path" or declared.per_team or declared.name in values:
            continue
        hits = _beside(files, log, declared)
        if hits:
            out.append(
                f"      {declared.name}: {_yaml(_rel(hits[0], base))}  "
                "# beside the log, guessed from its name: check"
            )
            claims.append(Claim(str(hits[0]), "input", e.id))
    return out


def _file_lines(
    found: Found, executions: Sequence[Execution], claims: list[Claim], base: Path
) -> list[str]:
    """Every file under the folders and its place (each once), as comment lines."""
    for e in executions:
        claims.append(Claim(str(Path(e.bmbox_log).resolve()), "execution", e.id))
        claims += [Claim(str(Path(g).resolve()), "gt", e.id) for g in e.gt_files]
        if e.robot_log is not None:
            claims.append(Claim(str(Path(e.robot_log).resolve()), "robot-log", e.id))
    for problem in found.problems:
        if problem.get("path"):
            claims.append(
                Claim(
                    str(Path(str(problem["path"])).resolve()),
                    "problem",
                    kind=str(problem["kind"]),
                    reason=str(problem["message"]),
                )
            )
    root = root_of(found.folders)
    entries = place_files(found.files, claims, root)
    lines = [
        "",
        f"# Every file under {_rel(Path(root), base) if root else 'PATH'}, in one place each:",
    ]
    for entry in entries:
        where = f"{entry.place}" + (f" of {entry.execution}" if entry.execution else "")
        if entry.kind:
            where += f" ({entry.kind}: {_rel_text(entry.reason or '', base)})"
        lines.append(f"#   {entry.path}: {where}")
    return lines
