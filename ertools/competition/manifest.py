"""The competition manifest: which inputs each benchmark and each team is scored with.

A YAML file (safe-loaded), documented in docs/rescore.md::

    version: 1
    title: ERL Local Tournament, Lisbon          # optional, shown on the results page
    benchmarks:
      fbm2h:                                     # a registry name (ertools score --help)
        inputs:                                  # every team's values: the benchmark's declared
          goal: configs/fbm2h/fbm2h_goal.yaml    # inputs (Input.name), relative paths from here
        teams:
          homer:                                 # per-team inputs (Input.per_team)
            transform: configs/fbm2h/transforms/transform-homer.yaml
    executions:                                  # optional: executions listed by hand
      - benchmark: fbm3w
        team: robotto
        bags: [bmmanager/log_fbm3w.bag, gtlogger/log_mocap_3.bag]
        start: 2015-11-20T12:31:05Z              # optional (default: the first bag's span)
        inputs: {d_min: 0.0005}                  # optional: this execution's own values

The keys a benchmark takes are exactly its registry declaration (:attr:`Benchmark.inputs`):
adding a benchmark to the registry adds it here with no change to this module. Every problem
(unknown keys, values of the wrong kind, missing files, a team without a per-team input such as
its transform) is found in one pass and reported together, one line each
(:class:`ManifestError`).
"""

from __future__ import annotations

import hashlib
import os
from collections.abc import Mapping, Sequence
from dataclasses import field
from datetime import UTC, date, datetime
from pathlib import Path
from typing import Any

from ertools.benchmarks import registry
from ertools.benchmarks.base import Benchmark, Discovered, Input, rename_former
from ertools.configs._yaml import number, parse_yaml, show
from ertools.errors import BagError, ConfigError
from ertools.frozen_dataclass import frozen_dataclass
from ertools.inputs import read_regular
from ertools.io.formats import detect_format
from ertools.io.text import sniff
from ertools.timeutil import MAX_SECONDS, s_to_ns

VERSION = 1
TOP_KEYS = ("version", "title", "benchmarks", "executions")
BENCHMARK_KEYS = ("inputs", "teams")
EXECUTION_KEYS = ("benchmark", "team", "bags", "start", "end", "inputs")
PATH_KINDS = ("path", "paths")
# A benchmark input of this name is its ``--team``: given the execution's team.
TEAM_INPUT = "team"


class ManifestError(ConfigError):
    """A manifest with problems: all of them, one line each (``problems``)."""

    def __init__(self, problems: Sequence[str], *, path: str | Path) -> None:
        self.problems = tuple(problems)
        count = f"{len(self.problems)} problem{'s' if len(self.problems) != 1 else ''}"
        super().__init__(f"{count} in the manifest: " + "; ".join(self.problems), path=path)


@frozen_dataclass
class ListedExecution:
    """An execution the manifest lists by hand: its benchmark, team, bags and own values."""

    index: int
    benchmark: str
    team: str | None  # None: nobody named it yet (scored, left out of the leaderboards)
    bags: tuple[Path, ...]
    start_ns: int | None
    end_ns: int | None
    values: Mapping[str, Any]


@frozen_dataclass
class BenchmarkEntry:
    """One benchmark's values for every team (``values``) and per team (``teams``)."""

    name: str
    values: Mapping[str, Any]
    teams: Mapping[str, Mapping[str, Any]]


