"""Start-up of `ertools score trajectory` (issue 39 item 2): from process start to the first
byte of a bag read, between source trees, interleaved.

    .venv/bin/python bench/startup.py TREE [TREE...] [--runs N] [--robot BAG --gt BAG]

Per tree and run, each a fresh process with this interpreter and ``PYTHONPATH=TREE`` (its
bytecode compiled first): the CPU time (``time.process_time``: the interpreter's start-up and
``site`` included) and the wall time since the parent started it, both taken when the command
first opens one of its bags (an audit hook); the whole process's CPU (``os.wait4``) of
``score trajectory ROBOT GT --format json --draws 0``; and, in another process, the sum of
``python -X importtime``'s self times. The trees alternate order every run; medians printed.
The hour is bench/data.py's, as `make bench` writes it under build/bench/.
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
BENCH = HERE.parent / "build" / "bench"

# The command as ertools/__main__.py runs it, with an audit hook noting the first open of a bag.
PROBE = """
import sys, time
BAGS = set(sys.argv[1:3])
first = []
def hook(event, args):
    if not first and event == "open" and isinstance(args[0], str) and args[0] in BAGS:
        first.append((time.process_time(), time.time()))
sys.addaudithook(hook)
sys.argv = ["ertools", "score", "trajectory", *sys.argv[1:]]
from ertools.__main__ import main
code = main()
cpu, when = first[0]
sys.stderr.write(f"\\nSTARTUP {cpu!r} {when!r}\\n")
sys.exit(code)
"""


def importtime_ms(line: str) -> float:
    """The self time of one ``-X importtime`` line, in ms (0 for the header)."""
    head = line.partition("|")[0].rpartition(":")[2].strip()
    return int(head) / 1000 if head.isdigit() else 0.0


def one_run(tree: Path, argv: list[str]) -> tuple[float, float, float, float]:
    """(CPU to the first byte, wall to it, whole-process CPU, importtime sum), in seconds."""
    env = dict(os.environ, PYTHONPATH=str(tree))
    env.pop("PYTHONDONTWRITEBYTECODE", None)
    start = time.time()
    # in the tree: `python -c` puts the working folder first on sys.path, before PYTHONPATH
    proc = subprocess.Popen(
        [sys.executable, "-c", PROBE, *argv],
        cwd=tree,
        env=env,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
    )
    assert proc.stderr is not None
    err = proc.stderr.read()
    _, status, usage = os.wait4(proc.pid, 0)
    if status != 0:
        raise SystemExit(f"{tree}: exit status {status}: {err.strip()[-300:]}")
    cpu, when = (float(x) for x in err.strip().splitlines()[-1].split()[1:])
    whole = usage.ru_utime + usage.ru_stime
    done = subprocess.run(
        [sys.executable, "-X", "importtime", "-c", PROBE, *argv],
        cwd=tree,
        env=env,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
        check=True,
    )
    imports = sum(importtime_ms(line) for line in done.stderr.splitlines()) / 1000
    return cpu, when - start, whole, imports


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.partition("\n")[0])
    parser.add_argument("trees", nargs="+", type=lambda p: Path(p).resolve())
    parser.add_argument("--runs", type=int, default=11)
    parser.add_argument("--robot", type=Path, default=BENCH / "robot_hour.bag")
    parser.add_argument("--gt", type=Path, default=BENCH / "gt_hour.bag")
    args = parser.parse_args()
    argv = [str(args.robot.resolve()), str(args.gt.resolve()), "--format", "json", "--draws", "0"]
    for tree in args.trees:
        compile_all = [sys.executable, "-m", "compileall", "-q", str(tree / "ertools")]
        subprocess.run(compile_all, check=True)
    results: dict[Path, list[tuple[float, float, float, float]]] = {t: [] for t in args.trees}
    for run in range(args.runs):
        order = args.trees if run % 2 == 0 else args.trees[::-1]
        for tree in order:
            results[tree].append(one_run(tree, argv))
    load = " ".join(f"{x:.1f}" for x in os.getloadavg())
    print(f"{args.runs} runs, load average {load}; medians [min]")
    print("| tree | CPU to first byte ms | wall to it ms | process CPU ms | importtime sum ms |")
    print("|---|---:|---:|---:|---:|")
    for tree, rows in results.items():
        cells = []
        for column in zip(*rows, strict=True):
            cells.append(f"{1000 * statistics.median(column):.1f} [{1000 * min(column):.1f}]")
        print(f"| {tree} | " + " | ".join(cells) + " |")


if __name__ == "__main__":
    main()
