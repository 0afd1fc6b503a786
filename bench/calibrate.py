"""`make calibrate`: do the 95% score intervals cover the truth 95% of the time? (issue 28)

For each benchmark of :data:`calibration.MODULES`, ``--trials`` seeded simulated executions
(known noise, known noiseless truth; one module per benchmark under bench/calibration/, see
its docstring), each scored with intervals exactly as ``ertools score`` does; counts how often
the interval covers the true noiseless score and writes the table (a row per benchmark:
trials, scores, coverage %, mean width) into docs/uncertainty.md between its markers.

    .venv/bin/python bench/calibrate.py [--trials 1000] [--draws 400] [--only fbm3w] [--jobs 2]
        [--docs docs/uncertainty.md | --no-docs]

Nothing here is a test: `make test` runs the small versions (tests/calibration/).
"""

from __future__ import annotations

import argparse
import importlib
import math
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass
from pathlib import Path

HERE = Path(__file__).resolve().parent
REPO = HERE.parent
sys.path.insert(0, str(HERE))

from calibration import MODULES, Row  # noqa: E402

BEGIN = "<!-- calibration table: bench/calibrate.py writes between these markers -->"
END = "<!-- end of calibration table -->"
TARGET = (93.0, 97.0)


@dataclass(frozen=True)
class Coverage:
    """What the trials of one benchmark gave (``keys``: (scores, covered) per score key, run
    and segment numbers replaced by ``*``)."""

    benchmark: str
    trials: int
    scores: int
    covered: int
    mean_width: float
    unit_scale: float
    unit: str
    seconds: float
    keys: tuple[tuple[str, int, int], ...] = ()

    @property
    def percent(self) -> float:
        return 100.0 * self.covered / self.scores if self.scores else math.nan

    @property
    def executions_covered(self) -> str:
        return f"{self.covered}/{self.scores}"


# how each benchmark's widths are shown (its scores' unit)
UNITS = {
    "fbm1": (1.0, ""),
    "fbm2h": (1000.0, "mm or mrad"),
    "fbm3w": (1000.0, "mm"),
    "trajectory": (1.0, ""),
}


def coverage(rows: list[Row]) -> tuple[int, int, float]:
    """(scores, covered, summed width) of a list of rows."""
    covered = sum(1 for _, true, lo, hi in rows if lo <= true <= hi)
    return len(rows), covered, sum(hi - lo for _, _, lo, hi in rows)


def key_of(key: str) -> str:
    """A score key with its run or segment number as ``*`` (``runs_details.*.distance_error``)."""
    return ".".join("*" if part.isdigit() else part for part in key.split("."))


Chunk = tuple[int, int, float, dict[str, tuple[int, int]]]


def _chunk(name: str, seeds: range, draws: int) -> Chunk:
    """(scores, covered, summed width, (scores, covered) per key) of one benchmark's trials
    over ``seeds``."""
    module = importlib.import_module(MODULES[name])
    scores = covered = 0
    width = 0.0
    keys: dict[str, tuple[int, int]] = {}
    for seed in seeds:
        rows = module.trial(seed, draws)
        n, c, w = coverage(rows)
        scores, covered, width = scores + n, covered + c, width + w
        for key, true, lo, hi in rows:
            k = key_of(key)
            total, inside = keys.get(k, (0, 0))
            keys[k] = (total + 1, inside + int(lo <= true <= hi))
    return scores, covered, width, keys


