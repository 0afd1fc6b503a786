"""One rescoring of a competition, start to finish: the function behind ``ertools rescore``
and ``ertools.rescore()``, so the command and the library write the same results.

Under the results folder's lock: the logs under the paths found and merged with the manifest's
executions, the timeline written, every execution scored (in parallel, cached), every file
under the paths placed once (the ledger), ``results.json``, ``results.csv`` and the results
page written.
"""

from __future__ import annotations

import contextlib
import logging
import os
from collections.abc import Callable, Sequence
from contextlib import AbstractContextManager, nullcontext
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ertools.atomic import folder_lock
from ertools.benchmarks import registry
from ertools.competition.children import ertools_own, forks_ready
from ertools.competition.found import find, merge, write_timeline
from ertools.competition.ledger import account
from ertools.competition.manifest import Manifest
from ertools.competition.memo import FileMemo
from ertools.competition.parallel import early_dask
from ertools.competition.pipeline import listed_executions, rescore, write_results
from ertools.errors import ConfigError
from ertools.frozen_dataclass import frozen_dataclass

log = logging.getLogger(__name__)

if TYPE_CHECKING:
    from ertools.competition.jobs import Outcome
    from ertools.competition.parallel import DaskClient
    from ertools.progress import Reporter


@frozen_dataclass
class Rescored:
    """The results document (``results.json``) and the files written."""

    doc: dict[str, Any]
    written: tuple[Path, ...]


def rescore_competition(
    paths: Sequence[Path],
    manifest: Manifest,
    out: Path,
    *,
    workers: int,
    scheduler: str | None = None,
    use_cache: bool = True,
    reports: bool = True,
    command: Sequence[str] = (),
    progress: Reporter | None = None,
    on_outcome: Callable[[Outcome], None] | None = None,
    on_wait: Callable[[str], None] | None = None,
) -> Rescored:
    """Rescore the executions under ``paths`` and those ``manifest`` lists into ``out``.

    Raises:
        ConfigError: no execution found under ``paths`` and none listed (nothing written but
            the timeline).
    """
    # two runs into one folder would mix their reports and caches: one at a time
    with contextlib.ExitStack() as stack:
        stack.enter_context(folder_lock(out, on_wait=on_wait))
        # A first run into this folder scores everything: a Dask cluster is started now, while
        # the logs are scanned, not after (a rerun starts one only if the cache lacks a score)
        cold = not use_cache or not any((out / "cache" / "outcomes").glob("*.json"))
        stack.enter_context(_scoring_processes(scheduler, workers, cold=cold))
        dask = early_dask(scheduler, workers, cold)
        try:
            return _rescore(
                paths,
                manifest,
                out,
                workers=workers,
                scheduler=scheduler,
                use_cache=use_cache,
                reports=reports,
                command=command,
                progress=progress,
                on_outcome=on_outcome,
                dask=dask,
            )
        finally:
            if dask is not None:
                dask.close()  # closing since the last job ended, while the results were written


def _scoring_processes(
    scheduler: str | None, workers: int, *, cold: bool
) -> AbstractContextManager[None]:
    """The scoring processes' fork server (:mod:`ertools.competition.children`), forked now, while
    this process has one thread: a LocalCluster's workers are threads of this process."""
    if scheduler == "local" or (scheduler is None and workers > 1):
        # On a first run, what ertools' benchmarks import lazily, imported by the server while
        # the logs are scanned (a rerun may score nothing; a test's registry holds none)
        ours = any(ertools_own(registry.target(n)) for n in registry.names())
        return forks_ready(preload=cold and ours)
    return nullcontext()


def _rescore(
    paths: Sequence[Path],
    manifest: Manifest,
    out: Path,
    *,
    workers: int,
    scheduler: str | None,
    use_cache: bool,
    reports: bool,
    command: Sequence[str],
    progress: Reporter | None,
    on_outcome: Callable[[Outcome], None] | None,
    dask: DaskClient | None,
) -> Rescored:
    scorings = listed_executions(manifest)
    problems: list[dict[str, object]] = []
    for line in manifest.duplicates:  # each scored once (load_manifest): said once too
        log.warning("%s: %s", manifest.path, line)
        problems.append(
            {"kind": "duplicate-execution", "path": str(manifest.path), "message": line}
        )
    timeline = None
    found = None
    if paths:
        # what each log says, remembered between runs (a warm rerun reads no log)
        memo = FileMemo(out / "cache" / "files.json", load=use_cache)
        found = find(paths, progress=progress, memo=memo)
        memo.save()
        scorings = merge(found.scorings, scorings)
        problems += found.problems
        out.mkdir(parents=True, exist_ok=True)
        timeline = write_timeline(found, out, manifest.title)
    if not scorings:
        where = ", ".join(map(str, paths)) or "no logs were given"
        raise ConfigError(
            f"no benchmark execution found ({where}) and none listed in the manifest",
            path=manifest.path,
        )
    doc = rescore(
        scorings,
        manifest,
        out,
        workers=workers,
        scheduler=scheduler,
        use_cache=use_cache,
        reports=reports,
        command=list(command),
        problems=problems,
        timeline=timeline,
        progress=progress,
        on_outcome=on_outcome,
        dask=dask,
    )
    if found is not None:  # every file under PATH in one place (docs/rescore.md, "files")
        robots = {str(s.bags[0]): s.of for s in found.scorings if s.of is not None}
        # the results folder inside a scanned one holds no input: its files are none of its
        # logs' (they were listed as unused on the next run)
        mine = str(out.resolve()) + os.sep
        files = [f for f in found.files if not f.startswith(mine)]
        doc = account(doc, files, found.folders, robots)
    return Rescored(doc, tuple(write_results(doc, out)))
