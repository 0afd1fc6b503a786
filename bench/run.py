"""`make bench`: ertools' reader and commands measured side by side with rosbags and evo.

Generates (once, cached in build/bench/) an hour of 120 Hz mocap GT written like the 2015
loggers (PoseStamped + Pose2D + /tf, 1.33 M messages) as uncompressed, lz4 and bz2 ROS1 bags
and as MCAP (zstd), a 10 Hz robot log of the same hour, and 1000 one-second GT bags. Every
command runs several times as a whole process (page cache warm); the table shows the median
wall time and the peak RSS of the process (``os.wait4``), then the ratios of issue 3.

Issue 39's table: `ertools score trajectory` (default, and ``--draws 0``) against `evo_ape
bag` on the same hour (the merged bag: evo reads both topics from one bag), and a 20-minute
robot log against an 8-hour GT (1.3 GB), the rows interleaved run by run; ``--score-only``
runs just that table (evo included; ``--quick`` leaves out the other slow baselines).

Then (``--season yes``, the default) the `ertools rescore` season benchmark of
bench/rescore_season.py: >= 100 executions cold with 1 and 2 workers, through a Dask
LocalCluster and warm from the cache; ``--season only`` runs just that one.

    .venv/bin/python bench/run.py [--runs N] [--quick] [--score-only] [--json FILE]
                                  [--season yes|no|only]

Nothing here is a test: `make test` never runs it.
"""

from __future__ import annotations

import argparse
import contextlib
import json
import os
import platform
import shutil
import statistics
import subprocess
import sys
import time
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

HERE = Path(__file__).resolve().parent
REPO = HERE.parent
sys.path.insert(0, str(HERE))

from data import GT_TOPIC, LONG_HOURS, NS_BODY, ROBOT_TOPIC, generate, generate_long  # noqa: E402
from fbm_hour import FBM_SCENARIOS, hour_bag  # noqa: E402

PY = sys.executable
FORMATS = {
    "gt": "ROS1",
    "gt_lz4": "ROS1 lz4",
    "gt_bz2": "ROS1 bz2",
    "gt_mcap_none": "MCAP",
    "gt_mcap": "MCAP zstd",
}
UNCOMPRESSED = ("gt", "gt_mcap_none")
BIN = Path(sys.executable).parent


@dataclass
class Measure:
    name: str
    wall_s: float
    inside_s: float | None
    rss_mib: float
    runs: int
    ok: bool
    note: str = ""
    cpu_s: float | None = None


@dataclass
class Once:
    wall_s: float
    rss_mib: float
    exit: int
    last_line: str
    cpu_s: float


def run_once(argv: list[str]) -> Once:
    """Wall time, peak RSS, exit status, last stdout line and CPU time of one whole process,
    started by the small launcher ``measure.py`` (see there why)."""
    done = subprocess.run(
        [PY, str(HERE / "measure.py"), *argv],
        capture_output=True,
        cwd=REPO,
        check=False,
    )
    if done.returncode != 0 or not done.stdout.strip():
        sys.stderr.write(done.stderr.decode(errors="replace")[-2000:])
        return Once(float("nan"), float("nan"), 1, "", float("nan"))
    report = json.loads(done.stdout.decode().strip().splitlines()[-1])
    if report["exit"] != 0:
        sys.stderr.write(done.stderr.decode(errors="replace")[-2000:])
    return Once(
        report["wall_s"],
        report["maxrss_kib"] / 1024.0,
        report["exit"],
        report["last_line"],
        report["cpu_s"],
    )