def run_benchmark(
    name: str, trials: int, draws: int, first_seed: int = 0, jobs: int = 1
) -> Coverage | None:
    """``trials`` trials of one benchmark (seeds first_seed..), on ``jobs`` processes; None if
    its module is absent."""
    try:
        importlib.import_module(MODULES[name])
    except ModuleNotFoundError as err:
        if err.name != MODULES[name]:
            raise
        return None
    t0 = time.perf_counter()
    seeds = range(first_seed, first_seed + trials)
    chunks = [seeds[k::jobs] for k in range(jobs)]
    if jobs > 1:
        with ProcessPoolExecutor(jobs) as pool:
            parts = list(pool.map(_chunk, [name] * jobs, chunks, [draws] * jobs))
    else:
        parts = [_chunk(name, seeds, draws)]
    scores = sum(p[0] for p in parts)
    covered = sum(p[1] for p in parts)
    width = sum(p[2] for p in parts)
    keys: dict[str, tuple[int, int]] = {}
    for p in parts:
        for k, (n, c) in p[3].items():
            total, inside = keys.get(k, (0, 0))
            keys[k] = (total + n, inside + c)
    scale, unit = UNITS.get(name, (1.0, ""))
    return Coverage(
        name,
        trials,
        scores,
        covered,
        width / scores if scores else math.nan,
        scale,
        unit,
        time.perf_counter() - t0,
        tuple((k, n, c) for k, (n, c) in keys.items()),
    )


def table(results: list[Coverage], draws: int) -> str:
    lines = [
        "| benchmark | trials | scores | coverage of the 95% intervals | mean width | time |",
        "|---|---:|---:|---:|---:|---:|",
    ]
    for r in results:
        ok = TARGET[0] <= r.percent <= TARGET[1]
        lines.append(
            f"| {r.benchmark} | {r.trials} | {r.scores} | {r.percent:.1f}% "
            f"({r.executions_covered}){'' if ok else ' (outside 93-97%)'} | "
            f"{r.mean_width * r.unit_scale:.4g} {r.unit} | {r.seconds:.0f} s |"
        )
    lines.append("")
    lines.append(f"{draws} Monte Carlo draws per interval; seeds 0 to trials - 1. Per score key:")
    lines.append("")
    lines.append("| benchmark | score key | scores | coverage |")
    lines.append("|---|---|---:|---:|")
    for r in results:
        for key, n, c in r.keys:
            pct = 100.0 * c / n if n else math.nan
            ok = TARGET[0] <= pct <= TARGET[1]
            flag = "" if ok else " (outside 93-97%)"
            lines.append(f"| {r.benchmark} | `{key}` | {n} | {pct:.1f}% ({c}/{n}){flag} |")
    return "\n".join(lines)


def write_docs(path: Path, text: str) -> None:
    """Replace the table between the markers (appended under "## Calibration" if absent)."""
    doc = path.read_text(encoding="utf-8") if path.exists() else "# Uncertainty of the scores\n"
    block = f"{BEGIN}\n{text}\n{END}"
    if BEGIN in doc and END in doc:
        head, rest = doc.split(BEGIN, 1)
        doc = head + block + rest.split(END, 1)[1]
    elif "## Calibration" in doc:
        head, rest = doc.split("## Calibration", 1)
        first, _, tail = rest.partition("\n")
        doc = f"{head}## Calibration{first}\n\n{block}\n{tail}"
    else:
        doc = doc.rstrip("\n") + f"\n\n## Calibration\n\n{block}\n"
    path.write_text(doc, encoding="utf-8")


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--trials", type=int, default=1000)
    ap.add_argument("--draws", type=int, default=400)
    ap.add_argument("--only", action="append", choices=sorted(MODULES))
    ap.add_argument("--jobs", type=int, default=1, help="processes (seeds split among them)")
    ap.add_argument("--docs", type=Path, default=REPO / "docs" / "uncertainty.md")
    ap.add_argument("--no-docs", action="store_true")
    args = ap.parse_args(argv)
    results = []
    for name in args.only or list(MODULES):
        r = run_benchmark(name, args.trials, args.draws, jobs=max(1, args.jobs))
        if r is None:
            print(f"{name}: bench/calibration/{name}.py not written yet, skipped")
            continue
        print(
            f"{name}: {r.percent:.1f}% of {r.scores} intervals cover the truth "
            f"({r.trials} executions, {r.seconds:.0f} s)",
            flush=True,
        )
        results.append(r)
    text = table(results, args.draws)
    print(text)
    if not args.no_docs and results:
        write_docs(args.docs, text)
        print(f"written into {args.docs}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
