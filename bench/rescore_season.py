"""`make bench`, the season: `ertools rescore` on >= 100 executions, cold and warm, 1 and 2
workers, local processes and a Dask LocalCluster (issue 18 item 6).

The season (bench/season.py: 3 days x 36 executions by ten teams, each day's GT logger split
every hour) is generated once into build/bench/season and never timed. Each configuration runs
``ertools rescore`` as a whole process, with the page cache warm (one unmeasured read of every
file first); "cold" means an empty results folder (no cache), "warm" a second run into the same
folder (everything from the cache). The configurations run interleaved in ``--rounds`` rounds
and the fastest round of each counts: the machine is shared, and other processes only add
time. A poller reads the peak RSS (``VmHWM``) of the command and of every process it starts
(workers, Dask's nanny and scheduler) from /proc.

    .venv/bin/python bench/rescore_season.py [--days 3] [--per-day 36] [--rounds 2] [--json F]

Targets (on a 2-core machine): --jobs 2 at least 1.7x faster than --jobs 1; Dask within 15 % of
--jobs 2; with reports at most 2x the --no-reports time per execution; a warm rerun under
2 s; every process under 200 MiB; time linear in the executions (per-execution time of one
day within 15 % of the whole season's); identical results in every
configuration (bench/season_compare.py: every run's results.json against the first's, scores,
intervals, verdicts and leaderboards, timings and paths left out).

The machine may be shared: beside each wall time the CPU time (user + system, every process)
and the load average before the run are printed; CPU time does not depend on the neighbours.
"""

from __future__ import annotations

import argparse
import datetime as dt
import json
import os
import resource
import shutil
import subprocess
import sys
import threading
import time
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

HERE = Path(__file__).resolve().parent
REPO = HERE.parent
sys.path.insert(0, str(HERE))

from season import DAYS, SLOTS_PER_DAY, generate_season  # noqa: E402
from season_compare import comparable, compare  # noqa: E402

from ertools.benchmarks import registry  # noqa: E402

ERTOOLS = str(Path(sys.executable).parent / "ertools")
FOLDER = REPO / "build" / "bench"


@dataclass
class Run:
    name: str
    executions: int
    wall_s: float
    exit: int
    peak_main_mib: float
    peak_other_mib: float  # the largest other process: a worker, Dask's nanny or scheduler
    processes: int
    cpu_s: float  # user + system time of the command and every process it waited for
    scored: int = 0
    cached: int = 0
    load: float = 0.0  # the 1-minute load average just before the run
    note: str = ""
    peaks: dict[str, float] = field(default_factory=dict)

    @property
    def per_execution_s(self) -> float:
        return self.wall_s / self.executions

    @property
    def cpu_per_execution_s(self) -> float:
        return self.cpu_s / self.executions