def measure(name: str, argv: list[str], runs: int, warm_up: bool = True) -> Measure:
    walls, rss, inside = [], [], []
    ok = True
    if warm_up:
        # This VM reclaims idle page cache (kdamond): one unmeasured run brings the files back.
        run_once(argv)
    for _ in range(runs):
        once = run_once(argv)
        ok &= once.exit == 0
        walls.append(once.wall_s)
        rss.append(once.rss_mib)
        with contextlib.suppress(ValueError, KeyError, IndexError, TypeError):
            inside.append(float(json.loads(once.last_line.strip().splitlines()[-1])["inside_s"]))
    m = Measure(
        name,
        statistics.median(walls),
        statistics.median(inside) if inside else None,
        max(rss),
        runs,
        ok,
    )
    inside_txt = f"{m.inside_s:8.3f}" if m.inside_s is not None else "       -"
    print(
        f"  {name:<58} {m.wall_s:8.3f} {inside_txt} {m.rss_mib:9.1f}  {'' if ok else 'FAILED'}",
        flush=True,
    )
    return m


def _leaves(d: object, path: str = "") -> dict[str, object]:
    if isinstance(d, dict):
        return {k: v for key, val in d.items() for k, v in _leaves(val, f"{path}.{key}").items()}
    if isinstance(d, list):
        return {k: v for i, val in enumerate(d) for k, v in _leaves(val, f"{path}[{i}]").items()}
    return {path: d}


def same_scores(short: dict[str, object], hour: dict[str, object]) -> str:
    """'' when the hour log scores as the sample did; else what differs. Times counted from
    the bag's first message move by one constant (the half hour of mocap logged before)."""
    a, b = _leaves(short), _leaves(hour)
    if a.keys() != b.keys():
        return "different fields"
    shifts = set()
    for key in a:
        if a[key] == b[key] or "file" in key or key.endswith(".bag"):
            continue
        relative = key.endswith(("_time", "_s")) or "_s[" in key
        if relative and isinstance(a[key], float | int) and isinstance(b[key], float | int):
            shifts.add(round(float(b[key]) - float(a[key]), 2))
            continue
        return f"{key}: {a[key]} vs {b[key]}"
    return "" if len(shifts) <= 1 else f"times shift by {sorted(shifts)}"


def fbm_scores(go: Any, runs: int, ex: list[str], ertools: list[str]) -> None:
    """Each FBM scorer on an hour log (a sample benchmark inside an hour of mocap), against
    the extraction of its pose topic; the scores must equal the sample's."""
    folder = REPO / "build" / "bench" / "fbm"
    for scenario, (_bodies, command, topic) in FBM_SCENARIOS.items():
        bag, sample_dir = hour_bag(scenario, folder)
        extra = [a.format(dir=sample_dir) for a in command]
        score = [*ertools, *extra[:2], str(bag), *extra[2:], "--format", "json"]
        m = go(
            f"fbm_{scenario}",
            f"ertools {' '.join(extra[:2])} (hour log, {bag.stat().st_size >> 20} MiB)",
            score,
            runs,
        )
        go(
            f"fbm_{scenario}_extract",
            f"  its pose topic -> arrays ({topic})",
            [*ex, "ertools", str(bag), topic],
            runs,
        )
        short_bag = next(p for p in sorted(sample_dir.glob("*.bag")))
        short = [*ertools, *extra[:2], str(short_bag), *extra[2:], "--format", "json"]
        outs = []
        for argv in (short, score):
            done = subprocess.run(argv, capture_output=True, cwd=REPO, check=False)
            outs.append(json.loads(done.stdout) if done.returncode == 0 else {})
        problem = same_scores(*outs) if all(outs) else "a score failed"
        m.note = "; same scores as the sample" if not problem else f"; SCORES DIFFER: {problem}"
        print(f"    hour log scores as the sample: {problem or 'yes'}")


def trajectory_argv(ertools: list[str], robot: Path, gt: Path, *extra: str) -> list[str]:
    return [
        *ertools,
        "score",
        "trajectory",
        str(robot),
        str(gt),
        "--robot-topic",
        ROBOT_TOPIC,
        "--gt-topic",
        GT_TOPIC,
        *extra,
        "--format",
        "json",
    ]


