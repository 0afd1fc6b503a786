"""The files a run's script read, found beside its bag in the RSBB's folder layout.

A run bag sits at ``<root>/rsbb_logs/<CODE>/<team>/run_<n>_<date>.bag``; its result file at
``<root>/results/<CODE>/<team>/result_run_<n>_<date>.yaml``; the script's inputs in
``rsbb_bmbox/scripts/benchmark_configs/<CODE>.yaml``, ``rsbb_etc/transforms/transform-<team>.yaml``
and ``rsbb_etc/objects_informations/items_with_pose.yaml`` (docs/rsbb.md, "What an RSBB run
writes"). A file given as an option wins; otherwise the bag's own folder is searched first
(a flat folder holding one run and its files), then the layout's places under ``<root>``.
Every file found, not given, is named in :attr:`SideFiles.found` for the benchmark to say on
stderr.
"""

from __future__ import annotations

import math
from collections.abc import Collection
from datetime import datetime
from pathlib import Path
from typing import Any

from ertools.configs._yaml import load_yaml
from ertools.errors import ConfigError, UsageError
from ertools.frozen_dataclass import frozen_dataclass
from ertools.rsbb.layout import PAIR_TOLERANCE, FileKind, bag_name, classify, result_name
from ertools.rsbb_states import LOGS_DIR, RESULTS_DIR

SIDE_KINDS = ("config", "transform", "items", "result")

#: Folders under the season's root searched for each side file, in order (after the bag's own).
CONFIG_DIRS = ("rsbb_bmbox/scripts/benchmark_configs", "benchmark_configs", "rsbb_etc/config", ".")
TRANSFORM_DIRS = ("rsbb_etc/transforms", "transforms", ".")
ITEMS_DIRS = ("rsbb_etc/objects_informations", "objects_informations", ".")
ITEMS_NAME = "items_with_pose.yaml"


@frozen_dataclass
class RunPlace:
    """Where a run bag sits: its code, team, run and start from the RSBB's names.

    Attributes:
        bag: the bag.
        code, team, run: from ``rsbb_logs/<CODE>/<team>/run_<n>_...``; None outside the layout
            (``run`` is still read from a ``run_<n>_<date>.bag`` name in any folder).
        local_time: rosbag's local start time in the name, or None.
        root: the folder holding ``rsbb_logs/`` (the RSBB's output folder), or None.
    """

    bag: Path
    code: str | None
    team: str | None
    run: int | None
    local_time: datetime | None
    root: Path | None


def run_place(bag: str | Path) -> RunPlace:
    """The RSBB layout's reading of a bag's path (pure: no file is opened)."""
    path = Path(bag)
    found = classify(path)
    if found is not None and found.kind is FileKind.RUN_BAG:
        parts = path.parts
        k = max(i for i, part in enumerate(parts[:-1]) if part == LOGS_DIR)
        root = Path(*parts[:k]) if k > 0 else Path(".")
        return RunPlace(path, found.code, found.team, found.run, found.local_time, root)
    # a run bag's name outside the layout (a flat folder): the run and time, no code or team
    named = bag_name(path.name)
    if named is not None:
        return RunPlace(path, None, None, named[0], named[1], None)
    return RunPlace(path, None, None, None, None, None)


@frozen_dataclass
class SideFiles:
    """A run's side files (None: given by nobody and not found).

    Attributes:
        place: the bag's place in the layout.
        code: the benchmark code searched for.
        team: the team (given, else the layout's, else the result file's name is not read here).
        config: ``<CODE>.yaml``.
        transform: ``transform-<team>.yaml``.
        items: ``items_with_pose.yaml``.
        result: ``result_run_<n>_<date>.yaml``.
        found: one line per file found rather than given (``HNF.yaml found beside the bag:
            PATH``), for the benchmark to say on stderr.
    """

    place: RunPlace
    code: str
    team: str | None
    config: Path | None
    transform: Path | None
    items: Path | None
    result: Path | None
    found: tuple[str, ...]


def _first(folders: list[Path], name: str) -> Path | None:
    for folder in folders:
        candidate = folder / name
        if candidate.is_file():
            return candidate
    return None


def _folders(place: RunPlace, under_root: tuple[str, ...]) -> list[Path]:
    out = [place.bag.parent]
    if place.root is not None:
        out += [place.root / d for d in under_root]
    seen: list[Path] = []
    for folder in out:
        if folder not in seen:
            seen.append(folder)
    return seen


