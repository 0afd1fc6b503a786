"""A season folder in the RSBB's layout: which file is which, and which result goes with which bag.

The RSBB wrote ``rsbb_logs/<CODE>/<team>/run_<n>_<YYYY-MM-DD-HH-MM-SS>.bag`` (rosbag's local
start time; ``.bag.active`` when the recorder was killed) and
``results/<CODE>/<team>/result_run_<n>_<YYYY-MM-DD_HH:MM:SS_TZ(+zzzz)>.yaml`` (the BmBox's
local setup time with its zone); its configuration sits in ``rsbb_etc/`` and
``rsbb_bmbox/scripts/benchmark_configs/`` (docs/rsbb.md, "What an RSBB run writes").
:func:`classify` and :func:`pair_runs` are pure functions of paths; :func:`scan` lists a
folder and applies them.
"""

from __future__ import annotations

import enum
import os
import re
from collections.abc import Collection, Iterable
from dataclasses import field
from datetime import datetime, timedelta
from pathlib import Path, PurePath

from ertools.errors import UsageError
from ertools.frozen_dataclass import frozen_dataclass
from ertools.rsbb.results import parse_result_time
from ertools.rsbb_states import BENCHMARKS, LOGS_DIR, RESULTS_DIR

#: A result file and its bag start within this of each other (the BmBox's setup and the
#: recorder's start follow the same referee action by about a second; clock seconds only).
PAIR_TOLERANCE = timedelta(seconds=60)


class FileKind(enum.Enum):
    """What a file of a season folder is."""

    RUN_BAG = "run bag"  # rsbb_logs/<CODE>/<team>/run_<n>_<date>.bag
    RESULT = "result"  # results/<CODE>/<team>/result_run_<n>_<date>.yaml
    BENCHMARK_CONFIG = "benchmark config"  # <CODE>.yaml (HNF.yaml, HPFF.yaml, HGMF.yaml...)
    TRANSFORM = "transform"  # transform-<team>.yaml
    ITEMS = "items"  # items_with_pose.yaml (HOPF)
    ITEMS_LIST = "items list"  # items_list.yaml (the acquirer's input)
    DESCRIPTION = "benchmarks description"  # benchmarks_description.yaml
    MOCAP_LOG = "mocap log"  # log_mocap_<date>[_<k>].bag (the optional continuous logger)


@frozen_dataclass
class SeasonFile:
    """One recognised file.

    Attributes:
        path: the file.
        kind: what it is.
        code: the benchmark code (run bags, results, benchmark configs), else None.
        team: the team (run bags, results, transforms), else None.
        run: the run number (run bags, results), else None.
        stamp: the date in the name as written, else None.
        local_time: that date as a naive local time (run bags, results), else None.
        active: a ``.bag.active`` (recording not closed).
    """

    path: Path
    kind: FileKind
    code: str | None = None
    team: str | None = None
    run: int | None = None
    stamp: str | None = None
    local_time: datetime | None = None
    active: bool = False


_BAG = re.compile(r"^run_(\d+)_(\d{4}-\d{2}-\d{2}-\d{2}-\d{2}-\d{2})\.bag(\.active)?$")
_RESULT = re.compile(r"^result_run_(\d+)_(.+)\.yaml$")
_TRANSFORM = re.compile(r"^transform-(.+)\.yaml$")
_MOCAP = re.compile(r"^log_mocap_.*\.bag(\.active)?$")


def _bag_time(stamp: str) -> datetime | None:
    try:
        return datetime.strptime(stamp, "%Y-%m-%d-%H-%M-%S")
    except ValueError:
        return None


def bag_name(name: str) -> tuple[int, datetime | None] | None:
    """(run, local start time) of a run bag's file name ``run_<n>_<date>.bag[.active]`` in
    any folder; None for another name."""
    m = _BAG.match(name)
    return None if m is None else (int(m.group(1)), _bag_time(m.group(2)))


def result_name(name: str) -> tuple[int, datetime | None] | None:
    """(run, local time) of a result file's name ``result_run_<n>_<date>.yaml`` in any folder;
    None for another name."""
    m = _RESULT.match(name)
    if m is None:
        return None
    aware = parse_result_time(m.group(2))
    return int(m.group(1)), None if aware is None else aware.replace(tzinfo=None)


def _code_team(parts: tuple[str, ...], top: str) -> tuple[str, str] | None:
    """(code, team) from ``.../<top>/<CODE>/<team>/[<robot>/]<file>``; None if not so."""
    for k in range(len(parts) - 3, -1, -1):
        if parts[k] != top:
            continue
        rest = parts[k + 1 : -1]
        if len(rest) in (2, 3) and rest[0] in BENCHMARKS:
            return rest[0], rest[1]
    return None