@frozen_dataclass
class Manifest:
    """A validated manifest; paths are absolute (resolved from the manifest's folder)."""

    path: Path
    sha256: str
    title: str
    benchmarks: Mapping[str, BenchmarkEntry]
    executions: tuple[ListedExecution, ...] = ()
    declared: Mapping[str, tuple[Input, ...]] = field(default_factory=dict)
    # executions listed more than once (YAML aliases, copies), one line each: scored once
    duplicates: tuple[str, ...] = ()

    def values_for(
        self, benchmark: str, team: str | None, overrides: Mapping[str, Any] | None = None
    ) -> tuple[dict[str, Any], list[str]]:
        """The input values of one execution (benchmark-wide, then the team's, then its own)
        and the per-team inputs still missing (one line each: the execution is unscoreable)."""
        entry = self.benchmarks.get(benchmark)
        values: dict[str, Any] = {}
        if entry is not None:
            values.update(entry.values)
            if team is not None:
                values.update(entry.teams.get(team, {}))
        values.update(overrides or {})
        declared_names = {d.name for d in self.declared.get(benchmark, ())}
        if TEAM_INPUT in declared_names and values.get(TEAM_INPUT) is None and team:
            values[TEAM_INPUT] = team  # the benchmark's own --team: the execution's team
        missing = [
            f"{benchmark}: no {declared.name} for team {team or '(unknown)'} in the manifest "
            f"(benchmarks.{benchmark}.teams.{team or 'TEAM'}.{declared.name})"
            for declared in self.declared.get(benchmark, ())
            # the rule of `ertools score`: only what this execution's scoring path uses (FBM2H's
            # transform, unless its reached moments come from a timing file or stop detection)
            # no team, no team's values: scored as `ertools score` without them (the numbers
            # first), and ranked only once the manifest names the team (then with them)
            if team is not None
            and declared.needed(values)
            and declared.name != TEAM_INPUT  # the execution's team, when there is one
            and values.get(declared.name) is None
        ]
        return values, missing


def load_manifest(path: Path) -> Manifest:
    """Read, safe-load and validate a manifest; :class:`ManifestError` lists every problem."""
    try:
        raw = read_regular(path)  # a named pipe would block open() for ever
    except FileNotFoundError:
        raise ConfigError("manifest not found", path=path) from None
    except OSError as err:
        raise ConfigError(f"cannot read the manifest: {err.strerror or err}", path=path) from err
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as err:
        raise ConfigError(f"the manifest is not UTF-8 text: {err}", path=path) from err
    data = parse_yaml(text, source=str(path), what="manifest")
    checker = _Checker(path.parent.resolve())
    manifest = checker.manifest(data, path, hashlib.sha256(raw).hexdigest())
    if checker.problems:
        raise ManifestError(checker.problems, path=path)
    return manifest


def _kind_name(value: Any) -> str:
    return "nothing" if value is None else type(value).__name__


