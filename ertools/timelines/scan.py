"""The IO edge of the timeline: find bags, summarise them, check their clocks.

Everything read here goes through :mod:`ertools.io`: summaries come from each file's index
(never its message data), and the clock check decodes only the first second of one pose topic
per bag with a windowed read. :func:`scan` returns the pure
:class:`~ertools.timelines.model.Timeline`.
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Sequence
from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING

from ertools.benchmarks import registry
from ertools.errors import ErtoolsError
from ertools.io.clock import ClockCheck, clock_check
from ertools.io.formats import Found, Unreadable, find_bags, regular_files
from ertools.io.summary import summary
from ertools.progress import reporting
from ertools.rsbb.layout import classify, pair_runs
from ertools.timelines.build import build_timeline, split_name
from ertools.timelines.model import RsbbFolder, RsbbRunFiles, Timeline, TimelineConfig

if TYPE_CHECKING:
    from ertools.io.model import BagSummary
    from ertools.progress import Reporter

log = logging.getLogger("ertools.timelines.scan")


def check_recordings(
    summaries: Sequence[BagSummary],
    tolerance_ns: int,
    on_progress: Callable[[int], None] | None = None,
    check: Callable[[BagSummary], ClockCheck | None] | None = None,
) -> list[ClockCheck]:
    """Clock checks, one per recording unless it finds a problem.

    A machine's clock offset does not change between the split files of one recording, so
    only the first file of each (``split_name`` group) is read; when it is off by more than
    ``tolerance_ns`` the other files of that recording are checked too, so every flagged
    file was measured. Files that are not split files are each checked.
    """
    check = check or clock_check
    groups: dict[str, list[tuple[int, BagSummary]]] = {}
    for s in summaries:
        split = split_name(s.path)
        key, index = (split[0], split[1]) if split is not None else (str(s.path), 0)
        groups.setdefault(key, []).append((index, s))
    checks: list[ClockCheck] = []
    done = 0
    for members in groups.values():
        members.sort(key=lambda m: m[0])
        first = check(members[0][1])
        done += 1
        if on_progress is not None:
            on_progress(done)
        if first is None:
            continue
        checks.append(first)
        if abs(first.offset_ns) > tolerance_ns:
            for _, s in members[1:]:
                c = check(s)
                if c is not None:
                    checks.append(c)
    return checks


def _ticker(progress: Reporter) -> Callable[[int], None]:
    """``on_progress(done)`` callbacks (a count so far) as the reporter's increments."""
    last = [0]

    def tick(done: int) -> None:
        progress.advance(done - last[0])
        last[0] = done

    return tick


def summarise(
    bags: Sequence[Path], on_progress: Callable[[int], None] | None = None
) -> tuple[list[BagSummary], list[Unreadable]]:
    """Summaries of the readable bags and one line for each unreadable one."""

    good: list[BagSummary] = []
    bad: list[Unreadable] = []
    for i, path in enumerate(bags):
        try:
            good.append(summary(path))
        except ErtoolsError as err:
            bad.append(Unreadable(str(path), err.message))
        except Exception as err:  # a reader bug on one odd file must not hide the others
            log.debug("summary of %s failed", path, exc_info=True)
            bad.append(Unreadable(str(path), f"unreadable ({type(err).__name__}: {err})"))
        if on_progress is not None:
            on_progress(i + 1)
    return good, bad


def scan(
    paths: Sequence[str | Path],
    config: TimelineConfig | None = None,
    *,
    check_clocks: bool = True,
    progress: Reporter | None = None,
    clock: Callable[[BagSummary], ClockCheck | None] | None = None,
) -> Timeline:
    """Find, summarise and clock-check the bags under ``paths`` and build their timeline.

    Args:
        paths: files and folders.
        config: thresholds.
        check_clocks: compare header stamps with record times (reads a second per bag).
        progress: gets the bags summarised, then the recordings clock-checked.
        clock: the clock check of one bag (a rescore passes one that remembers its checks).
    """

    found = find_bags(Path(p) for p in paths)
    with reporting(None):  # counted by bag and recording: the reads inside do not report
        timeline = _scan(found, config, check_clocks, progress, clock)
    return replace(timeline, rsbb=rsbb_folder([Path(p) for p in paths]))


def rsbb_folder(paths: Sequence[Path]) -> RsbbFolder | None:
    """The RSBB season layout of the files under ``paths`` (by their names and folders: no
    file is opened), None when no run bag or result file is there."""
    files, _problems = regular_files(paths)  # an unlistable folder: the scan's problem already
    recognised = [f for f in (classify(p) for p in sorted(files)) if f is not None]
    if not any(f.code is not None and f.run is not None for f in recognised):
        return None
    runs, problems = pair_runs(recognised, registry.season_items())

    def text(path: Path | None) -> str | None:
        return None if path is None else str(path)

    return RsbbFolder(
        tuple(
            RsbbRunFiles(
                r.code,
                r.team,
                r.run,
                None if r.bag is None else str(r.bag.path),
                None if r.result is None else str(r.result.path),
                text(r.config),
                text(r.transform),
                text(r.items),
            )
            for r in runs
        ),
        tuple((f.kind.value, str(f.path)) for f in recognised),
        problems,
    )


def _scan(
    found: Found,
    config: TimelineConfig | None,
    check_clocks: bool,
    progress: Reporter | None,
    clock: Callable[[BagSummary], ClockCheck | None] | None = None,
) -> Timeline:
    tick: Callable[[int], None] | None = None
    if progress is not None:
        progress.task("summarising", len(found.bags), "bags")
        tick = _ticker(progress)
    summaries, unreadable = summarise(found.bags, tick)
    checks: list[ClockCheck] = []
    if check_clocks:
        tolerance = (config or TimelineConfig()).clock_tolerance_ns
        if progress is not None:  # one check per recording (see check_recordings)
            recordings = {(split_name(s.path) or (s.path, 0))[0] for s in summaries}
            progress.task("checking clocks", len(recordings), "recordings")
            tick = _ticker(progress)
        checks = check_recordings(summaries, tolerance, tick, clock)
    return build_timeline(summaries, [*found.problems, *unreadable], checks, config)