def interleaved(rows: list[tuple[str, str, list[str], int]]) -> dict[str, Measure]:
    """Each row ``(key, name, argv, runs)`` run ``runs`` times as a whole process, the rows
    taking turns (one run of each per round, after one unmeasured warm-up run each), so that
    a change of the machine's load falls on every row alike; medians, peak RSS the largest."""
    for _key, _name, argv, _runs in rows:
        run_once(argv)
    got: dict[str, list[Once]] = {key: [] for key, *_ in rows}
    for r in range(max(runs for *_, runs in rows)):
        # The order rotates every round: the run just after a slow, memory-hungry row (evo's
        # 10 s and 550 MiB) came out slower on this VM, and that run is each row's in turn.
        for key, _name, argv, runs in rows[r % len(rows) :] + rows[: r % len(rows)]:
            if r < runs:
                got[key].append(run_once(argv))
    return {
        key: Measure(
            name,
            statistics.median(o.wall_s for o in got[key]),
            None,
            max(o.rss_mib for o in got[key]),
            runs,
            all(o.exit == 0 for o in got[key]),
            cpu_s=statistics.median(o.cpu_s for o in got[key]),
        )
        for key, name, _argv, runs in rows
    }


def score_table(
    paths: dict[str, Path], runs: int, slow_runs: int, ertools: list[str]
) -> dict[str, Measure]:
    """Issue 39's table: `score trajectory` on the hour, default and ``--draws 0``, against
    `evo_ape bag` on the same hour merged into one bag, and a 20-minute robot log against
    the 8-hour GT; printed, and returned by key."""
    print(f"\nissue 39: score trajectory against evo_ape (data: {paths['gt'].parent})", flush=True)
    t0 = time.perf_counter()
    long = generate_long(paths["gt"].parent)
    print(f"  the {LONG_HOURS}-hour GT ready in {time.perf_counter() - t0:.1f} s", flush=True)
    hour = trajectory_argv(ertools, paths["robot"], paths["gt"])
    gt_mib = long["gt_long"].stat().st_size / 2**20
    rows = [
        ("trajectory", "ertools score trajectory, robot hour + GT hour", hour, runs),
        (
            "trajectory_draws0",
            "  the same with --draws 0 (no intervals)",
            trajectory_argv(ertools, paths["robot"], paths["gt"], "--draws", "0"),
            runs,
        ),
        (
            "trajectory_window",
            f"ertools score trajectory, 20-min robot log + {LONG_HOURS}-hour GT ({gt_mib:.0f} MiB)",
            trajectory_argv(ertools, long["robot_window"], long["gt_long"]),
            runs,
        ),
    ]
    evo_ape = shutil.which("evo_ape", path=str(BIN))
    if evo_ape:
        rows.append(
            (
                "evo_ape",
                "evo_ape bag, the same hour (GT + robot topic merged in one bag)",
                [evo_ape, "bag", str(paths["combined"]), GT_TOPIC, ROBOT_TOPIC],
                slow_runs,
            )
        )
    got = interleaved(rows)
    counts = f"{runs} runs" + (f", evo {slow_runs}" if evo_ape else "")
    print(f"  (whole processes, page cache warm, rows interleaved; medians of {counts})")
    title = "command"
    head = "evo_ape / it: wall, CPU"
    print(f"  {title:<74} {'wall s':>7} {'CPU s':>7} {'peak MiB':>9} {head:>24}")
    evo = got.get("evo_ape")
    for key, m in got.items():
        ratio = ""
        if evo is not None and evo.ok and m.ok and key != "trajectory_window":
            ratio = f"{evo.wall_s / m.wall_s:.1f}x"
            if evo.cpu_s and m.cpu_s:
                ratio += f", {evo.cpu_s / m.cpu_s:.1f}x"
        cpu = f"{m.cpu_s:7.3f}" if m.cpu_s is not None else "      -"
        flag = "" if m.ok else "  FAILED"
        print(f"  {m.name:<74} {m.wall_s:7.3f} {cpu} {m.rss_mib:9.1f} {ratio:>24}{flag}")
    if not evo_ape:
        print("  evo_ape: not installed (pip install 'ertools[bench]'), no ratio")
    default = got["trajectory"]
    if evo is not None and evo.ok and default.ok:
        ratio = evo.wall_s / default.wall_s
        verdict = "met" if ratio >= 30 else "NOT met"
        print(
            f"  target: default >= 30x faster than evo_ape: {ratio:.1f}x, {verdict} "
            f"(30x needs <= {evo.wall_s / 30:.3f} s)"
        )
    verdict = "met" if default.rss_mib <= 150 else "NOT met"
    print(f"  target: default peak RSS <= 150 MiB: {default.rss_mib:.1f} MiB, {verdict}")
    return got


