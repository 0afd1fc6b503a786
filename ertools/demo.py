"""``make demo``: the main jobs of ertools on ``sample_bags/``, reports written to a folder.

Runs the same CLI a referee would type, so the demo shows (and checks) the real commands.
"""

from __future__ import annotations

import sys
from collections.abc import Iterator
from contextlib import redirect_stdout
from dataclasses import dataclass
from pathlib import Path

from ertools.cli.main import main as ertools_main

SAMPLES = Path(__file__).resolve().parent.parent / "sample_bags"


@dataclass(frozen=True)
class Step:
    """One command of the demo and the file its stdout goes to."""

    title: str
    argv: list[str]
    stdout_file: str


def _first(folder: Path, pattern: str) -> Path:
    found = sorted(folder.glob(pattern))
    if not found:
        raise SystemExit(f"demo: no {pattern} in {folder}: run `make samples` first")
    return found[0]


def steps(samples: Path, out: Path) -> Iterator[Step]:
    """The demo's commands, in the order a referee would run them."""
    yield Step(
        "timeline of the sample folder",
        ["timeline", str(samples), "--plot", str(out / "timeline.png")],
        "timeline.txt",
    )
    fbm3 = samples / "fbm3w"
    fbm3_bag = _first(fbm3, "*.bag")
    yield Step("info of the FBM3@Work bag", ["info", str(fbm3_bag)], "info_fbm3w.txt")
    yield Step(
        "FBM3@Work score",
        [
            "score",
            "fbm3w",
            str(fbm3_bag),
            "--report",
            str(out / "fbm3w"),
            "--foxglove",
            str(out / "fbm3w.mcap"),
        ],
        "fbm3w_score.yaml",
    )
    fbm2 = samples / "fbm2h"
    fbm2_bag = _first(fbm2, "*.bag")
    yield Step(
        "FBM2@Home score",
        [
            "score",
            "fbm2h",
            str(fbm2_bag),
            "--goal",
            str(_first(fbm2, "*goal*.yaml")),
            "--transform",
            str(_first(fbm2, "transform-*.yaml")),
            "--report",
            str(out / "fbm2h"),
        ],
        "fbm2h_score.yaml",
    )
    fbm1 = samples / "fbm1h"
    fbm1_bag = _first(fbm1, "*.bag")
    yield Step(
        "FBM1@Home score",
        [
            "score",
            "fbm1h",
            str(fbm1_bag),
            "--items",
            str(_first(fbm1, "fbm1h.yaml")),
            "--report",
            str(out / "fbm1h"),
        ],
        "fbm1h_score.yaml",
    )
    robot = samples / "robotlog"
    robot_bag = _first(robot, "FBM2H_*.bag")
    yield Step(
        "robot log vs ground truth",
        [
            "score",
            "trajectory",
            str(robot_bag),
            str(robot),
            "--offset",
            "auto",
            "--apply-offset",
            "--report",
            str(out / "trajectory"),
        ],
        "trajectory_score.yaml",
    )
    yield Step(
        "noise of the stationary marker set",
        ["noise", str(_first(samples / "stationary", "*.bag")), "--format", "json"],
        "noise.json",
    )
    yield Step(
        "audit of the FBM2@Home benchmark",
        ["audit", str(fbm2_bag), "--format", "text", "--report", str(out / "audit_fbm2h")],
        "audit_fbm2h.txt",
    )


def run(out: Path, samples: Path = SAMPLES) -> int:
    """Run every step; returns the number of steps that failed."""
    out.mkdir(parents=True, exist_ok=True)
    failed = 0
    for step in steps(samples, out):
        print(f"== {step.title}: ertools {' '.join(step.argv)}", file=sys.stderr)
        target = out / step.stdout_file
        with target.open("w", encoding="utf-8") as fh, redirect_stdout(fh):
            code = ertools_main(step.argv)
        if code != 0:
            failed += 1
            print(f"   exit status {code} (see above)", file=sys.stderr)
        else:
            print(f"   -> {target}", file=sys.stderr)
    index = [p for p in sorted(out.glob("*/index.html"))]
    print("\nReports written:", file=sys.stderr)
    for p in index:
        print(f"  {p}", file=sys.stderr)
    print(f"Open {out.resolve()}/fbm3w/index.html in a browser to start.", file=sys.stderr)
    print(f"Open {out.resolve()}/fbm3w.mcap in Foxglove (docs/foxglove.md).", file=sys.stderr)
    return failed


def main(argv: list[str] | None = None) -> int:
    args = sys.argv[1:] if argv is None else argv
    out = Path(args[0]) if args else Path("demo_output")
    return 1 if run(out) else 0


if __name__ == "__main__":
    raise SystemExit(main())