class _Checker:
    """Walks the YAML once, converting what is right and noting every problem."""

    def __init__(self, base: Path) -> None:
        self.base = base
        self.problems: list[str] = []
        self.benchmarks: dict[str, Benchmark[Any, Any, Any, Any]] = {}

    def problem(self, where: str, message: str) -> None:
        self.problems.append(f"{where}: {message}")

    def mapping(self, value: Any, where: str) -> dict[str, Any] | None:
        if value is None:
            return {}
        if not isinstance(value, dict):
            self.problem(where, f"expected a mapping, got {_kind_name(value)}")
            return None
        return {str(k): v for k, v in value.items()}

    def unknown(self, mapping: Mapping[str, Any], known: Sequence[str], where: str) -> None:
        for key in mapping:
            if key not in known:
                self.problem(
                    f"{where}.{key}" if where else key, f"unknown key (known: {', '.join(known)})"
                )

    def benchmark(self, name: str, where: str) -> Benchmark[Any, Any, Any, Any] | None:
        if name not in registry.names():
            self.problem(
                where, f"unknown benchmark {name!r} (one of {', '.join(registry.names())})"
            )
            return None
        if name not in self.benchmarks:
            bench = registry.get(name)
            if not isinstance(bench, Discovered):
                self.problem(where, f"{name} is no benchmark of a competition (it has no ranking)")
                return None
            self.benchmarks[name] = bench
        return self.benchmarks[name]

    def manifest(self, data: Any, path: Path, sha256: str) -> Manifest:
        top = self.mapping(data, "the manifest") or {}
        self.unknown(top, TOP_KEYS, "")
        version = top.get("version", VERSION)
        if version != VERSION:
            self.problem(
                "version", f"{show(version)}: this ertools reads manifest version {VERSION}"
            )
        title = top.get("title", "")
        if not isinstance(title, str):
            self.problem("title", f"expected text, got {_kind_name(title)}")
            title = ""
        entries: dict[str, BenchmarkEntry] = {}
        for name, body in (self.mapping(top.get("benchmarks"), "benchmarks") or {}).items():
            entry = self.entry(name, body)
            if entry is not None:
                entries[name] = entry
        executions = top.get("executions") or []
        if not isinstance(executions, list):
            self.problem("executions", f"expected a list, got {_kind_name(executions)}")
            executions = []
        listed = [self.execution(i, item) for i, item in enumerate(executions)]
        declared = {name: bm.inputs for name, bm in self.benchmarks.items()}
        once, duplicates = _listed_once([e for e in listed if e is not None])
        manifest = Manifest(
            path=path.resolve(),
            sha256=sha256,
            title=title,
            benchmarks=entries,
            executions=once,
            declared=declared,
            duplicates=duplicates,
        )
        for entry in entries.values():
            for team in entry.teams:
                _, missing = manifest.values_for(entry.name, team)
                for line in missing:
                    self.problem(f"benchmarks.{entry.name}.teams.{team}", line.split(": ", 1)[1])
        for execution in manifest.executions:
            _, missing = manifest.values_for(execution.benchmark, execution.team, execution.values)
            for line in missing:
                self.problem(f"executions[{execution.index}]", line.split(": ", 1)[1])
        return manifest

    def entry(self, name: str, body: Any) -> BenchmarkEntry | None:
        where = f"benchmarks.{name}"
        bm = self.benchmark(name, where)
        mapping = self.mapping(body, where)
        if bm is None or mapping is None:
            return None
        self.unknown(mapping, BENCHMARK_KEYS, where)
        values = self.values(bm, mapping.get("inputs"), f"{where}.inputs", team=False)
        teams: dict[str, dict[str, Any]] = {}
        for team, team_body in (self.mapping(mapping.get("teams"), f"{where}.teams") or {}).items():
            teams[team] = self.values(bm, team_body, f"{where}.teams.{team}", team=True)
        return BenchmarkEntry(name, values, teams)

    def values(
        self, bm: Benchmark[Any, Any, Any, Any], body: Any, where: str, *, team: bool
    ) -> dict[str, Any]:
        """Declared inputs only, each converted to its kind; a team may set per-team ones."""
        mapping = rename_former(bm.inputs, self.mapping(body, where) or {}, where=where)
        declared = {i.name: i for i in bm.inputs}
        allowed = [i.name for i in bm.inputs if i.per_team] if team else list(declared)
        out: dict[str, Any] = {}
        for key, value in mapping.items():
            if key not in declared:
                self.problem(
                    f"{where}.{key}",
                    f"not an input of {bm.name} (its inputs: {', '.join(declared) or 'none'})",
                )
            elif key not in allowed:
                self.problem(
                    f"{where}.{key}",
                    f"not a per-team input of {bm.name} (set it under benchmarks.{bm.name}.inputs; "
                    f"per-team: {', '.join(allowed) or 'none'})",
                )
            else:
                converted = self.value(declared[key], value, f"{where}.{key}")
                if converted is not _BAD:
                    out[key] = converted
        return out

    def value(self, declared: Input, value: Any, where: str) -> Any:
        if value is None:  # a blank left for the organiser (``--init``): not given
            return None
        if declared.repeat or declared.kind == "paths":
            items = value if isinstance(value, list) else [value]
            single = Input(
                declared.name,
                "path" if declared.kind == "paths" else declared.kind,
                "",
                choices=declared.choices,
            )
            converted = [self.value(single, item, where) for item in items]
            return _BAD if any(c is _BAD for c in converted) else tuple(converted)
        kind = declared.kind
        if kind == "choice" and declared.with_file:
            return self.choice_with_file(declared, value, where)
        if kind == "path":
            if not isinstance(value, str) or not value:
                self.problem(where, f"expected a file path, got {_kind_name(value)}")
                return _BAD
            return self.path(value, where)
        if kind == "float":
            if isinstance(value, bool) or not isinstance(value, int | float):
                self.problem(where, f"expected a number, got {_kind_name(value)} {show(value)}")
                return _BAD
            return self.number(declared, value, where)
        if kind == "int":
            if isinstance(value, bool) or not isinstance(value, int):
                self.problem(
                    where, f"expected a whole number, got {_kind_name(value)} {show(value)}"
                )
                return _BAD
            return _BAD if self.number(declared, value, where) is _BAD else value
        if kind == "flag":
            if not isinstance(value, bool):
                self.problem(where, f"expected true or false, got {value!r}")
                return _BAD
            return value
        if not isinstance(value, str | int | float) or isinstance(value, bool):
            self.problem(where, f"expected text, got {_kind_name(value)}")
            return _BAD
        if kind == "choice" and str(value) not in declared.choices:
            self.problem(where, f"{value!r} is not one of {', '.join(declared.choices)}")
            return _BAD
        return str(value)

    def number(self, declared: Input, value: float, where: str) -> float | Any:
        """A finite number within the declared input's minimum (a NaN ``d_min`` would pass
        here and abort every execution scored with it)."""
        try:
            f = number(value, where, "")
        except ConfigError as err:
            self.problem(where, err.message.split(": ", 1)[1])
            return _BAD
        low = declared.minimum if declared.minimum is not None else 0.0
        if (declared.positive and f <= low) or (declared.minimum is not None and f < low):
            sign = ">" if declared.positive else ">="
            self.problem(where, f"{show(value)} must be {sign} {low:g} {declared.unit}".rstrip())
            return _BAD
        if declared.below is not None and f >= declared.below:
            self.problem(
                where, f"{show(value)} must be < {declared.below:g} {declared.unit}".rstrip()
            )
            return _BAD
        if declared.maximum is not None and f > declared.maximum:
            self.problem(
                where, f"{show(value)}: at most {declared.maximum:g} {declared.unit}".rstrip()
            )
            return _BAD
        return f

    def choice_with_file(self, declared: Input, value: Any, where: str) -> Any:
        """``states`` or ``[timing, FILE]``: a choice, with a file for those that take one."""
        words = [value] if isinstance(value, str) else value
        expected = " | ".join(
            f"[{c}, FILE]" if c in declared.with_file else c for c in declared.choices
        )
        if (
            not isinstance(words, list)
            or not words
            or not all(isinstance(w, str) for w in words)
            or words[0] not in declared.choices
            or len(words) != (2 if words[0] in declared.with_file else 1)
        ):
            self.problem(where, f"expected {expected}, got {value!r}")
            return _BAD
        if len(words) == 1:
            return (words[0],)
        path = self.path(words[1], where)
        return _BAD if path is _BAD else (words[0], path)

    def path(self, text: str, where: str) -> Path | Any:
        path = Path(text).expanduser()
        if not path.is_absolute() and ".." in path.parts:
            # a relative path is read from the manifest's folder: one climbing out of it
            # (`../../../../etc/passwd`) is refused; a file elsewhere is named absolutely
            resolved = Path(os.path.normpath(self.base / path))
            if not resolved.is_relative_to(self.base):
                self.problem(
                    where,
                    f"{text} leads out of the manifest's folder ({self.base}); give a path "
                    "inside it, or an absolute path",
                )
                return _BAD
        path = Path(os.path.normpath(path if path.is_absolute() else self.base / path))
        if not path.exists():
            self.problem(where, f"file not found: {path}")
            return _BAD
        return path

    def bag(self, text: Any, where: str, bm: Benchmark[Any, Any, Any, Any] | None) -> Any:
        """A listed log: a path, and, for a benchmark reading bags, a bag (checked by its
        first bytes; what they hold is never quoted)."""
        if not isinstance(text, str) or not text:
            return _BAD
        path = self.path(text, where)
        if path is _BAD or not isinstance(bm, Discovered) or not bm.logs_are_bags:
            return path
        try:
            detect_format(path)
        except BagError as err:
            if bm.logs_may_be_text and sniff(path) is not None:
                return path  # a TUM, KITTI, EuRoC or ertools CSV trajectory
            self.problem(where, err.message)
            return _BAD
        return path

    def execution(self, index: int, item: Any) -> ListedExecution | None:
        where = f"executions[{index}]"
        mapping = self.mapping(item, where)
        if mapping is None:
            return None
        self.unknown(mapping, EXECUTION_KEYS, where)
        ok = True
        for key in ("benchmark", "bags"):  # no team (or a blank one): scored, not ranked
            if key not in mapping:
                self.problem(where, f"missing key {key!r}")
                ok = False
        name = mapping.get("benchmark")
        bm = self.benchmark(str(name), f"{where}.benchmark") if name is not None else None
        team = mapping.get("team")
        if team is not None and not isinstance(team, str | int):
            self.problem(f"{where}.team", f"expected a team name, got {_kind_name(team)}")
            ok = False
        bags_raw = mapping.get("bags", [])
        bags_list = bags_raw if isinstance(bags_raw, list) else [bags_raw]
        bags = [self.bag(b, f"{where}.bags", bm) for b in bags_list]
        if "bags" in mapping and (not bags_list or any(b is _BAD for b in bags)):
            if not bags_list or not all(isinstance(b, str) and b for b in bags_list):
                self.problem(f"{where}.bags", "expected a list of one or more bag paths")
            ok = False
        start = self.time(mapping.get("start"), f"{where}.start")
        end = self.time(mapping.get("end"), f"{where}.end")
        values = self.values(bm, mapping.get("inputs"), f"{where}.inputs", team=False) if bm else {}
        if not ok or bm is None or start is _BAD or end is _BAD:
            return None
        return ListedExecution(
            index=index,
            benchmark=bm.name,
            team=None if team is None or not str(team).strip() else str(team),
            bags=tuple(bags),
            start_ns=start,
            end_ns=end,
            values=values,
        )

    def time(self, value: Any, where: str) -> int | Any | None:
        """A time: ISO 8601 (YAML reads it as a date-time; without a zone, UTC) or epoch s."""
        if value is None:
            return None
        if isinstance(value, str):
            try:
                value = datetime.fromisoformat(value.replace("Z", "+00:00"))
            except ValueError:
                self.problem(where, f"{value!r} is not an ISO 8601 time (2015-11-20T12:31:05Z)")
                return _BAD
        if isinstance(value, datetime):
            aware = value if value.tzinfo is not None else value.replace(tzinfo=UTC)
            return s_to_ns(aware.timestamp())
        if isinstance(value, date | bool) or not isinstance(value, int | float):
            self.problem(where, f"expected a time (ISO 8601 or epoch seconds), got {show(value)}")
            return _BAD
        try:
            seconds = number(value, where, "", low=0.0, high=MAX_SECONDS, unit="s")
        except ConfigError as err:
            self.problem(where, f"{err.message.split(': ', 1)[1]}; give ISO 8601 or epoch seconds")
            return _BAD
        return s_to_ns(seconds)