def classify(path: str | PurePath) -> SeasonFile | None:
    """What ``path`` is in an RSBB season folder, from its name and folders; None if nothing.

    A run bag or result file must sit in the RSBB's own folders
    (``rsbb_logs/<CODE>/<team>/``, ``results/<CODE>/<team>/``) with a known benchmark code;
    side files are recognised by name anywhere.
    """
    p = Path(path)
    name = p.name
    parts = p.parts
    m = _BAG.match(name)
    if m:
        where = _code_team(parts, LOGS_DIR)
        if where is None:
            return None
        return SeasonFile(
            p,
            FileKind.RUN_BAG,
            where[0],
            where[1],
            int(m.group(1)),
            m.group(2),
            _bag_time(m.group(2)),
            m.group(3) is not None,
        )
    m = _RESULT.match(name)
    if m:
        where = _code_team(parts, RESULTS_DIR)
        if where is None:
            return None
        aware = parse_result_time(m.group(2))
        local = None if aware is None else aware.replace(tzinfo=None)
        return SeasonFile(
            p, FileKind.RESULT, where[0], where[1], int(m.group(1)), m.group(2), local
        )
    if _MOCAP.match(name):
        return SeasonFile(p, FileKind.MOCAP_LOG, active=name.endswith(".active"))
    m = _TRANSFORM.match(name)
    if m:
        return SeasonFile(p, FileKind.TRANSFORM, team=m.group(1))
    if name == "items_with_pose.yaml":
        return SeasonFile(p, FileKind.ITEMS)
    if name == "items_list.yaml":
        return SeasonFile(p, FileKind.ITEMS_LIST)
    if name == "benchmarks_description.yaml":
        return SeasonFile(p, FileKind.DESCRIPTION)
    if p.suffix == ".yaml" and p.stem in BENCHMARKS and BENCHMARKS[p.stem].scripted:
        return SeasonFile(p, FileKind.BENCHMARK_CONFIG, code=p.stem)
    return None


@frozen_dataclass
class RunFiles:
    """One run's files: its bag and result file (either may be missing) and its side files.

    Attributes:
        code, team, run: the run.
        bag: the run bag, or None (a result file without its bag).
        result: the result file, or None (no BmBox script, or it wrote none).
        config: the benchmark config (``<CODE>.yaml``) found in the folder, or None.
        transform: ``transform-<team>.yaml``, or None.
        items: ``items_with_pose.yaml`` (a benchmark's that takes it), or None.
    """

    code: str
    team: str
    run: int
    bag: SeasonFile | None
    result: SeasonFile | None
    config: Path | None = None
    transform: Path | None = None
    items: Path | None = None


@frozen_dataclass
class SeasonLayout:
    """A season folder's recognised files and its runs.

    Attributes:
        root: the folder.
        files: every recognised file, sorted by path.
        runs: the runs, sorted by code, team, time.
        problems: one line per thing a referee should look at (two configs for one code, a
            result with no bag...).
    """

    root: Path
    files: tuple[SeasonFile, ...]
    runs: tuple[RunFiles, ...]
    problems: tuple[str, ...] = field(default=())


def layout_root(f: SeasonFile) -> Path | None:
    """The folder holding a run bag's ``rsbb_logs/`` or a result file's ``results/`` (its
    season's layout), None for other files."""
    top = {FileKind.RUN_BAG: LOGS_DIR, FileKind.RESULT: RESULTS_DIR}.get(f.kind)
    parts = f.path.parts
    for k in range(len(parts) - 3, -1, -1):
        if parts[k] == top and parts[k + 1 : k + 3] == (f.code, f.team):
            return Path(*parts[:k]) if k else Path(parts[0])
    return None


class _SideFiles:
    """The side files by code (configs) and team (transforms), and the items; each run takes
    those of its own layout (under its root) first, others only when its layout has none."""

    def __init__(self, files: Iterable[SeasonFile]) -> None:
        self.configs: dict[str, list[Path]] = {}
        self.transforms: dict[str, list[Path]] = {}
        self.items: list[Path] = []
        self.problems: list[str] = []  # two files for one choice, each said once
        self._told: set[str] = set()
        for f in files:
            if f.kind is FileKind.BENCHMARK_CONFIG and f.code is not None:
                self.configs.setdefault(f.code, []).append(f.path)
            elif f.kind is FileKind.TRANSFORM and f.team is not None:
                self.transforms.setdefault(f.team, []).append(f.path)
            elif f.kind is FileKind.ITEMS:
                self.items.append(f.path)

    def one(self, what: str, paths: list[Path], root: Path | None) -> Path | None:
        own = [p for p in paths if root is not None and root in p.parents]
        chosen = sorted(own or paths)
        if len(chosen) > 1:
            others = ", ".join(map(str, chosen[1:]))
            line = f"{len(chosen)} files for {what}: {chosen[0]} used, not {others}"
            if line not in self._told:  # once, not once per run
                self._told.add(line)
                self.problems.append(line)
        return chosen[0] if chosen else None