def machine() -> dict[str, str]:
    cpu = "unknown"
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    mem = "unknown"
    try:
        kb = int(Path("/proc/meminfo").read_text().split()[1])
        mem = f"{kb / 1024 / 1024:.1f} GiB"
    except (OSError, ValueError, IndexError):
        pass
    load = ", ".join(f"{x:.2f}" for x in os.getloadavg())
    return {
        "load_average_at_start": load,
        "nproc": str(os.cpu_count()),
        "cpu": cpu,
        "memory": mem,
        "python": platform.python_version(),
        "platform": platform.platform(),
    }


def main() -> int:
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument("--runs", type=int, default=5, help="runs per fast command (default 5)")
    parser.add_argument(
        "--slow-runs", type=int, default=3, help="runs per slow baseline (default 3)"
    )
    parser.add_argument(
        "--quick",
        action="store_true",
        help="skip the slow rosbags and evo_traj baselines (evo_ape stays: issue 39's table)",
    )
    parser.add_argument(
        "--score-only",
        action="store_true",
        help="only issue 39's table: score trajectory against evo_ape (and the 8-hour GT)",
    )
    parser.add_argument(
        "--json",
        type=Path,
        help="where the figures go (default build/bench/results.json, results_score.json)",
    )
    parser.add_argument(
        "--season",
        choices=("yes", "no", "only"),
        default="yes",
        help="the `ertools rescore` season benchmark after the others (bench/rescore_season.py)",
    )
    args = parser.parse_args()
    if args.season == "only":
        return season()

    folder = REPO / "build" / "bench"
    print(f"data: {folder} (generated once, then reused)", flush=True)
    t0 = time.perf_counter()
    paths = generate(folder)
    print(f"  ready in {time.perf_counter() - t0:.1f} s", flush=True)
    sizes = {
        k: (p.stat().st_size if p.is_file() else sum(f.stat().st_size for f in p.iterdir()))
        for k, p in paths.items()
    }
    info = machine()
    print(
        f"machine: {info['nproc']} cores, {info['cpu']}, {info['memory']}, "
        f"Python {info['python']}, load average {info['load_average_at_start']}"
    )
    if args.score_only:
        got = score_table(paths, args.runs, args.slow_runs, [str(BIN / "ertools")])
        write_json(args.json or folder / "results_score.json", info, sizes, got, {})
        return 0
    title = "command (whole process, page cache warm)"
    print(f"  {title:<58} {'wall s':>8} {'inside':>8} {'peak MiB':>9}")
    ertools = [str(BIN / "ertools")]
    results: dict[str, Measure] = {}

    def go(key: str, name: str, argv: list[str], runs: int) -> Measure:
        # the slow baselines (rosbags, evo: seconds each) warm up in their first of 3 runs
        results[key] = measure(name, argv, runs, warm_up=runs == args.runs)
        return results[key]

    ex = [PY, str(HERE / "extract.py")]
    go("python", "python -c pass (interpreter start)", [PY, "-c", "pass"], args.runs)
    go(
        "numpy",
        "python -c 'import numpy' (the floor of any NumPy tool)",
        [PY, "-c", "import numpy"],
        args.runs,
    )
    for fmt, label in FORMATS.items():
        p = str(paths[fmt])
        go(
            f"bytes_{fmt}",
            f"read the file's bytes ({label}, {sizes[fmt] / 2**20:.0f} MiB)",
            [*ex, "bytes", p],
            args.runs,
        )
        if fmt not in UNCOMPRESSED:
            go(
                f"inflate_{fmt}",
                f"read + decompress every chunk ({label})",
                [*ex, "inflate", p],
                args.runs,
            )
        go(
            f"extract_{fmt}",
            f"ertools: pose topic -> arrays ({label})",
            [*ex, "ertools", p, GT_TOPIC],
            args.runs,
        )
        if not args.quick and fmt in ("gt", "gt_mcap_none"):
            go(
                f"rosbags_{fmt}",
                f"rosbags AnyReader per message ({label})",
                [*ex, "rosbags", p, GT_TOPIC],
                args.slow_runs,
            )
    # issue 39: the GT hour's three pose sources (PoseStamped, Pose2D, /tf: 1.3 M messages)
    for fmt, label in FORMATS.items():
        if fmt != "gt_bz2":  # (bz2: the decompression is the read)
            go(
                f"sources_{fmt}",
                f"ertools: GT's 3 pose sources, one read ({label})",
                [*ex, "sources", str(paths[fmt]), NS_BODY],
                args.runs,
            )
    go(
        "each_gt",
        "ertools: the same, one source at a time (ROS1)",
        [*ex, "each", str(paths["gt"]), NS_BODY],
        args.runs,
    )
    for key, label in (("robot", "robot hour"), ("robot_fat", "robot hour + 16 KiB camera")):
        p = paths[key]
        go(
            f"extract_{key}",
            f"ertools: robot pose topic -> arrays ({label}, {p.stat().st_size >> 20} MiB)",
            [*ex, "ertools", str(p), ROBOT_TOPIC],
            args.runs,
        )
    go("info_hour", "ertools info (hour bag)", [*ertools, "info", str(paths["gt"])], args.runs)
    go(
        "info_small",
        "ertools info (1 s bag)",
        [*ertools, "info", str(next(iter(sorted(paths["small"].iterdir()))))],
        args.runs,
    )
    go(
        "info_1000",
        "ertools info (1000 bags)",
        [*ertools, "info", str(paths["small"]), "--format", "json"],
        args.runs,
    )
    tl = go(
        "timeline_1000",
        "ertools timeline (1000 bags, summaries only)",
        [*ertools, "timeline", str(paths["small"]), "--no-clock-check", "--format", "json"],
        args.runs,
    )
    if not tl.ok:
        tl.note = "ertools timeline failed or is not available"
    fbm_scores(go, args.runs, ex, ertools)
    evo_traj = shutil.which("evo_traj", path=str(BIN))
    if args.quick:
        print("  evo_traj: skipped (--quick)")
    elif evo_traj:
        go(
            "evo_traj",
            "evo_traj bag (GT topic)",
            [evo_traj, "bag", str(paths["gt"]), GT_TOPIC],
            args.slow_runs,
        )
    else:
        print("  evo: not installed (pip install 'ertools[bench]'), skipped")
    results.update(score_table(paths, args.runs, args.slow_runs, ertools))

    print("\nratios (targets of issue 3):")
    ratios: dict[str, float] = {}

    def ratio(key: str, text: str, a: str, b: str, target: str) -> None:
        if a in results and b in results and results[a].ok and results[b].ok:
            ratios[key] = results[a].wall_s / results[b].wall_s
            print(f"  {text:<62} {ratios[key]:7.2f}x   (target {target})")

    for fmt, label in FORMATS.items():
        ratio(
            f"extract_vs_bytes_{fmt}",
            f"pose extraction / reading the bytes, {label}",
            f"extract_{fmt}",
            f"bytes_{fmt}",
            "<= 3x",
        )
    for fmt, label in FORMATS.items():
        a, b = results.get(f"extract_{fmt}"), results.get(f"bytes_{fmt}")
        if a and b and a.inside_s and b.inside_s:
            ratios[f"inside_extract_vs_bytes_{fmt}"] = a.inside_s / b.inside_s
            text = f"same, inside the process (after imports), {label}"
            print(f"  {text:<62} {a.inside_s / b.inside_s:7.2f}x   (target <= 3x)")
    for fmt, label in FORMATS.items():
        if fmt in UNCOMPRESSED:
            continue
        ratio(
            f"inflate_vs_bytes_{fmt}",
            f"read + decompress only (no decoding) / reading the bytes, {label}",
            f"inflate_{fmt}",
            f"bytes_{fmt}",
            "the floor",
        )
        ratio(
            f"extract_vs_inflate_{fmt}",
            f"pose extraction / read + decompress only, {label}",
            f"extract_{fmt}",
            f"inflate_{fmt}",
            "-",
        )
    for fmt in ("gt", "gt_mcap_none"):
        ratio(
            f"rosbags_vs_ertools_{fmt}",
            f"rosbags per message / ertools, {fmt}",
            f"rosbags_{fmt}",
            f"extract_{fmt}",
            "-",
        )
    ratio(
        "evo_ape_vs_trajectory",
        "evo_ape bag / ertools score trajectory (same data)",
        "evo_ape",
        "trajectory",
        ">= 30x",
    )
    ratio(
        "evo_traj_vs_extract",
        "evo_traj bag / ertools pose extraction",
        "evo_traj",
        "extract_gt",
        "-",
    )
    a, b = results.get("extract_robot_fat"), results.get("extract_robot")
    if a and b and a.inside_s and b.inside_s:
        ratios["robot_fat_vs_plain_inside"] = a.inside_s / b.inside_s
        size = sizes["robot_fat"] / sizes["robot"]
        text = f"same 36,000 poses in a {size:.0f}x larger bag (camera), inside"
        print(f"  {text:<62} {a.inside_s / b.inside_s:7.2f}x   (cost ~ messages, not bytes)")
    for scenario in FBM_SCENARIOS:
        a, b = results.get(f"fbm_{scenario}"), results.get(f"fbm_{scenario}_extract")
        if a and b and a.ok and b.ok:
            extra = a.wall_s - b.wall_s
            ratios[f"fbm_{scenario}_beyond_extraction_s"] = extra
            text = f"ertools score {scenario} (hour log) beyond its pose extraction"
            print(f"  {text:<62} {extra:7.2f} s   (target < 1 s){a.note}")
    for fmt, label in FORMATS.items():
        m = results.get(f"sources_{fmt}")
        if m and m.ok and m.inside_s is not None:
            ratios[f"sources_inside_s_{fmt}"] = m.inside_s
            text = f"GT hour's 3 pose sources in one read, inside, {label}"
            target = "<= 0.1 s" if fmt == "gt" else "-"
            print(f"  {text:<62} {m.inside_s:7.3f} s   (target {target}; {m.rss_mib:.0f} MiB)")
    for key in ("info_1000", "timeline_1000"):
        if key in results:
            print(f"  {results[key].name:<62} {results[key].wall_s:7.2f} s   (target <= 3 s)")
    if "trajectory" in results:
        label = "peak memory of ertools score trajectory"
        peak = results["trajectory"].rss_mib
        print(f"  {label:<62} {peak:7.1f} MiB (target <= 150 MiB)")
    write_json(args.json or folder / "results.json", info, sizes, results, ratios)
    return season() if args.season == "yes" else 0


def write_json(
    path: Path,
    info: dict[str, str],
    sizes: dict[str, int],
    results: dict[str, Measure],
    ratios: dict[str, float],
) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(
        json.dumps(
            {
                "machine": info,
                "sizes_bytes": sizes,
                "results": {k: asdict(v) for k, v in results.items()},
                "ratios": ratios,
            },
            indent=2,
        )
    )
    print(f"\nwrote {path}")


def season() -> int:
    """The season benchmark of `ertools rescore`, in its own process (its own data and table)."""
    print("\nertools rescore over a generated season (bench/rescore_season.py):", flush=True)
    return subprocess.run([PY, str(HERE / "rescore_season.py")], cwd=REPO, check=False).returncode


if __name__ == "__main__":
    raise SystemExit(main())
