"""A/B of one pose topic read between two source trees, interleaved on the same machine.

    .venv/bin/python bench/ab_read.py OLD_TREE NEW_TREE FILE... [--runs N] [--topic T]

Each run is a fresh process per tree and file (trees alternate order every run), timing one
``read_poses`` after a warm-up read; the medians of wall and CPU time are printed. A shared,
loaded machine cannot give absolute figures, but it gives both trees the same conditions.
Make an old tree with ``git worktree add --detach ../old REV``.
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys

CODE = """
import sys, time
from ertools.io.reader import read_poses
path, topic = sys.argv[1], sys.argv[2]
read_poses(path, topic)
w, c = time.perf_counter(), time.process_time()
poses = read_poses(path, topic)
print(time.perf_counter() - w, time.process_time() - c, len(poses.t_ns))
"""


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("old")
    parser.add_argument("new")
    parser.add_argument("files", nargs="+")
    parser.add_argument("--runs", type=int, default=9)
    parser.add_argument("--topic", default="/fbm3w/robot_at_work/pose")
    args = parser.parse_args()
    trees = [args.old, args.new]
    times: dict[tuple[str, str], list[tuple[float, float, int]]] = {}
    for run in range(args.runs):
        for path in args.files:
            for tree in trees if run % 2 == 0 else trees[::-1]:
                env = dict(os.environ, PYTHONPATH=tree)
                out = subprocess.run(
                    [sys.executable, "-c", CODE, path, args.topic],
                    env=env,
                    cwd="/",
                    capture_output=True,
                    text=True,
                    check=True,
                ).stdout.split()
                times.setdefault((tree, path), []).append(
                    (float(out[0]), float(out[1]), int(out[2]))
                )
    for path in args.files:
        (w0, c0), (w1, c1) = (
            (
                statistics.median(t[0] for t in times[tree, path]),
                statistics.median(t[1] for t in times[tree, path]),
            )
            for tree in trees
        )
        print(
            f"{os.path.basename(path)}: old {w0 * 1e3:.1f} ms wall, {c0 * 1e3:.1f} ms CPU; "
            f"new {w1 * 1e3:.1f} ms wall, {c1 * 1e3:.1f} ms CPU; CPU ratio {c1 / c0:.3f}"
        )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
