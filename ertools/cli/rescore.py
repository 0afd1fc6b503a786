"""Score a whole competition: every benchmark execution, through the registry, in parallel.

The manifest (--config, docs/rescore.md) names each benchmark's inputs and each team's (its
transform...). Writes DIR/results.json (every execution: inputs with SHA-256, status, the
`ertools score NAME --format json` object, rank value), DIR/results.csv (one row each), one
report folder per execution (DIR/executions/ID/) and the results page DIR/index.html. A second
run recomputes only what changed (DIR/cache). Exit 0 when every execution was scored, 1 when
some were not (the rest is still scored and written), 2 for usage errors.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ertools.atomic import write_text
from ertools.cli.output import note
from ertools.cli.text import one_line
from ertools.competition.draft import draft_text
from ertools.competition.found import find
from ertools.competition.manifest import ManifestError, load_manifest
from ertools.competition.parallel import default_jobs
from ertools.competition.run import rescore_competition
from ertools.errors import UsageError
from ertools.inputs import read_regular

if TYPE_CHECKING:
    from ertools.competition.jobs import Outcome

EPILOG = """examples:
  ertools rescore --config competition.yaml --out results/
  ertools rescore logs/ --config competition.yaml --out results/ --jobs 8
  ertools rescore logs/ --config competition.yaml --out results/ --scheduler tcp://10.0.0.5:8786
  ertools rescore --config competition.yaml --check
  ertools rescore logs/ --init competition.yaml
  ertools rescore logs/ --out results/     # no manifest: drafted from the logs, kept as
                                           # results/manifest.yaml

