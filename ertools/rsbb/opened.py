"""A run bag opened for its script's score: another benchmark's bag refused, its events read,
its side files found (the team transform also for the result file's team) and its result file
loaded, as every benchmark whose script reads a team transform does it first."""

from __future__ import annotations

from collections.abc import Collection
from dataclasses import dataclass
from pathlib import Path
from typing import Protocol

from ertools.errors import UsageError
from ertools.rsbb.log import RsbbRun, check_code, read_rsbb_run
from ertools.rsbb.results import RsbbResult, load_result
from ertools.rsbb.sidefiles import SideFiles, find_side_files


class SideOptions(Protocol):
    """The side files a benchmark's options name (None: look for it)."""

    @property
    def config(self) -> Path | None: ...

    @property
    def transform(self) -> Path | None: ...

    @property
    def result(self) -> Path | None: ...

    @property
    def team(self) -> str | None: ...


@dataclass(frozen=True, eq=False)
class OpenedRun:
    """A run bag and its side files.

    Attributes:
        bag: the run bag.
        run: its RefBox/BmBox events and live scores.
        side: the side files given or found (``side.config`` the script's config).
        result: the result file loaded (None: none found).
        team: the layout's team, else the result file's (None: neither).
        transform: the team transform's file (None: none found, for the benchmark to refuse).
        found: one line per file found rather than given, for stderr.
    """

    bag: Path
    run: RsbbRun
    side: SideFiles
    result: RsbbResult | None
    team: str | None
    transform: Path | None
    found: tuple[str, ...]

    def transform_file(self) -> Path:
        """The team transform's file.

        Raises:
            UsageError: none was given or found.
        """
        if self.transform is None:
            raise UsageError(
                f"no transform-{self.team or '<team>'}.yaml beside the bag or in "
                "rsbb_etc/transforms/: give --transform FILE (the team's "
                "markerset_to_robot_transform)"
            )
        return self.transform


def open_run(
    bag: Path,
    code: str,
    given: SideOptions,
    *,
    want: Collection[str] = ("config", "transform", "result"),
) -> OpenedRun:
    """The bag of a ``code`` run with the side files ``want`` (given, else found).

    Raises:
        UsageError: a bag in another benchmark's folder of the layout.
        ConfigError: a bag whose live scores name another benchmark; an unreadable result file.
        TopicError, BagError: an unreadable bag.
    """
    side = find_side_files(
        bag,
        code,
        want=want,
        config=given.config,
        transform=given.transform,
        result=given.result,
        team=given.team,
    )
    if side.place.code not in (None, code):
        raise UsageError(
            f"{bag} is an {side.place.code} run (rsbb_logs/{side.place.code}/...): "
            f"ertools score {side.place.code.lower()}"
        )
    run = read_rsbb_run(bag)
    check_code(run, code)  # outside the layout, the live score names the benchmark
    loaded = load_result(side.result) if side.result is not None else None
    found = list(side.found)
    owner = side.team or (loaded.team if loaded is not None else None)
    path = side.transform
    if "transform" in want and path is None and owner is not None and side.team is None:
        # outside the layout the team comes from the result file: its transform, looked for
        again = find_side_files(bag, code, want={"transform"}, team=owner)
        path = again.transform
        found += again.found
    return OpenedRun(bag, run, side, loaded, owner, path, tuple(found))
