"""A run bag of one RSBB benchmark opened with its side files: the files given or found (each
said), the run's result file and its events read, each checked to be that benchmark's."""

from __future__ import annotations

from collections.abc import Callable, Collection, Sequence
from dataclasses import dataclass
from pathlib import Path

from ertools.errors import ConfigError
from ertools.rsbb.log import RsbbRun, check_code, read_rsbb_run
from ertools.rsbb.results import RsbbResult, load_result
from ertools.rsbb.sidefiles import SideFiles, find_side_files


@dataclass(frozen=True)
class RunFiles:
    """A run's bag (or its split files), side files, result file (None: none) and events."""

    paths: tuple[Path, ...]
    side: SideFiles
    result_file: RsbbResult | None
    run: RsbbRun


def open_run(
    bags: Sequence[Path],
    code: str,
    *,
    want: Collection[str],
    say: Callable[[str], None],
    config: Path | None = None,
    items: Path | None = None,
    result: Path | None = None,
) -> RunFiles:
    """The run of ``code`` in ``bags`` with the side files ``want`` (given, else found: each
    found one is said through ``say`` before anything is read).

    Raises:
        ConfigError: a side file missing or unreadable, or another benchmark's bag or result file.
        TopicError, BagError: not an RSBB run bag.
    """
    paths = tuple(Path(b) for b in bags)
    side = find_side_files(paths[0], code, want=want, config=config, items=items, result=result)
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
    run = read_rsbb_run(paths)
    check_code(run, code)  # outside the layout, the live score names the benchmark
    return RunFiles(paths, side, result_file, run)