def manifest_text(root: Path, season: dict[str, Any], days: set[int]) -> str:
    """The competition manifest (docs/rescore.md) listing the executions of ``days``: each
    benchmark's shared inputs once, each team's transform under its team."""
    shared: dict[str, dict[str, str]] = {}
    teams: dict[str, dict[str, dict[str, str]]] = {}
    lines = ["version: 1", "title: Generated season (bench/season.py)", "benchmarks:"]
    chosen = [e for e in season["executions"] if e["day"] in days]
    for e in chosen:
        # Which inputs the registry declares per team (the transform, or the team's name with a
        # shared folder of transform-<team>.yaml): the manifest follows the declarations.
        per_team = {i.name for i in registry.get(e["benchmark"]).inputs if i.per_team}
        mine = teams.setdefault(e["benchmark"], {}).setdefault(e["team"], {})
        if "team" in per_team:
            mine["team"] = e["team"]
        for key, rel in e["inputs"].items():
            path = str(root / rel)
            if key == "transform" and key not in per_team:
                shared.setdefault(e["benchmark"], {})["transforms"] = str(Path(path).parent)
            elif key in per_team:
                mine[key] = path
            else:
                shared.setdefault(e["benchmark"], {})[key] = path
    for bench in sorted({e["benchmark"] for e in chosen}):
        lines.append(f"  {bench}:")
        if shared.get(bench):
            lines.append("    inputs:")
            lines += [f"      {k}: {json.dumps(v)}" for k, v in sorted(shared[bench].items())]
        if any(teams.get(bench, {}).values()):
            lines.append("    teams:")
            for team, values in sorted(teams[bench].items()):
                if not values:
                    continue
                lines.append(f"      {json.dumps(team)}:")
                lines += [f"        {k}: {json.dumps(v)}" for k, v in sorted(values.items())]
    lines.append("executions:")
    for e in chosen:
        bags = [str(root / e["bmbox_log"]), *(str(root / g) for g in e["gt_files"])]
        lines.append(f"  - benchmark: {e['benchmark']}")
        lines.append(f"    team: {json.dumps(e['team'])}")
        lines.append(f"    bags: {json.dumps(bags)}")
        # The benchmark log's span, not the GT hour files' (the execution's id and times).
        for key in ("start", "end"):
            stamp = dt.datetime.fromtimestamp(e[f"{key}_ns"] / 1e9, tz=dt.UTC)
            lines.append(f"    {key}: {stamp.isoformat(timespec='milliseconds')}")
    return "\n".join(lines) + "\n"


def _tree(root: int) -> list[int]:
    """``root`` and every process descended from it, from /proc."""
    children: dict[int, list[int]] = {}
    for entry in os.scandir("/proc"):
        if not entry.name.isdigit():
            continue
        try:
            with open(f"/proc/{entry.name}/stat", encoding="ascii", errors="replace") as fh:
                stat = fh.read()
        except OSError:
            continue
        ppid = int(stat.rsplit(")", 1)[1].split()[1])
        children.setdefault(ppid, []).append(int(entry.name))
    out, todo = [], [root]
    while todo:
        pid = todo.pop()
        out.append(pid)
        todo += children.get(pid, [])
    return out


def _hwm_kib(pid: int) -> tuple[int, str] | None:
    try:
        status = Path(f"/proc/{pid}/status").read_text(encoding="ascii", errors="replace")
        cmd = Path(f"/proc/{pid}/cmdline").read_bytes().replace(b"\0", b" ").decode()
    except OSError:
        return None
    for line in status.splitlines():
        if line.startswith("VmHWM:"):
            return int(line.split()[1]), cmd.strip()
    return None


