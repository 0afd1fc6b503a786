"""The cluster bench: `ertools rescore --scheduler tcp://...` on a Dask cluster started by
hand (a `dask scheduler` and two `dask worker --nthreads 1` on 127.0.0.1, as
tests/rescore/test_rescore_dask.py starts them), against `--jobs 2` on the same day of the
season (issue 29 item 2: the fixed cost apart from the per-execution cost on a real cluster).

A cluster's workers outlive a rescore: the first run into fresh workers pays their fixed cost
(each worker's fork server, python -m ertools.competition.children, and the first imports of each
benchmark), the next runs only the client's connection and the executions. So the runs are:
`--jobs 2`; the cluster on fresh workers; the cluster again (warm workers), each cold (an empty
results folder), interleaved over ``--rounds`` rounds with fresh workers each round. CPU
seconds count the rescore command and, on the cluster, what its workers' process trees spent
during the run (from /proc: the workers, their fork servers and scorers).

    .venv/bin/python bench/rescore_cluster.py [--per-day 36] [--rounds 2]
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import socket
import subprocess
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

from rescore_season import ERTOOLS, FOLDER, _read_all, _tree, manifest_text, timed  # noqa: E402
from season import generate_season  # noqa: E402
from season_compare import comparable, compare  # noqa: E402

DASK = str(Path(sys.executable).parent / "dask")
# what docs/rescore.md tells a cluster's operator to set: what --scheduler local sets itself
WORKER_ENV = {
    "DASK_DISTRIBUTED__WORKER__PROFILE__ENABLED": "False",
    "DASK_DISTRIBUTED__ADMIN__TICK__INTERVAL": "1s",
    "DASK_DISTRIBUTED__ADMIN__SYSTEM_MONITOR__INTERVAL": "5s",
    "DASK_DISTRIBUTED__WORKER__MEMORY__MONITOR_INTERVAL": "1s",
}
TICKS = os.sysconf("SC_CLK_TCK")


def _cpu_s(pids: list[int]) -> float:
    """User + system seconds of ``pids`` (with their reaped children), from /proc."""
    total = 0
    for pid in pids:
        try:
            with open(f"/proc/{pid}/stat", encoding="ascii", errors="replace") as fh:
                fields = fh.read().rsplit(")", 1)[1].split()
        except OSError:
            continue
        total += sum(int(f) for f in fields[11:15])  # utime stime cutime cstime
    return total / TICKS


class Cluster:
    """A scheduler and two one-thread workers on 127.0.0.1, killed on close."""

    def __init__(self, log: Path) -> None:
        with socket.socket() as s:
            s.bind(("127.0.0.1", 0))
            port = s.getsockname()[1]
        self.address = f"tcp://127.0.0.1:{port}"
        env = {**os.environ, **WORKER_ENV}
        self._log = log.open("a")
        common = {"env": env, "stdout": self._log, "stderr": subprocess.STDOUT}
        self.procs = [
            subprocess.Popen(
                [DASK, "scheduler", "--host", "127.0.0.1", "--port", str(port), "--no-dashboard"],
                **common,  # type: ignore[call-overload]
            )
        ]
        worker = [DASK, "worker", self.address, "--nthreads", "1", "--host", "127.0.0.1"]
        worker += ["--no-nanny", "--memory-limit", "0", "--no-dashboard"]
        self.workers = [
            subprocess.Popen(worker, **common)  # type: ignore[call-overload]
            for _ in range(2)
        ]
        self.procs += self.workers
        import distributed  # lazy: the optional Dask extra, as in ertools

        with distributed.Client(self.address, timeout="30s") as client:
            client.wait_for_workers(2, timeout=60)

    def cpu_s(self) -> float:
        return _cpu_s([pid for w in self.workers for pid in _tree(w.pid)])

    def close(self) -> None:
        for proc in self.procs:
            proc.kill()
        for proc in self.procs:
            proc.wait()
        self._log.close()


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n", 1)[0])
    parser.add_argument("--per-day", type=int, default=36)
    parser.add_argument("--rounds", type=int, default=2)
    args = parser.parse_args()
    root = FOLDER / f"season-1x{args.per_day}"
    if not (root / "season.json").exists():
        print(f"generating one day into {root} (once; not timed)...", flush=True)
        generate_season(root, days=1, per_day=args.per_day)
    season = json.loads((root / "season.json").read_text(encoding="utf-8"))
    n = len(season["executions"])
    work = FOLDER / "cluster_runs"
    shutil.rmtree(work, ignore_errors=True)
    work.mkdir(parents=True)
    manifest = work / "day1.yaml"
    manifest.write_text(manifest_text(root, season, {1}), encoding="utf-8")
    paths = [str(root / "day1"), str(root / "configs")]
    _read_all(root)
    print(f"one day: {n} executions; machine: {os.cpu_count()} cores")
    print(f"  {'ertools rescore ...':<40} {'wall s':>8} {'s/exec':>7} {'CPU s':>7} {'load':>5}")
    best: dict[str, tuple[float, float]] = {}
    docs = []

    def go(key: str, label: str, out: Path, extra: list[str], cluster: Cluster | None) -> None:
        argv = [ERTOOLS, "rescore", *paths, "--config", str(manifest), "--out", str(out), *extra]
        load = os.getloadavg()[0]
        before = cluster.cpu_s() if cluster else 0.0
        run = timed(label, argv, n)
        cpu = run.cpu_s + (cluster.cpu_s() - before if cluster else 0.0)
        print(f"  {label:<40} {run.wall_s:8.2f} {run.wall_s / n:7.3f} {cpu:7.1f} {load:5.1f}")
        if key not in best or run.wall_s < best[key][0]:
            best[key] = (run.wall_s, cpu)
        doc = json.loads((out / "results.json").read_text(encoding="utf-8"))
        docs.append((f"{label} ({out.parent.name})", comparable(doc)))

    for r in range(1, args.rounds + 1):
        here = work / f"round{r}"
        go("jobs2", "--jobs 2", here / "jobs2", ["--jobs", "2"], None)
        cluster = Cluster(work / "dask.log")
        try:
            on = ["--scheduler", cluster.address]
            go("fresh", "cluster, fresh workers", here / "fresh", on, cluster)
            go("warm", "cluster, warm workers", here / "warm", on, cluster)
        finally:
            cluster.close()
    j2 = best["jobs2"][0]
    print()
    for key, text in (("fresh", "cluster, fresh workers"), ("warm", "cluster, warm workers")):
        wall, cpu = best[key]
        extra = cpu - best["jobs2"][1]
        print(f"  {text} vs --jobs 2: {wall / j2 - 1:+.1%} wall, {extra:+.1f} s CPU")
    fixed = best["fresh"][1] - best["warm"][1]
    print(f"  the workers' fixed cost (fresh - warm, CPU): {fixed:.1f} s")
    same, diffs = compare(docs)
    verdict = "yes" if same else "NO: " + ", ".join(diffs)
    print(f"  identical results in every run: {verdict} ({len(docs)} runs)")
    return 0 if same else 1


if __name__ == "__main__":
    raise SystemExit(main())