def _identity(execution: ListedExecution) -> tuple[Any, ...]:
    """What makes two listed executions the same one: everything its score depends on."""
    values = tuple(sorted((k, repr(v)) for k, v in execution.values.items()))
    return (
        execution.benchmark,
        execution.team,
        execution.bags,  # normalised, absolute (_Checker.path)
        execution.start_ns,
        execution.end_ns,
        values,
    )


def _listed_once(
    executions: Sequence[ListedExecution],
) -> tuple[tuple[ListedExecution, ...], tuple[str, ...]]:
    """Each execution once (its first listing), and one line per execution listed again: as
    YAML aliases or copies, 1,000 listings cost 1,000 scorings of the same cache key. The
    same log and time listed for two teams is named too (both are scored: which is right is
    the organiser's to say)."""
    first: dict[tuple[Any, ...], ListedExecution] = {}
    again: dict[int, list[int]] = {}
    for execution in executions:
        seen = first.setdefault(_identity(execution), execution)
        if seen is not execution:
            again.setdefault(seen.index, []).append(execution.index)
    lines = []
    for index, copies in again.items():
        shown = ", ".join(f"executions[{i}]" for i in copies[:5])
        more = f" and {len(copies) - 5} more" if len(copies) > 5 else ""
        times = "once more" if len(copies) == 1 else f"{len(copies)} more times"
        lines.append(
            f"{shown}{more}: the same execution as executions[{index}] (listed {times}: "
            "same benchmark, team, logs, time and inputs); scored once"
        )
    by_log: dict[tuple[Any, ...], ListedExecution] = {}
    for execution in first.values():
        where = (execution.benchmark, execution.bags, execution.start_ns, execution.end_ns)
        other = by_log.setdefault(where, execution)
        if other is not execution and other.team != execution.team:
            lines.append(
                f"executions[{execution.index}]: the logs and time of executions[{other.index}] "
                f"for another team ({execution.team or 'none'}, there {other.team or 'none'}): "
                "both are scored; remove the wrong one"
            )
    return tuple(first.values()), tuple(lines)


class _Bad:
    """A value that had a problem (already noted)."""


_BAD: Any = _Bad()