def _result_candidates(place: RunPlace, code: str, team: str | None) -> list[Path]:
    pattern = f"result_run_{place.run}_*.yaml" if place.run is not None else "result_run_*.yaml"
    folders = [place.bag.parent]
    if place.root is not None and team is not None:
        folders.append(place.root / RESULTS_DIR / code / team)
    out: list[Path] = []
    for folder in folders:
        if folder.is_dir():
            out += [p for p in sorted(folder.glob(pattern)) if p.is_file() and p not in out]
    return out


def _nearest_result(place: RunPlace, candidates: list[Path]) -> Path | None:
    """The candidate whose name's time is nearest the bag's (within the layout's pairing
    tolerance); without times, the only candidate, if there is one."""
    if place.local_time is None:
        return candidates[0] if len(candidates) == 1 else None
    timed: list[tuple[float, Path]] = []
    for path in candidates:
        named = result_name(path.name)
        if named is None or named[1] is None:
            continue
        gap = abs(named[1] - place.local_time)
        if gap <= PAIR_TOLERANCE:
            timed.append((gap.total_seconds(), path))
    return min(timed)[1] if timed else None


def find_side_files(
    bag: str | Path,
    code: str,
    *,
    want: Collection[str],
    config: Path | None = None,
    transform: Path | None = None,
    items: Path | None = None,
    result: Path | None = None,
    team: str | None = None,
) -> SideFiles:
    """The side files ``want`` (of :data:`SIDE_KINDS`) of the run in ``bag``: the given ones,
    else found beside the bag or in the layout (nothing is read; a missing one is None).

    Raises:
        UsageError: ``want`` names an unknown kind.
    """
    unknown = set(want) - set(SIDE_KINDS)
    if unknown:
        raise UsageError(f"unknown side file kind(s): {', '.join(sorted(unknown))}")
    place = run_place(bag)
    team = team if team is not None else place.team
    found: list[str] = []

    def note(what: str, path: Path | None) -> Path | None:
        if path is not None:
            where = "beside the bag" if path.parent == place.bag.parent else "in the RSBB layout"
            found.append(f"{what} found {where}: {path}")
        return path

    if config is None and "config" in want:
        config = note(f"{code}.yaml", _first(_folders(place, CONFIG_DIRS), f"{code}.yaml"))
    if transform is None and "transform" in want and team is not None:
        name = f"transform-{team}.yaml"
        transform = note(name, _first(_folders(place, TRANSFORM_DIRS), name))
    if items is None and "items" in want:
        items = note(ITEMS_NAME, _first(_folders(place, ITEMS_DIRS), ITEMS_NAME))
    if result is None and "result" in want:
        result = note(
            "the result file", _nearest_result(place, _result_candidates(place, code, team))
        )
    return SideFiles(place, code, team, config, transform, items, result, tuple(found))


#: The team transform's key: 2019 and December 2017 on; ``marker_to_robot_transform`` before.
TRANSFORM_KEYS = ("markerset_to_robot_transform", "marker_to_robot_transform")


def read_side_yaml(path: str | Path, what: str) -> Any:
    """A side file's YAML as the script's ``yaml.load`` saw it (``!!python/tuple`` as a list,
    no other Python tag; ``what`` names the file in errors).

    Raises:
        ConfigError: unreadable, not YAML, or a refused tag.
    """
    return load_yaml(path, what, tags="tuples")


def script_transform(
    path: str | Path, keys: tuple[str, ...] = TRANSFORM_KEYS
) -> tuple[tuple[float, float, float], tuple[float, float, float, float]]:
    """The team transform (translation, quaternion) exactly as the file writes it (the scripts
    broadcast it unnormalised), under the first of ``keys`` the file has.

    Raises:
        ConfigError: no such key, or not ``[[x, y, z], [qx, qy, qz, qw]]`` of numbers.
    """
    data = read_side_yaml(path, "transform")
    key = next((k for k in keys if isinstance(data, dict) and k in data), None)
    if key is None:
        raise ConfigError(f"transform file: no {' or '.join(keys)}", path=str(path))
    pair = data[key]
    ok = (
        isinstance(pair, list)
        and len(pair) == 2
        and all(isinstance(part, list) for part in pair)
        and [len(part) for part in pair] == [3, 4]
        and all(_is_real(v) for part in pair for v in part)
    )
    if not ok:
        raise ConfigError(
            f"{key}: expected [[x, y, z], [qx, qy, qz, qw]], got {pair!r}", path=str(path)
        )
    t, q = pair
    return (float(t[0]), float(t[1]), float(t[2])), (
        float(q[0]),
        float(q[1]),
        float(q[2]),
        float(q[3]),
    )


def _is_real(v: Any) -> bool:
    return isinstance(v, int | float) and not isinstance(v, bool) and math.isfinite(v)