def pair_runs(
    files: Iterable[SeasonFile], season_items: Collection[str] = ()
) -> tuple[tuple[RunFiles, ...], tuple[str, ...]]:
    """Runs from recognised files: a result file and a bag of the same code, team and run
    whose times are within :data:`PAIR_TOLERANCE` go together (nearest first); the side files
    are attached by code and team, those under the run's own layout root first
    (:func:`layout_root`), the items file to the runs of the codes in ``season_items`` (the
    registry's :func:`~ertools.benchmarks.registry.season_items`). Returns (runs, problems)."""
    items_all = list(files)
    problems: list[str] = []
    side = _SideFiles(items_all)
    groups: dict[tuple[str, str, int], tuple[list[SeasonFile], list[SeasonFile]]] = {}
    for f in items_all:
        if (
            f.kind in (FileKind.RUN_BAG, FileKind.RESULT)
            and f.code
            and f.team
            and f.run is not None
        ):
            bags, results = groups.setdefault((f.code, f.team, f.run), ([], []))
            (bags if f.kind is FileKind.RUN_BAG else results).append(f)
    runs: list[RunFiles] = []
    for (code, team, run), (bags, results) in groups.items():
        pairs: list[tuple[SeasonFile | None, SeasonFile | None]] = []
        free_bags = sorted(bags, key=lambda f: (f.local_time or datetime.min, str(f.path)))
        candidates = sorted(
            (abs(b.local_time - r.local_time), i, j)
            for i, r in enumerate(results)
            for j, b in enumerate(free_bags)
            if r.local_time is not None
            and b.local_time is not None
            and abs(b.local_time - r.local_time) <= PAIR_TOLERANCE
        )
        used_r: set[int] = set()
        used_b: set[int] = set()
        for _, i, j in candidates:
            if i not in used_r and j not in used_b:
                used_r.add(i)
                used_b.add(j)
                pairs.append((free_bags[j], results[i]))
        pairs += [(b, None) for j, b in enumerate(free_bags) if j not in used_b]
        pairs += [(None, r) for i, r in enumerate(results) if i not in used_r]
        for bag, result in pairs:
            scripted = BENCHMARKS[code].scripted
            if bag is None and result is not None:
                problems.append(f"{result.path}: no run bag of {code} {team} run {run} beside it")
            elif result is None and scripted and bag is not None:
                problems.append(f"{bag.path}: no result file of {code} {team} run {run}")
            own = bag or result
            root = None if own is None else layout_root(own)
            runs.append(
                RunFiles(
                    code,
                    team,
                    run,
                    bag,
                    result,
                    side.one(f"{code}'s config", side.configs.get(code, []), root),
                    side.one(f"team {team}'s transform", side.transforms.get(team, []), root),
                    side.one("the items (items_with_pose.yaml)", side.items, root)
                    if code in season_items
                    else None,
                )
            )

    def when(r: RunFiles) -> datetime:
        f = r.bag or r.result
        return f.local_time if f is not None and f.local_time is not None else datetime.min

    runs.sort(key=lambda r: (r.code, r.team, when(r), r.run))
    return tuple(runs), (*side.problems, *problems)


def scan(root: str | Path, season_items: Collection[str] = ()) -> SeasonLayout:
    """List ``root`` recursively (symbolic links to folders not followed) and recognise it
    (``season_items``: as :func:`pair_runs`).

    Raises:
        UsageError: ``root`` is not a folder.
    """
    base = Path(root)
    if not base.is_dir():
        raise UsageError(f"{base}: not a folder (give the season's RSBB output folder)")
    found: list[SeasonFile] = []
    for folder, dirs, names in os.walk(base):
        dirs.sort()
        for name in sorted(names):
            f = classify(Path(folder) / name)
            if f is not None:
                found.append(f)
    runs, problems = pair_runs(found, season_items)
    return SeasonLayout(base, tuple(sorted(found, key=lambda f: str(f.path))), runs, problems)
