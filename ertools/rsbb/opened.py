"""A run bag of one RSBB benchmark opened with its side files, as every benchmark re-scoring
an RSBB script does it first: the files given or found (each said before anything is read,
the team transform also for the result file's team), another benchmark's bag or result file
refused, the result file loaded and the run's events read."""

from __future__ import annotations

from collections.abc import Callable, Collection, Sequence
from pathlib import Path
from typing import Any, Protocol

from ertools.errors import ConfigError, UsageError
from ertools.frozen_dataclass import frozen_dataclass
from ertools.rsbb.log import RsbbRun, check_code, read_rsbb_run
from ertools.rsbb.results import RsbbResult, load_result
from ertools.rsbb.sidefiles import SideFiles, find_side_files


@frozen_dataclass(eq=False)
class OpenedRun:
    """A run's bag (or its split files) and its side files.

    Attributes:
        paths: the bag or its split files.
        side: the side files given or found (``side.config`` the script's config).
        result_file: the result file loaded (None: none given or found).
        run: its RefBox/BmBox events and live scores.
        team: the given or layout's team, else the result file's (None: neither).
        transform: the team transform's file (None: not wanted or none found).
    """

    paths: tuple[Path, ...]
    side: SideFiles
    result_file: RsbbResult | None
    run: RsbbRun
    team: str | None
    transform: Path | None

    def transform_file(self) -> Path:
        """The team transform's file.

        Raises:
            ConfigError: none was given or found (a file missing, not a command-line error:
                exit 1, docs/cli.md).
        """
        if self.transform is None:
            raise ConfigError(
                f"no transform-{self.team or '<team>'}.yaml beside the bag or in "
                "rsbb_etc/transforms/: give --transform FILE (the team's "
                "markerset_to_robot_transform)"
            )
        return self.transform


class SideOptions(Protocol):
    """The side files a benchmark's options name (None: look for it); ``transform``,
    ``items`` and ``team`` are read too where the benchmark has them."""

    @property
    def config(self) -> Path | None: ...

    @property
    def result(self) -> Path | None: ...


def _given(options: SideOptions, name: str) -> Any:
    return getattr(options, name, None)  # transform, items, team: not every benchmark has them


def open_run(
    bags: Sequence[Path],
    code: str,
    given: SideOptions,
    *,
    want: Collection[str],
    say: Callable[[str], None],
) -> OpenedRun:
    """The run of ``code`` in ``bags`` with the side files ``want`` (``given``, else found:
    each found one is said through ``say`` before anything is read).

    Raises:
        ConfigError: another benchmark's bag (by its folder in the layout, else its live
            score) or result file; an unreadable result file.
        TopicError, BagError: not an RSBB run bag.
    """
    paths = tuple(Path(b) for b in bags)
    side = find_side_files(
        paths[0],
        code,
        want=want,
        config=given.config,
        transform=_given(given, "transform"),
        items=_given(given, "items"),
        result=given.result,
        team=_given(given, "team"),
    )
    if side.place.code is not None and side.place.code != code:
        raise ConfigError(
            f"this bag is a {side.place.code} run (rsbb_logs/{side.place.code}/...), not "
            f"{code}'s: ertools score {side.place.code.lower()}",
            path=str(paths[0]),
        )
    for line in side.found:
        say(line)
    result_file = load_result(side.result) if side.result is not None else None
    if result_file is not None and result_file.code != code:
        raise ConfigError(
            f"the result file is a {result_file.code} run's, not {code}'s", path=result_file.path
        )
    owner = side.team or (result_file.team if result_file is not None else None)
    path = side.transform
    if "transform" in want and path is None and owner is not None and side.team is None:
        # outside the layout the team comes from the result file: its transform, looked for
        again = find_side_files(paths[0], code, want={"transform"}, team=owner)
        path = again.transform
        for line in again.found:
            say(line)
    run = read_rsbb_run(paths)
    check_code(run, code)  # outside the layout, the live score names the benchmark
    return OpenedRun(paths, side, result_file, run, owner, path)


def one_run_bag(logs: Sequence[Path], code: str) -> Path:
    """The one run bag a script benchmark scores.

    Raises:
        UsageError: none or several were given.
    """
    if len(logs) != 1:
        raise UsageError(
            f"give one {code} run bag (rsbb_logs/{code}/<team>/run_<n>_<date>.bag), not {len(logs)}"
        )
    return Path(logs[0])
