"""``python -m ertools.samples OUTDIR [--only NAME...] [--seed N]``: write the sample logs.

``python -m ertools.samples --competition DIR [--seed N]`` writes the sample competition
instead (:mod:`ertools.samples.competition`): one day of logs at one venue and its
``answers.json``; DIR is replaced as a whole, like a scenario folder.

Every scenario (:func:`ertools.samples.scenario.scenarios`: each benchmark's, through the
registry, and the timeline folder and the season) is generated into
``OUTDIR/<name>/``, which is replaced as a whole (built in a folder of a unique name,
``OUTDIR/.<name>.XXXXXXXX.partial``, first, so a failure leaves the old folder in place).
Without ``--seed`` each scenario uses its fixed
default seed, so the output is byte-identical from run to run. An unknown scenario is an
error naming it, before anything is written. The answers of a scenario written in the RSBB's
layout (the season's, and each single-benchmark RSBB sample's: an organiser's folder holds no
answers, and ``ertools rescore`` would list one as not a log) are written beside its folder,
``OUTDIR/<name>.answers.yaml`` (:func:`~ertools.simulator.answers.answers_path` of the
folder), and move with it.
"""

from __future__ import annotations

import sys

if __name__ == "__main__":
    # `python -m ertools.samples`: the module run under its own name, its imports included,
    # inside ertools.launch's guard (a Ctrl-C while they load: one line, exit 130)
    from ertools.launch import run as launch

    def _start() -> object:
        from ertools.samples.__main__ import program  # lazy: in the Ctrl-C guard, 600 ms

        return program()

    sys.exit(launch(_start, "python -m ertools.samples"))

import argparse
import os
import shutil
import tempfile
from collections.abc import Sequence
from pathlib import Path

from ertools.atomic import replace_folder
from ertools.benchmarks.base import Generate
from ertools.errors import ErtoolsError
from ertools.samples.competition import DEFAULT_SEED, write_competition
from ertools.samples.scenario import ScenarioMissingError, load_scenario, scenarios, seed_of
from ertools.samples.simd import rerun_pinned
from ertools.simulator.answers import answers_path

SIZE_BUDGET_BYTES = 2_600_000  # per log; sample_bags/ as a whole stays under ~15 MB


def _size(path: Path) -> int:
    if path.is_dir():
        return sum(p.stat().st_size for p in sorted(path.rglob("*")) if p.is_file())
    return path.stat().st_size


def generate(outdir: Path, names: Sequence[str], seed: int | None = None) -> dict[str, list[Path]]:
    """Generate ``names`` into ``outdir/<name>/``; returns the paths each wrote."""
    generators: dict[str, Generate] = {}
    missing: list[str] = []
    for name in names:  # every module is loaded before anything is written
        try:
            generators[name] = load_scenario(name)
        except ScenarioMissingError as exc:
            missing.append(exc.message)
    if missing:
        raise ScenarioMissingError("; ".join(missing))
    written: dict[str, list[Path]] = {}
    outdir.mkdir(parents=True, exist_ok=True)
    for name, gen in generators.items():
        final = outdir / name
        # a folder of a unique name: two runs at once each build their own (the last rename
        # wins, with a whole folder)
        partial = Path(tempfile.mkdtemp(dir=outdir, prefix=f".{name}.", suffix=".partial"))
        beside = answers_path(partial)
        try:
            paths = gen(partial, seed=seed_of(name) if seed is None else seed)
        except BaseException:
            shutil.rmtree(partial, ignore_errors=True)
            beside.unlink(missing_ok=True)
            raise
        replace_folder(partial, final)
        if beside.exists():  # after its folder: a failure above leaves the old pair
            os.replace(beside, answers_path(final))
        written[name] = [
            answers_path(final) if p == beside else final / p.relative_to(partial) for p in paths
        ]
    return written


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m ertools.samples",
        description="Write simulated 2015 benchmark logs with their answers.",
        epilog="example: python -m ertools.samples sample_bags --only stationary fbm3w",
    )
    parser.add_argument(
        "outdir", type=Path, nargs="?", help="folder to write into (OUTDIR/<scenario>/)"
    )
    parser.add_argument(
        "--competition",
        type=Path,
        metavar="DIR",
        help="write the sample competition (a day of logs at one venue) into DIR instead",
    )
    parser.add_argument(
        "--only", nargs="+", metavar="NAME", choices=list(scenarios()), help="scenarios to write"
    )
    parser.add_argument("--seed", type=int, help="one seed for all (default: fixed per scenario)")
    args = parser.parse_args(argv)
    if args.competition is not None:
        if args.outdir is not None or args.only:
            parser.error("--competition DIR takes no OUTDIR and no --only")
        return _competition(args.competition, args.seed)
    if args.outdir is None:
        parser.error("give OUTDIR (or --competition DIR)")
    names = list(args.only) if args.only else list(scenarios())
    try:
        written = generate(args.outdir, names, args.seed)
    except ErtoolsError as exc:
        print(f"ertools.samples: error: {exc}", file=sys.stderr)
        return 1
    for name, paths in written.items():
        for path in paths:
            size = _size(path)
            flag = "  (over the size budget)" if size > SIZE_BUDGET_BYTES else ""
            print(f"{name}\t{size:>10,d}\t{path}{flag}")
    return 0


def _competition(outdir: Path, seed: int | None) -> int:
    paths = write_competition(outdir, seed=DEFAULT_SEED if seed is None else seed)
    total = sum(p.stat().st_size for p in paths)
    print(f"competition\t{total:>10,d}\t{outdir}\t({len(paths)} files)")
    return 0


def program() -> int:
    """``python -m ertools.samples``: :func:`main` on ``sys.argv``."""
    rerun_pinned(sys.argv[1:])  # bit-identical samples on AVX-512 CPUs too (samples.simd)
    return main()
