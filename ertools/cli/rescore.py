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
from pathlib import Path

from ertools.cli.common import note

EPILOG = """examples:
  ertools rescore --config competition.yaml --out results/
  ertools rescore logs/ --config competition.yaml --out results/ --jobs 8
  ertools rescore logs/ --config competition.yaml --out results/ --scheduler tcp://10.0.0.5:8786
  ertools rescore --config competition.yaml --check

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
        "--check",
        action="store_true",
        help="only validate the manifest: every problem, one line each (exit 1 if any)",
    )
    parser.add_argument(
        "--jobs",
        "-j",
        type=int,
        metavar="N",
        help="local worker processes (default: the CPU count; 1: in this process)",
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
    from ertools.errors import UsageError
    from ertools.rescore.manifest import ManifestError, load_manifest
    from ertools.rescore.parallel import default_jobs
    from ertools.rescore.pipeline import listed_executions, rescore, write_results

    if args.config is None:
        raise UsageError("--config FILE is needed: the competition manifest (docs/rescore.md)")
    if args.out is None and not args.check:
        raise UsageError("--out DIR is needed: where results.json and the reports go")
    if args.jobs is not None and args.jobs < 1:
        raise UsageError(f"--jobs {args.jobs}: give 1 or more worker processes")
    for path in args.paths:
        if not path.exists():
            raise UsageError(f"{path}: no such file or folder")
    try:
        manifest = load_manifest(args.config)
    except ManifestError as err:
        for problem in err.problems:
            note(f"error: {args.config}: {problem}")
        note(f"error: {len(err.problems)} problem(s) in {args.config}; nothing was scored")
        return 1
    if args.check:
        note(f"{args.config}: no problems ({len(manifest.executions)} listed executions)")
        return 0
    executions = listed_executions(manifest)
    if not executions:
        note(f"error: {args.config} lists no executions and no logs were given")
        return 1
    workers = args.jobs if args.jobs is not None else default_jobs()

    def tell(outcome: object) -> None:
        status = getattr(outcome, "status", "")
        if status != "scored":
            note(f"error: {getattr(outcome, 'id', '')}: {status}: {getattr(outcome, 'reason', '')}")

    doc = rescore(
        executions,
        manifest,
        args.out,
        workers=workers,
        scheduler=args.scheduler,
        use_cache=not args.no_cache,
        reports=not args.no_reports,
        command=args.command_line,
        progress=args.progress,
        on_outcome=tell,
    )
    written = write_results(doc, args.out)
    rows = doc["executions"]
    counts = {s: sum(r["status"] == s for r in rows) for s in ("scored", "unscoreable", "failed")}
    from_cache = sum(bool(r["cached"]) for r in rows)
    note(
        f"{len(rows)} executions: {counts['scored']} scored, {counts['unscoreable']} unscoreable, "
        f"{counts['failed']} failed ({from_cache} from the cache)"
    )
    for path in written:
        note(f"wrote {path}")
    sys.stdout.flush()
    return 0 if counts["scored"] == len(rows) else 1