--scheduler needs `pip install 'ertools[dask]'`; its workers must see the logs at the same paths
(a shared file system): only paths and values go through the scheduler."""


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "paths", nargs="*", type=Path, metavar="PATH", help="folders and files of logs"
    )
    parser.add_argument(
        "--config",
        type=Path,
        metavar="FILE",
        help="the competition manifest (YAML, docs/rescore.md)",
    )
    parser.add_argument("--out", type=Path, metavar="DIR", help="the results folder")
    parser.add_argument(
        "--init",
        type=Path,
        metavar="FILE",
        help="draft the manifest FILE from the logs under PATH (every execution found, its "
        "team, the inputs found and TODO lines for those missing); nothing is scored",
    )
    parser.add_argument(
        "--check",
        action="store_true",
        help="only validate the manifest: every problem, one line each (exit 1 if any)",
    )
    parser.add_argument(
        "--jobs",
        "-j",
        type=int,
        metavar="N",
        help="local worker processes (default: the cores this process may use; 1: in this process)",
    )
    parser.add_argument(
        "--scheduler",
        metavar="ADDRESS",
        help="score on a Dask cluster: a scheduler address (tcp://host:8786), or `local` for a "
        "LocalCluster of --jobs workers (pip install 'ertools[dask]')",
    )
    parser.add_argument(
        "--no-cache",
        action="store_true",
        help="score every execution again (DIR/cache is refreshed, not read)",
    )
    parser.add_argument(
        "--no-reports",
        action="store_true",
        help="no report folder per execution (faster; the results page links none)",
    )


def run(args: argparse.Namespace) -> int:
    if args.init is not None:
        return _init(args)
    if args.config is None and (not args.paths or args.out is None or args.check):
        raise UsageError(
            "--config FILE is needed: the competition manifest (docs/rescore.md); or give the "
            "folders of logs and --out DIR to score them with a manifest drafted from them"
        )
    if args.out is None and not args.check:
        raise UsageError("--out DIR is needed: where results.json and the reports go")
    if args.jobs is not None and args.jobs < 1:
        raise UsageError(f"--jobs {args.jobs}: give 1 or more worker processes")
    for path in args.paths:
        if not path.exists():
            raise UsageError(f"{path}: no such file or folder")
    if args.config is None:
        args.config = _draft(args)
    try:
        manifest = load_manifest(args.config)
    except ManifestError as err:
        for problem in err.problems:
            note(f"error: {args.config}: {problem}")
        note(f"error: {len(err.problems)} problem(s) in {args.config}; nothing was scored")
        return 1
    if args.check:
        for line in manifest.duplicates:
            note(f"warning: {args.config}: {line}")
        note(f"{args.config}: no problems ({len(manifest.executions)} listed executions)")
        return 0

    def waiting(holder: str) -> None:
        note(
            f"{args.out} is being written by another ertools rescore (process {holder}); "
            "waiting for it to end (Ctrl-C to stop, or give another --out)"
        )

    def tell(outcome: Outcome) -> None:
        if outcome.status != "scored":
            note(f"error: {outcome.id}: {outcome.status}: {outcome.reason}")

    done = rescore_competition(
        args.paths,
        manifest,
        args.out,
        workers=args.jobs if args.jobs is not None else default_jobs(),
        scheduler=args.scheduler,
        use_cache=not args.no_cache,
        reports=not args.no_reports,
        command=args.command_line,
        progress=args.progress,
        on_outcome=tell,
        on_wait=waiting,
    )
    for problem in done.doc["problems"]:
        # each execution's missing inputs are its error line; duplicates were warned of
        if problem["kind"] not in ("missing-input", "duplicate-execution"):
            _warn(problem)
    rows = done.doc["executions"]
    counts = {s: sum(r["status"] == s for r in rows) for s in ("scored", "unscoreable", "failed")}
    from_cache = sum(bool(r["cached"]) for r in rows)
    note(
        f"{len(rows)} executions: {counts['scored']} scored, {counts['unscoreable']} unscoreable, "
        f"{counts['failed']} failed ({from_cache} from the cache)"
    )
    for path in done.written:
        note(f"wrote {path}")
    sys.stdout.flush()
    return 0 if counts["scored"] == len(rows) else 1


DRAFTED = "manifest.yaml"


def _warn(problem: Mapping[str, Any]) -> None:
    """A problem of the logs (results.json's ``problems``) as one warning line: where, what."""
    where = f"{problem['path']}: " if problem.get("path") else ""
    note(f"warning: {where}{one_line(str(problem['message']))}")


def _draft(args: argparse.Namespace) -> Path:
    """DIR/manifest.yaml drafted from the logs, as --init writes it. One the user edited is
    never overwritten: a draft that differs from it is refused."""
    found = find(args.paths, progress=args.progress)
    if not found.executions:
        raise UsageError(
            f"no benchmark execution found under {', '.join(map(str, args.paths))}: "
            "`ertools rescore PATH --init FILE` lists why each file is not one"
        )
    target: Path = args.out / DRAFTED
    text = draft_text(found, args.paths, target, ["ertools", "rescore", *map(str, args.paths)])
    if target.exists() and read_regular(target) != text.encode("utf-8"):
        raise UsageError(
            f"{target} exists and is not the manifest drafted from these logs: "
            f"give --config {target} to score with it, or delete it"
        )
    args.out.mkdir(parents=True, exist_ok=True)
    write_text(target, text)
    todo = sum("TODO" in line for line in text.splitlines())
    note(
        f"no --config: wrote {target}, a manifest drafted from the logs "
        f"({len(found.executions)} execution(s)"
        + (f"; {todo} TODO line(s) left at their defaults" if todo else "")
        + f"; edit it, then give --config {target})"
    )
    return target


def _init(args: argparse.Namespace) -> int:
    if not args.paths:
        raise UsageError("--init FILE drafts the manifest from logs: give the PATHs to scan")
    if args.config is not None or args.out is not None:
        raise UsageError("--init FILE only drafts the manifest: no --config or --out with it")
    if args.init.exists():
        raise UsageError(f"--init {args.init}: the file exists; ertools does not overwrite it")
    for path in args.paths:
        if not path.exists():
            raise UsageError(f"{path}: no such file or folder")
    found = find(args.paths, progress=args.progress)
    for problem in found.problems:
        _warn(problem)
    text = draft_text(found, args.paths, args.init, args.command_line)
    args.init.parent.mkdir(parents=True, exist_ok=True)
    write_text(args.init, text)
    todo = sum("TODO" in line for line in text.splitlines())
    problems = sum(1 for p in found.problems if p.get("kind") != "no-team")
    note(
        f"wrote {args.init}: {len(found.executions)} execution(s), {todo} TODO line(s) "
        f"to fill in; {len(found.files)} file(s), each placed at the end of the draft"
        + (f" ({problems} with a problem)" if problems else "")
    )
    if not found.executions:
        note(
            f"warning: no benchmark execution found under {', '.join(map(str, args.paths))}: "
            f"why each file is not one is listed at the end of {args.init}"
        )
        return 1
    return 0