def timed(name: str, argv: list[str], executions: int) -> Run:
    """Run ``argv`` once; wall time, exit status and the peak RSS of each process it started."""
    peaks: dict[int, tuple[int, str]] = {}
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    proc = subprocess.Popen(argv, cwd=REPO, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    stop = threading.Event()

    def poll() -> None:
        while not stop.is_set():
            for pid in _tree(proc.pid):
                got = _hwm_kib(pid)
                if got and got[0] > peaks.get(pid, (0, ""))[0]:
                    peaks[pid] = got
            stop.wait(0.05)

    poller = threading.Thread(target=poll, daemon=True)
    poller.start()
    _, err = proc.communicate()
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    stop.set()
    poller.join()
    main = peaks.get(proc.pid, (0, ""))[0] / 1024
    others = {pid: v for pid, v in peaks.items() if pid != proc.pid}
    other = max((v[0] for v in others.values()), default=0) / 1024
    tail = err.decode(errors="replace").strip().splitlines()
    run = Run(
        name,
        executions,
        wall,
        proc.returncode,
        main,
        other,
        1 + len(others),
        cpu,
        note=tail[-1] if tail else "",
        peaks={f"{pid} {cmd[:80]}": kib / 1024 for pid, (kib, cmd) in peaks.items()},
    )
    if proc.returncode not in (0, 1):
        sys.stderr.write("\n".join(tail[-10:]) + "\n")
    return run


def _doc(out: Path) -> dict[str, Any] | None:
    try:
        doc: dict[str, Any] = json.loads((out / "results.json").read_text(encoding="utf-8"))
    except (OSError, json.JSONDecodeError):
        return None
    return doc


def _counts(doc: dict[str, Any] | None, run: Run) -> Run:
    if doc is None:
        return run
    rows = doc.get("executions") or []
    run.scored = sum(r.get("status") == "scored" for r in rows)
    run.cached = sum(bool(r.get("cached")) for r in rows)
    return run


def _read_all(root: Path) -> None:
    """Every file once, so that each measured run starts with the page cache warm."""
    for path in sorted(root.rglob("*")):
        if path.is_file():
            with path.open("rb") as fh:
                while fh.read(1 << 20):
                    pass


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n", 1)[0])
    parser.add_argument("--days", type=int, default=DAYS)
    parser.add_argument("--per-day", type=int, default=SLOTS_PER_DAY)
    parser.add_argument("--json", type=Path, default=FOLDER / "season_results.json")
    parser.add_argument("--no-dask", action="store_true", help="skip the LocalCluster run")
    parser.add_argument(
        "--rounds", type=int, default=2, help="cold runs of each kind, interleaved (default 2)"
    )
    args = parser.parse_args()

    root = FOLDER / f"season-{args.days}x{args.per_day}"
    t0 = time.perf_counter()
    if not (root / "season.json").exists():
        print(f"generating the season into {root} (once; not timed)...", flush=True)
        generate_season(root, days=args.days, per_day=args.per_day)
    season = json.loads((root / "season.json").read_text(encoding="utf-8"))
    n = len(season["executions"])
    size = sum(p.stat().st_size for p in root.rglob("*.bag"))
    print(
        f"season: {n} executions over {args.days} days, {size / 2**20:.0f} MiB of logs "
        f"({len(season['gt_files'])} GT hour files), ready in {time.perf_counter() - t0:.1f} s"
    )
    work = FOLDER / "season_runs"
    shutil.rmtree(work, ignore_errors=True)
    work.mkdir(parents=True)
    all_days = set(range(1, args.days + 1))
    manifest = work / "season.yaml"
    manifest.write_text(manifest_text(root, season, all_days), encoding="utf-8")
    one_day = work / "day1.yaml"
    one_day.write_text(manifest_text(root, season, {1}), encoding="utf-8")
    n_day = sum(e["day"] == 1 for e in season["executions"])
    _read_all(root)
    load = ", ".join(f"{x:.2f}" for x in os.getloadavg())
    print(f"machine: {os.cpu_count()} cores, load average {load} at start")
    print(
        f"  {'ertools rescore ...':<44} {'execs':>5} {'wall s':>8} {'s/exec':>7} "
        f"{'CPU s':>7} {'load':>5} {'main MiB':>8} {'other MiB':>9} {'procs':>5}  scored/cached"
    )

    runs: dict[str, Run] = {}

    # rescore places every log under its PATH (issue 24): a day's run is given that day's folder
    # (and the configs), not the season's, or it scores the whole season
    day_paths = [str(root / "day1"), str(root / "configs")]

    # the results of every run, by what they must equal: the season's (every configuration,
    # every round, the warm rerun) and day 1's (with and without reports)
    results: dict[str, list[tuple[str, dict[str, Any]]]] = {"season": [], "day 1": []}
    day_ids: set[str] = set()

    def go(key: str, label: str, config: Path, out: Path, count: int, *extra: str) -> Run:
        paths = day_paths if config == one_day else [str(root)]
        argv = [ERTOOLS, "rescore", *paths, "--config", str(config), "--out", str(out), *extra]
        load_before = os.getloadavg()[0]
        run = timed(label, argv, count)
        run.load = load_before
        doc = _doc(out)
        run = _counts(doc, run)
        if doc is not None:
            group = "day 1" if config == one_day else "season"
            results[group].append((f"{label} (round {len(rounds.get(key, [])) + 1})", doc))
            if group == "day 1":
                day_ids.update(str(r["id"]) for r in doc.get("executions") or [])
        # The least disturbed of the rounds counts (this machine is shared: other processes
        # only ever add time); every round is in the JSON.
        rounds.setdefault(key, []).append(run)
        if key not in runs or run.wall_s < runs[key].wall_s:
            runs[key] = run
        print(
            f"  {label:<44} {count:>5} {run.wall_s:8.2f} {run.per_execution_s:7.3f} "
            f"{run.cpu_s:7.1f} {run.load:5.1f} {run.peak_main_mib:8.1f} {run.peak_other_mib:9.1f} "
            f"{run.processes:>5}  "
            f"{run.scored}/{run.cached}{'' if run.exit in (0, 1) else '  FAILED: ' + run.note}",
            flush=True,
        )
        return run

    rounds: dict[str, list[Run]] = {}
    for r in range(1, args.rounds + 1):
        print(f"  round {r} of {args.rounds}, load average {os.getloadavg()[0]:.2f}", flush=True)
        cold = work / f"round{r}"
        go("jobs1", "--jobs 1, cold", manifest, cold / "j1", n, "--jobs", "1")
        go("jobs2", "--jobs 2, cold", manifest, cold / "j2", n, "--jobs", "2")
        if not args.no_dask:
            go(
                "dask",
                "--scheduler local --jobs 2 (LocalCluster), cold",
                manifest,
                cold / "dask",
                n,
                "--scheduler",
                "local",
                "--jobs",
                "2",
            )
        go("day1", "--jobs 2, cold, day 1 only", one_day, cold / "day1", n_day, "--jobs", "2")
        go(
            "warm",
            "--jobs 2, warm (second run, same folder)",
            manifest,
            cold / "j2",
            n,
            "--jobs",
            "2",
        )
    go(
        "day1_noreports",
        "--jobs 1 --no-reports, cold, day 1 (for scale)",
        one_day,
        work / "noreports",
        n_day,
        "--jobs",
        "1",
        "--no-reports",
    )

    print("\ntargets (issues 18 item 6 and 29):")
    checks: dict[str, bool] = {}

    def check(key: str, text: str, value: str, ok: bool) -> None:
        checks[key] = ok
        print(f"  {text:<56} {value:>14}  {'pass' if ok else 'FAIL'}")

    j1, j2 = runs["jobs1"], runs["jobs2"]
    speedup = j1.wall_s / j2.wall_s
    check("speedup", "--jobs 2 vs --jobs 1 (>= 1.7x)", f"{speedup:.2f}x", speedup >= 1.7)
    # per execution: the season's --jobs 1 against day 1's without reports (issue 29 item 1)
    reports = j1.per_execution_s / runs["day1_noreports"].per_execution_s
    check(
        "reports",
        "with reports vs --no-reports, --jobs 1 (<= 2x)",
        f"{reports:.2f}x",
        reports <= 2.0,
    )
    if "dask" in runs:
        slower = runs["dask"].wall_s / j2.wall_s - 1
        check(
            "dask",
            "Dask LocalCluster vs --jobs 2 (within 15 %)",
            f"{slower:+.1%}",
            abs(slower) <= 0.15,
        )
    warm = runs["warm"]
    check(
        "warm", "warm rerun (< 2 s)", f"{warm.wall_s:.2f} s", warm.wall_s < 2.0 and warm.cached == n
    )
    every = [r for rs in rounds.values() for r in rs]
    peak = max(max(r.peak_main_mib, r.peak_other_mib) for r in every)
    check("memory", "peak RSS of any process (< 200 MiB)", f"{peak:.0f} MiB", peak < 200)
    lin = runs["day1"].per_execution_s / j2.per_execution_s
    check(
        "linear",
        f"s/execution, {n_day} vs {n} executions (within 15 %)",
        f"{lin:.2f}",
        abs(lin - 1) <= 0.15,
    )
    everything = all(r.scored == r.executions for r in every)
    check("scored", "every execution scored in every run", f"{j2.scored}/{n}", everything)
    identical, compared = _identical(results, day_ids)
    same = all(ok for ok, _ in identical.values())
    check(
        "identical",
        "identical results in every configuration",
        f"{'yes' if same else 'NO'} ({compared} runs)",
        same,
    )
    for group, (_, diffs) in identical.items():
        for label, lines in diffs.items():
            print(f"    {group}: {label} differs from the first run:")
            for line in lines:
                print(f"      {line}")

    # A 16-worker cluster by the same measure (Amdahl): the serial part (manifest, hashes,
    # cache check, writing results and the site: what a warm run does) plus the executions
    # spread over the workers at the parallel efficiency measured with 2. Two per-execution
    # figures: the wall time with one worker (this machine, as loaded) and the CPU time (what
    # a worker with a core of its own spends: the figure for dedicated cluster nodes).
    serial = warm.wall_s
    wall_per_exec = (j1.wall_s - serial) / n
    cpu_per_exec = (j1.cpu_s - warm.cpu_s) / n
    efficiency = min((j1.wall_s - serial) / (2 * max(j2.wall_s - serial, 1e-9)), 1.0)
    projection = {
        f"{w}_{basis}": serial + n * per / (w * (efficiency if w > 1 else 1.0))
        for w in (1, 2, 16)
        for basis, per in (("wall", wall_per_exec), ("cpu", cpu_per_exec))
    }
    print("\nextrapolation (per execution measured here; Amdahl with the 2-worker efficiency):")
    print(
        f"  serial part (the warm run) {serial:.2f} s; per execution with one worker "
        f"{wall_per_exec:.3f} s wall, {cpu_per_exec:.3f} s CPU; 2-worker efficiency "
        f"{efficiency:.2f}"
    )
    for w in (1, 2, 16):
        a, b = projection[f"{w}_wall"], projection[f"{w}_cpu"]
        rate = 3600 * n / (b - serial)
        print(
            f"  {w:>2} worker(s), {n} executions: {a:8.1f} s by the wall time here, {b:8.1f} s "
            f"by the CPU time ({rate:,.0f} executions/hour)"
        )
    labels = {g: [label for label, _ in docs] for g, docs in results.items()}
    if results["season"] and results["day 1"]:
        labels["day 1 in the season"] = [results["day 1"][0][0], results["season"][0][0]]
    args.json.parent.mkdir(parents=True, exist_ok=True)
    args.json.write_text(
        json.dumps(
            {
                "executions": n,
                "days": args.days,
                "bytes": size,
                "load_average_at_start": load,
                "runs": {k: asdict(v) for k, v in runs.items()},
                "rounds": {k: [asdict(v) for v in vs] for k, vs in rounds.items()},
                "checks": checks,
                "identical": {
                    group: {"identical": ok, "differences": diffs, "runs": labels.get(group, [])}
                    for group, (ok, diffs) in identical.items()
                },
                "extrapolation": {
                    "serial_s": serial,
                    "wall_per_execution_s": wall_per_exec,
                    "cpu_per_execution_s": cpu_per_exec,
                    "efficiency_2": efficiency,
                    "seconds": projection,
                },
            },
            indent=2,
        )
        + "\n"
    )
    print(f"\nwrote {args.json}")
    return 0 if all(checks.values()) else 1


def _identical(
    results: dict[str, list[tuple[str, dict[str, Any]]]], day_ids: set[str]
) -> tuple[dict[str, tuple[bool, dict[str, list[str]]]], int]:
    """Each group's runs compared with its first; day 1's executions also compared between
    the day's first run and the season's first run (the same executions, scored alone)."""
    out = {
        group: compare([(label, comparable(doc)) for label, doc in docs])
        for group, docs in results.items()
    }
    if results["season"] and results["day 1"]:
        pair = [results["day 1"][0], results["season"][0]]
        out["day 1 in the season"] = compare(
            [(label, comparable(doc, day_ids)) for label, doc in pair]
        )
    return out, sum(len(docs) for docs in results.values())


if __name__ == "__main__":
    raise SystemExit(main())
