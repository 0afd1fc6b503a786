"""A/B of whole ertools commands between source trees, interleaved on the same machine.

    .venv/bin/python bench/ab_commands.py TREE [TREE...] [--runs N] [--only ROW...]

Issue 37's timing table: `ertools --version`, the parser of `score trajectory` (issue 39),
`score fbm3w` on the sample and `score trajectory` on the hour of bench/data.py. Every tree runs
with this interpreter and ``PYTHONPATH=TREE``, its bytecode compiled first; each command is a
fresh process (wall, user+sys CPU and peak RSS from ``os.wait4``), the trees alternate order
every run, and the medians are printed. Make an old tree with
``git worktree add --detach ../pre37 pre37``. One tree gives that tree's figures alone.
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

HERE = Path(__file__).resolve().parent

# `ertools` as the console script runs it; an old tree has no ertools/__main__.py.
ERTOOLS = ["-c", "from ertools.cli.main import main; raise SystemExit(main())"]
PARSER = """
import time
t = time.perf_counter()
from ertools.cli.main import build_parser
build_parser("ertools score trajectory", "ertools.cli.score")
print(time.perf_counter() - t)
"""
SAMPLE = "sample_bags/fbm3w"


@dataclass
class Row:
    key: str
    argv: list[str]
    runs: int
    cwd_is_tree: bool = False


@dataclass
class Sample:
    wall: float
    cpu: float
    rss_mib: float


HOUR = """
import sys
from pathlib import Path
from bagwrite import write_ros1
from data import GT_TOPIC, ROBOT_TOPIC, T0, gt_topics, robot_topics
folder = Path(sys.argv[1])
robot, gt = folder / "robot_hour.bag", folder / "gt_hour.bag"
if not (robot.exists() and gt.exists()):
    folder.mkdir(parents=True, exist_ok=True)
    write_ros1(gt, gt_topics(T0, 3600, seed=1))
    write_ros1(robot, robot_topics(T0, 3600, seed=2))
print(robot, gt, ROBOT_TOPIC, GT_TOPIC)
"""


def hour_args() -> list[str]:
    """`score trajectory`'s arguments for the robot and GT hours of bench/data.py, written
    once under build/bench/ab/. In a child process: the peak RSS that ``os.wait4`` reports
    for a child counts its parent's pages at the fork."""
    folder = HERE.parent / "build" / "bench" / "ab"
    robot, gt, robot_topic, gt_topic = subprocess.run(
        [sys.executable, "-c", HOUR, str(folder)],
        env=dict(os.environ, PYTHONPATH=str(HERE)),
        capture_output=True,
        text=True,
        check=True,
    ).stdout.split()
    return [robot, gt, "--robot-topic", robot_topic, "--gt-topic", gt_topic]


def rows(runs: int | None) -> list[Row]:
    fbm3w = [
        "score",
        "fbm3w",
        f"{SAMPLE}/log_fbm3w_mocap_2015-11-20-12-00-00_0.bag",
        "--config",
        f"{SAMPLE}/fbm3w.yaml",
        "--format",
        "json",
    ]
    hour = ["score", "trajectory", *hour_args(), "--format", "json"]
    return [
        Row("version", [*ERTOOLS, "--version"], runs or 21),
        Row("parser", ["-X", "importtime", "-c", PARSER], runs or 21),
        Row("fbm3w sample", [*ERTOOLS, *fbm3w], runs or 7, cwd_is_tree=True),
        Row("hour trajectory", [*ERTOOLS, *hour], runs or 3),
    ]


def ertools_import_us(stderr: str) -> int:
    """The cumulative import time (us) of the ertools modules imported at the outermost level
    (`-X importtime`: one space before a name there, two more per level of nesting), which
    includes everything they import."""
    total = 0
    for line in stderr.splitlines():
        parts = line.split("|")
        if len(parts) == 3 and parts[2].startswith(" ertools") and parts[1].strip().isdigit():
            total += int(parts[1])
    return total


def run_one(tree: Path, row: Row) -> tuple[Sample, int, str]:
    """One fresh process: its figures, its ertools import time (us) and its stdout."""
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    env["PYTHONPATH"] = str(tree)
    with tempfile.TemporaryFile("w+") as out, tempfile.TemporaryFile("w+") as err:
        start = time.perf_counter()
        proc = subprocess.Popen(
            [sys.executable, *row.argv],
            env=env,
            cwd=tree if row.cwd_is_tree else "/",
            stdout=out,
            stderr=err,
        )
        _pid, status, usage = os.wait4(proc.pid, 0)
        wall = time.perf_counter() - start
        proc.returncode = os.waitstatus_to_exitcode(status)
        out.seek(0)
        err.seek(0)
        stdout, stderr = out.read(), err.read()
    if proc.returncode != 0:
        raise SystemExit(f"{tree}: {' '.join(row.argv)} failed:\n{stderr[-2000:]}")
    sample = Sample(wall, usage.ru_utime + usage.ru_stime, usage.ru_maxrss / 1024)
    return sample, ertools_import_us(stderr), stdout


def main() -> int:
    parser = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    parser.add_argument("trees", nargs="+", type=Path)
    parser.add_argument("--runs", type=int, default=None, help="runs per row (default: per row)")
    parser.add_argument("--only", nargs="*", default=None, help="row keys to run")
    args = parser.parse_args()
    trees = [t.resolve() for t in args.trees]
    for tree in trees:
        subprocess.run(
            [sys.executable, "-m", "compileall", "-q", str(tree / "ertools")], check=True
        )
    load0 = os.getloadavg()
    table = [r for r in rows(args.runs) if args.only is None or r.key in args.only]
    results: dict[tuple[str, Path], list[Sample]] = {}
    imports: dict[tuple[str, Path], list[int]] = {}
    built: dict[Path, list[float]] = {}
    for row in table:
        for run in range(row.runs):
            for tree in trees if run % 2 == 0 else trees[::-1]:
                sample, import_us, stdout = run_one(tree, row)
                results.setdefault((row.key, tree), []).append(sample)
                imports.setdefault((row.key, tree), []).append(import_us)
                if row.key == "parser":
                    built.setdefault(tree, []).append(float(stdout))
    load1 = os.getloadavg()
    print(f"load average at start {load0[0]:.2f}, at end {load1[0]:.2f}")
    for row in table:
        for tree in trees:
            got = results[row.key, tree]
            wall = [s.wall for s in got]
            line = (
                f"{row.key:16} {tree.name:10} wall {statistics.median(wall) * 1e3:8.1f} ms"
                f" [{min(wall) * 1e3:.0f}-{max(wall) * 1e3:.0f}]"
                f"  CPU {statistics.median(s.cpu for s in got) * 1e3:8.1f} ms"
                f"  RSS {statistics.median(s.rss_mib for s in got):6.1f} MiB"
            )
            if row.key == "parser":
                line += (
                    f"  built in {statistics.median(built[tree]) * 1e3:.1f} ms"
                    f" (ertools imports {statistics.median(imports[row.key, tree]) / 1e3:.1f} ms)"
                )
            print(line, flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
