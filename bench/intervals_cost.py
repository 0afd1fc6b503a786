"""What the score intervals cost: each sample benchmark of the README (the RSBB ones
included) and the hour trajectory, scored by the default command, with the interval code's
own CPU time beside the whole command's.

Each case runs as a whole process, several times (page cache warm), by the child mode of
this script: it wraps the benchmark's interval entry point with a CPU clock, runs the
command in-process (``ertools.cli.main.main``) and prints the interval time and the
process's CPU time since it started (imports included, as a user's command pays them).
The table gives the medians, the command with ``--draws 0`` beside, and the intervals'
share of the default command; ``--before`` measures another checkout's code (a worktree of
the main branch) in the same run, interleaved.

    .venv/bin/python bench/intervals_cost.py [--runs N] [--hour DIR] [--only NAME ...]
        [--before CHECKOUT] [--json FILE]

``--hour DIR`` holds ``gt_hour.bag`` and ``robot_hour.bag`` (bench/data.py's hour; written
there when missing). Nothing here is a test: `make test` never runs it.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

HERE = Path(__file__).resolve().parent
REPO = HERE.parent
S = REPO / "sample_bags"

# the interval code of each benchmark: (module, attribute) wrapped by a CPU clock (a module
# or attribute a version does not have is skipped: the trajectory's noise is measured inside
# trajectory_intervals before issue 39, beside it after, as mocap_sigma and then jitter; the
# score at the fitted offset calls it from its own module since)
ENTRY = {
    "trajectory": (
        ("ertools.benchmarks.trajectory.comparison", "trajectory_intervals"),
        ("ertools.benchmarks.trajectory.comparison", "mocap_sigma"),
        ("ertools.benchmarks.trajectory.comparison", "jitter"),
        ("ertools.benchmarks.trajectory.fitted", "trajectory_intervals"),
    ),
    "fbm3w": (("ertools.benchmarks.fbm3w.pipeline", "with_intervals"),),
    "fbm2h": (("ertools.benchmarks.fbm2h.pipeline", "with_intervals"),),
    "fbm1": (("ertools.benchmarks.fbm1.pipeline", "fbm1_intervals"),),
    # the RSBB benchmarks (ERL @Home 2017-19): each its intervals.py's entry point, seen
    # from the pipeline that calls it
    **{
        name: ((f"ertools.benchmarks.{name}.pipeline", f"{name}_intervals"),)
        for name in ("hnf", "hpff", "hopf", "hppf", "hgmf")
    },
}

# the README's RSBB sample commands (its "Try it" block): one run bag each, side files found
# in the RSBB layout beside it
RSBB = {
    "hnf": "hnf/rsbb_logs/HNF/simbot/run_1_2019-04-10-14-31-06.bag",
    "hpff": "hpff/rsbb_logs/HPFF/simbot/run_1_2019-04-10-15-22-11.bag",
    "hopf": "hopf/rsbb_logs/HOPF/simbot/run_1_2019-04-11-16-26-40.bag",
    "hppf": "hppf/rsbb_logs/HPPF/simbot/run_1_2019-04-11-17-26-40.bag",
    "hgmf": "hgmf/rsbb_logs/HGMF/simbot/run_1_2019-04-12-10-00-00.bag",
}


def cases(hour: Path, fbm1w: Path) -> dict[str, tuple[str, list[str]]]:
    """name -> (entry key, ertools arguments)."""
    robotlog = S / "robotlog"
    return {
        "fbm1h": (
            "fbm1",
            [
                "score",
                "fbm1h",
                str(S / "fbm1h/log_fbm1h_2015-11-20-12-00-00_0.bag"),
                "--items",
                str(S / "fbm1h/fbm1h.yaml"),
            ],
        ),
        "fbm1w": (
            "fbm1",
            ["score", "fbm1w", str(fbm1w), "--items", str(S / "fbm1h/fbm1h.yaml")],
        ),
        "fbm2h": (
            "fbm2h",
            [
                "score",
                "fbm2h",
                str(S / "fbm2h/log_fbm2h_mocap_2015-11-20-12-00-00_0.bag"),
                "--goal",
                str(S / "fbm2h/fbm2h_goal.yaml"),
                "--transform",
                str(S / "fbm2h/transform-simbot.yaml"),
            ],
        ),
        "fbm3w": (
            "fbm3w",
            ["score", "fbm3w", str(S / "fbm3w/log_fbm3w_mocap_2015-11-20-12-00-00_0.bag")],
        ),
        "trajectory": (
            "trajectory",
            [
                "score",
                "trajectory",
                str(robotlog / "FBM2H_201511201200_homer.bag"),
                str(robotlog),
                "--offset",
                "auto",
                "--apply-offset",
            ],
        ),
        "trajectory (no --apply-offset)": (
            "trajectory",
            [
                "score",
                "trajectory",
                str(robotlog / "FBM2H_201511201200_homer.bag"),
                str(robotlog),
            ],
        ),
        **{name: (name, ["score", name, str(S / bag)]) for name, bag in RSBB.items()},
        "trajectory hour": (
            "trajectory",
            [
                "score",
                "trajectory",
                str(hour / "robot_hour.bag"),
                str(hour / "gt_hour.bag"),
                "--robot-topic",
                "/rockin/homer/marker_pose",
                "--gt-topic",
                "/fbm3w/robot_at_work/pose",
            ],
        ),
    }


def child(entry: str, argv: list[str]) -> None:
    """Run one command in this process; print {interval_s, total_s} as JSON on stdout's last
    line (the command's own output goes to /dev/null)."""
    import importlib  # lazy: the child's imports are part of what it measures

    spent = [0.0]
    depth = [0]  # a wrapped function calling another is timed once

    def timer(inner: Any) -> Any:
        def timed(*args: Any, **kwargs: Any) -> Any:
            depth[0] += 1
            t0 = time.process_time()
            try:
                return inner(*args, **kwargs)
            finally:
                depth[0] -= 1
                if depth[0] == 0:
                    spent[0] += time.process_time() - t0

        return timed

    wrapped = 0
    for module, name in ENTRY[entry]:
        try:
            mod = importlib.import_module(module)
        except ModuleNotFoundError:
            continue
        if hasattr(mod, name):
            setattr(mod, name, timer(getattr(mod, name)))
            wrapped += 1
    from ertools.cli.main import main  # lazy: after the wrapper is in place

    code = main([*argv, "--format", "json", "--out", "/dev/null"])
    total = time.process_time()
    print(json.dumps({"exit": code, "interval_s": spent[0], "total_s": total, "wrapped": wrapped}))


def run_child(entry: str, argv: list[str], code: Path | None = None) -> dict[str, float]:
    """One child run; ``code``: the checkout whose ertools it imports (PYTHONPATH; None:
    this one's)."""
    env = dict(os.environ)
    if code is not None:
        env["PYTHONPATH"] = str(code)
    done = subprocess.run(
        [sys.executable, str(Path(__file__)), "--child", entry, *argv],
        capture_output=True,
        cwd=REPO,
        env=env,
        check=False,
    )
    lines = done.stdout.decode().strip().splitlines()
    if done.returncode != 0 or not lines:
        sys.stderr.write(done.stderr.decode(errors="replace")[-2000:])
        raise SystemExit(f"failed: {' '.join(argv)}")
    report: dict[str, float] = json.loads(lines[-1])
    if code is None and not report.get("wrapped"):
        # a renamed entry point would otherwise measure 0 s of intervals, silently
        raise SystemExit(f"{entry}: none of {ENTRY[entry]} exists: update ENTRY")
    return report


def ensure_hour(folder: Path) -> None:
    if (folder / "gt_hour.bag").exists() and (folder / "robot_hour.bag").exists():
        return
    sys.path.insert(0, str(HERE))
    from bagwrite import write_ros1  # lazy: bench/'s writer, only to write the hour once
    from data import T0, gt_topics, robot_topics  # lazy: as above

    folder.mkdir(parents=True, exist_ok=True)
    write_ros1(folder / "gt_hour.bag", gt_topics(T0, 3600, seed=1))
    write_ros1(folder / "robot_hour.bag", robot_topics(T0, 3600, seed=2))


def ensure_fbm1w(folder: Path) -> Path:
    """The fbm1h sample scenario recorded as FBM1@Work (the RefBox names each item)."""
    path = folder / "log_fbm1w_2015-11-20-12-00-00_0.bag"
    if path.exists():
        return path
    from ertools.benchmarks.fbm1 import sample as fbm1  # lazy: only to write the log once
    from ertools.simulator.mocap import publish_environment, publish_mocap  # lazy: as above
    from ertools.simulator.statemachine import publish_states  # lazy: as above
    from ertools.simulator.writer import BagWriter  # lazy: as above

    sim = fbm1.simulate(0)
    with BagWriter(path, "ros1") as bag:
        for body, pub in sim.bodies.items():
            publish_mocap(bag, "fbm1w", body, pub)
        publish_states(bag, "fbm1w", sim.transitions, end_ns=sim.state_end_ns)
        publish_environment(
            bag, "fbm1w", sim.start_ns, sim.end_ns, bag_name=path.name, bodies=list(sim.bodies)
        )
    return path


def main() -> int:
    if len(sys.argv) > 2 and sys.argv[1] == "--child":
        child(sys.argv[2], sys.argv[3:])
        return 0
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=5)
    ap.add_argument("--hour", type=Path, default=REPO / "build" / "bench" / "intervals")
    ap.add_argument("--only", nargs="*", default=None)
    ap.add_argument("--json", type=Path, default=None)
    ap.add_argument(
        "--before",
        type=Path,
        default=None,
        help="another checkout (e.g. a worktree of main) measured in the same run",
    )
    args = ap.parse_args()
    ensure_hour(args.hour)
    fbm1w = ensure_fbm1w(args.hour)
    rows = []
    versions: list[tuple[str, Path | None]] = [("after", None)]
    if args.before is not None:
        versions.insert(0, ("before", args.before.resolve()))
    head = " | ".join(f"{v}: command CPU s | {v}: intervals s | {v}: share" for v, _ in versions)
    print(f"| case | {head} | --draws 0 CPU s |")
    print("|---|" + "---:|" * (3 * len(versions) + 1))
    for name, (entry, argv) in cases(args.hour, fbm1w).items():
        if args.only and name not in args.only:
            continue
        got: dict[str, list[dict[str, float]]] = {v: [] for v, _ in versions}
        none = []
        for _ in range(args.runs):  # interleaved: the machine's load hits all alike
            for v, code in versions:
                got[v].append(run_child(entry, argv, code))
            none.append(run_child(entry, [*argv, "--draws", "0"]))
        row: dict[str, Any] = {"case": name}
        cells = []
        for v, _ in versions:
            total = statistics.median(r["total_s"] for r in got[v])
            iv = statistics.median(r["interval_s"] for r in got[v])
            row[v] = {"total_s": total, "interval_s": iv}
            cells.append(f"{total:.3f} | {iv:.3f} | {iv / total:.1%}")
        bare = statistics.median(r["total_s"] for r in none)
        row["draws0_s"] = bare
        rows.append(row)
        print(f"| {name} | {' | '.join(cells)} | {bare:.3f} |", flush=True)
    if args.json:
        args.json.write_text(json.dumps(rows, indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
