"""``make demo``: the main jobs of ertools on ``sample_bags/``, reports written to a folder,
then ``ertools rescore`` on the sample competition (a day of logs at one venue), whose results
site is the page to open.

Runs the same CLI a referee would type, so the demo shows (and checks) the real commands.
"""

from __future__ import annotations

import sys

from ertools.frozen_dataclass import frozen_dataclass

if __name__ == "__main__":
    # `python -m ertools.demo`: the module run under its own name, its imports included, inside
    # ertools.launch's guard (a Ctrl-C while they load: one line, exit 130)
    from ertools.launch import run as launch

    def _start() -> object:
        from ertools.demo import main  # lazy: in launch's Ctrl-C guard, 600 ms

        return main()

    sys.exit(launch(_start, "python -m ertools.demo"))

import io
from collections.abc import Iterator
from contextlib import redirect_stdout
from pathlib import Path

from ertools.atomic import write_text
from ertools.benchmarks import registry
from ertools.benchmarks.base import Audited, Simulated, offers
from ertools.cli.main import main as ertools_main
from ertools.samples.competition import DEFAULT_SEED, MANIFEST, write_competition

SAMPLES = Path(__file__).resolve().parent.parent / "sample_bags"


@frozen_dataclass
class Step:
    """One command of the demo and the file its stdout goes to (None: it prints nothing on
    stdout, its outputs are files of its own)."""

    title: str
    argv: list[str]
    stdout_file: str | None
    # rescore exits 1 when some executions could not be scored: the sample day has such
    # problems on purpose (a truncated log, a missing transform), listed on its page
    expected_exit: int = 0


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
    samples_by_name = {}
    for name in registry.names():
        bench = registry.get(name)
        sample = bench.sample_args(samples) if isinstance(bench, Simulated) else None
        if sample is not None:
            samples_by_name[name] = list(sample)
    if not samples_by_name:
        raise SystemExit(f"demo: no sample logs in {samples}: run `make samples` first")
    first, first_sample = next(iter(samples_by_name.items()))
    yield Step(
        f"info of the {registry.get(first).title} bag",
        ["info", first_sample[0]],
        f"info_{first}.txt",
    )
    for name, sample in samples_by_name.items():
        bench = registry.get(name)
        # the referee-scored benchmarks draw nothing: `score` refuses --foxglove for them
        foxglove = ["--foxglove", str(out / f"{name}.mcap")] if offers(bench, "foxglove") else []
        yield Step(
            f"{bench.title} score",
            ["score", name, *sample, "--report", str(out / name), *foxglove],
            f"{name}_score.yaml",
        )
    yield Step(
        "noise of the stationary marker set",
        ["noise", str(_first(samples / "stationary", "*.bag")), "--format", "json"],
        "noise.json",
    )
    for name, sample in samples_by_name.items():
        bench = registry.get(name)
        if isinstance(bench, Audited):
            yield Step(
                f"audit of the {bench.title} benchmark",
                ["audit", sample[0], "--format", "text", "--report", str(out / f"audit_{name}")],
                f"audit_{name}.txt",
            )


def competition_step(day: Path, out: Path) -> Step:
    """``ertools rescore`` of the sample competition in ``day`` into ``out``."""
    return Step(
        "rescore of the sample competition (a day at one venue, problems planted)",
        ["rescore", str(day), "--config", str(day / MANIFEST), "--out", str(out), "--jobs", "2"],
        None,  # its results are the folder: results.json, results.csv, index.html
        expected_exit=1,
    )


def season_steps(season: Path, out: Path) -> list[Step]:
    """The sample 2019 season in the RSBB layout: its manifest drafted, then its results site
    from the draft as written."""
    manifest = out / "season2019.yaml"
    return [
        Step(
            "draft of the sample 2019 season's manifest (the RSBB layout)",
            ["rescore", str(season), "--init", str(manifest)],
            None,
        ),
        Step(
            "rescore of the sample 2019 season (FBM and task-benchmark leaderboards)",
            ["rescore", str(season), "--config", str(manifest), "--out", str(out / "season")],
            None,
        ),
    ]


def make_competition(day: Path) -> None:
    """The sample competition in ``day`` (``python -m ertools.samples --competition DAY``),
    generated once: it is deterministic."""
    if (day / "answers.json").is_file():
        return
    print(
        f"== the sample competition: python -m ertools.samples --competition {day}", file=sys.stderr
    )
    write_competition(day, seed=DEFAULT_SEED)


def run(out: Path, samples: Path = SAMPLES) -> int:
    """Run every step; returns the number of steps that failed."""
    out.mkdir(parents=True, exist_ok=True)
    failed = 0
    make_competition(out / "competition")
    site = out / "rescore"
    (out / "season2019.yaml").unlink(missing_ok=True)  # a rerun drafts it again
    season = season_steps(samples / "season2019", out)
    for step in [*steps(samples, out), competition_step(out / "competition", site), *season]:
        print(f"== {step.title}: ertools {' '.join(step.argv)}", file=sys.stderr)
        if step.stdout_file is None:
            written = step.argv[step.argv.index("--out") + 1] if "--out" in step.argv else None
            target: Path | None = None if written is None else Path(written) / "index.html"
            code = ertools_main(step.argv)
        else:
            target = out / step.stdout_file
            printed = io.StringIO()
            with redirect_stdout(printed):
                code = ertools_main(step.argv)
            if printed.getvalue():  # nothing printed (its errors are above): no file
                write_text(target, printed.getvalue())
            else:
                target.unlink(missing_ok=True)
                target = None
        shown = "nothing on stdout" if target is None else f"-> {target}"
        if code != step.expected_exit:
            failed += 1
            print(f"   exit status {code} (see above)", file=sys.stderr)
        elif code:
            print(f"   {shown} (exit {code}, as planted: see the problems above)", file=sys.stderr)
        else:
            print(f"   {shown}", file=sys.stderr)
    index = [p for p in sorted(out.glob("*/index.html")) if p.parent not in (site, out / "season")]
    print("\nReports written:", file=sys.stderr)
    for p in index:
        print(f"  {p}", file=sys.stderr)
    print(
        f"The sample competition's results site: {(site / 'index.html').resolve()}", file=sys.stderr
    )
    print(
        f"The sample 2019 season's results site: {(out / 'season' / 'index.html').resolve()}",
        file=sys.stderr,
    )
    print("Open it (or a report above) in a browser to start.", file=sys.stderr)
    for mcap in sorted(out.glob("*.mcap"))[:1]:
        print(f"Open {mcap.resolve()} in Foxglove (docs/foxglove.md).", file=sys.stderr)
    return failed


def main(argv: list[str] | None = None) -> int:
    args = sys.argv[1:] if argv is None else argv
    out = Path(args[0]) if args else Path("demo_output")
    return 1 if run(out) else 0
