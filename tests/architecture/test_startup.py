"""A command imports what it runs (issue 39, item 2): the modules a command leaves in
``sys.modules``, seen in a fresh interpreter. Sets of modules, never timings (timings go to
``make bench``): a heavy module that comes back into a command's imports fails here whatever
the machine's speed."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from ertools._version import __version__
from ertools.benchmarks import registry

ROOT = Path(__file__).resolve().parents[2]
ROBOTLOG = ROOT / "sample_bags" / "robotlog"

# Runs the command in-process, then prints its exit code and every module imported.
PROBE = """
import contextlib, io, json, sys
from ertools.cli.main import main
with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
    try:
        code = main(sys.argv[1:])
    except SystemExit as stop:
        code = stop.code
print(json.dumps({"code": code, "modules": sorted(sys.modules)}))
"""

# Heavy for any command that does not draw, tabulate or write HTML (issue 39).
HEAVY = ("scipy", "matplotlib", "pandas", "jinja2")
# What `score trajectory --format json` does not use, each 2 to 20 ms of its start-up (issue 39
# item 2, docs/performance.md "Start-up"): PyYAML (YAML output, config files, rosbag2
# metadata), the MCAP readers (a ROS1 bag here), the ROS1 record scan of damaged bags, NumPy's
# masked arrays (np.median, np.percentile, np.unique import them: ertools.arrays has their own),
# sqlite3 (rosbag2 storage). Then standard-library modules, each ~1-3 ms with what it imports,
# used where they are needed (a `# lazy:` import): statistics (z_value; it imports fractions
# and decimal), tempfile (rosbag2's file-compressed storage), csv and decimal (text
# trajectories), shutil with lzma (argparse's width; bz2 too, but the sample logs are bz2
# chunks), and the 2015 state enums (ertools.states: only state topics). Then the modules
# split off those the command imports, each with frozen dataclasses it never makes (~0.65 ms
# each, issue 39, lazy39b): frozen stretches and gaps on a path (FBM2H, FBM3W), every message
# as an object (RSBB, referee), the clock check (timeline, competitions), the node versions.
NOT_FOR_JSON = (
    "yaml",
    "ertools.io.mcap",
    "ertools.io.ros1.check",
    "numpy.ma",
    "sqlite3",
    "statistics",
    "fractions",
    "tempfile",
    "csv",
    "decimal",
    "shutil",
    "lzma",
    "ertools.states",
    "ertools.benchmarks.common.frozen",
    "ertools.benchmarks.common.path_gaps",
    "ertools.io.messages",
    "ertools.io.clock",
    "ertools.node_versions",
)


def imported(*argv: str) -> tuple[int, set[str]]:
    """The exit code of ``ertools ARGV`` and the modules it imported."""
    done = subprocess.run(
        [sys.executable, "-c", PROBE, *argv],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=300,
        check=True,
    )
    out = json.loads(done.stdout.splitlines()[-1])
    return out["code"], set(out["modules"])


def packages() -> dict[str, str]:
    """Each registered benchmark's package (``ertools.benchmarks.fbm1`` for fbm1h and fbm1w)."""
    return {
        e.name: e.absolute.partition(":")[0].rpartition(".")[0]
        for e in registry.ENTRIES
        if e.absolute.startswith("ertools.benchmarks.")
    }


def loaded(modules: set[str], package: str) -> list[str]:
    return sorted(m for m in modules if m == package or m.startswith(package + "."))


def test_the_top_level_help_and_version_import_no_numpy() -> None:
    for argv in (["--help"], ["--version"]):
        code, modules = imported(*argv)
        assert code == 0
        assert "ertools.cli.main" in modules  # the probe sees the command's imports
        assert "numpy" not in modules, argv
        assert [p for p in packages().values() if loaded(modules, p)] == [], argv
        if argv == ["--version"]:  # the version alone: not even the registry's protocols
            assert loaded(modules, "ertools.benchmarks") == []


def test_score_help_lists_every_benchmark_and_imports_none() -> None:
    code, modules = imported("score", "--help")
    assert code == 0
    assert "numpy" not in modules
    for name, package in packages().items():
        assert loaded(modules, package) == [], name


# Benchmarks whose declaration imports their scorers (so their parser loads NumPy): none
# since every benchmark is on the protocols; the list may not grow.
HEAVY_DECLARES: frozenset[str] = frozenset()


def test_a_benchmarks_help_imports_its_declaration_and_no_numpy() -> None:
    heavy = set()
    for name, package in packages().items():
        code, modules = imported("score", name, "--help")
        assert code == 0, name
        others = {p for p in packages().values() if p != package}
        assert {p for p in others if loaded(modules, p)} == set(), name
        if "numpy" in modules:
            heavy.add(name)
    new, fixed = sorted(heavy - HEAVY_DECLARES), sorted(HEAVY_DECLARES - heavy)
    assert not new, f"these parsers import NumPy: {new}"
    assert not fixed, f"NumPy-free now: remove them from HEAVY_DECLARES: {fixed}"


@pytest.mark.skipif(not ROBOTLOG.is_dir(), reason="no sample logs (make samples)")
def test_scoring_a_trajectory_imports_nothing_heavy_and_no_other_benchmark() -> None:
    robot = sorted(ROBOTLOG.glob("FBM2H_*.bag"))[0]
    code, modules = imported("score", "trajectory", str(robot), str(ROBOTLOG), "--format", "json")
    assert code == 0
    assert [m for m in HEAVY if m in modules] == []
    assert [m for m in NOT_FOR_JSON if m in modules] == []
    own = packages()["trajectory"]
    others = {p for p in packages().values() if p != own}
    assert {p for p in others if loaded(modules, p)} == set()
    assert loaded(modules, "ertools.report") == []  # nothing asked for a report or a figure


# Builds one command's parser, then prints every module imported (no json: it would be one).
PARSER_PROBE = """
import sys
from ertools.cli.main import build_parser
build_parser(sys.argv[1], sys.argv[2])
print(" ".join(sorted(sys.modules)))
"""

# All the ertools modules the parser of `score trajectory` imports (issue 39 item 2: 30 ms or
# less, docs/performance.md "The parser of `score trajectory`"). The list may shrink, not grow:
# each module more is its import time and its dataclasses (~0.6 ms each) on every `--help`.
TRAJECTORY_PARSER = frozenset(
    {
        "ertools",
        "ertools._version",
        "ertools.benchmarks",
        "ertools.benchmarks.base",
        "ertools.benchmarks.common",
        "ertools.benchmarks.common.inputs",
        "ertools.benchmarks.common.spec",
        "ertools.benchmarks.registry",
        "ertools.benchmarks.trajectory",
        "ertools.benchmarks.trajectory.declare",
        "ertools.benchmarks.trajectory.inputs",
        "ertools.cli",
        "ertools.cli.command",
        "ertools.cli.groups",
        "ertools.cli.main",
        "ertools.cli.options",
        "ertools.cli.output",
        "ertools.cli.result_options",
        "ertools.cli.score",
        "ertools.cli.text",
        "ertools.errors",
        # the decorator of the dataclasses above: 1 method compiled per class, not 6 (1 ms here)
        "ertools.frozen_dataclass",
        "ertools.io",
        "ertools.io.names",
        "ertools.progress",
    }
)
# Standard-library modules the parser no longer imports, each 1.5 - 7 ms of its time (they may
# not be imported lazily: the ertools module that needs them is): logging (cli/logs.py, after
# parsing), json (serialize.json_text), tempfile (ertools.atomic, for --out), datetime
# (ertools.timeutil, for a number's bound once given); shutil with bz2, lzma and zlib, 2 ms
# (argparse's formatter asks it the terminal's width: cli.main's _Formatter asks os).
NOT_FOR_THE_PARSER = ("logging", "json", "tempfile", "datetime", "shutil")


def test_the_trajectory_parser_imports_only_what_it_needs() -> None:
    done = subprocess.run(
        [sys.executable, "-c", PARSER_PROBE, "ertools score trajectory", "ertools.cli.score"],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=120,
        check=True,
    )
    modules = set(done.stdout.split())
    assert "ertools.benchmarks.trajectory.declare" in modules  # the probe built that parser
    own = {m for m in modules if m == "ertools" or m.startswith("ertools.")}
    assert sorted(own - TRAJECTORY_PARSER) == []
    assert [m for m in NOT_FOR_THE_PARSER if m in modules] == []
    assert "numpy" not in modules


def test_python_m_ertools_is_the_command() -> None:
    done = subprocess.run(
        [sys.executable, "-m", "ertools", "--version"],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
    )
    assert (done.returncode, done.stdout.strip()) == (0, f"ertools {__version__}")


# The console command's environment once it has started, printed after `ertools --version`.
ENV_PROBE = """
import os, sys
from ertools.__main__ import main
sys.argv = ["ertools", "--version"]
main()
print(os.environ.get("OPENBLAS_NUM_THREADS"))
"""


@pytest.mark.parametrize(("given", "used"), [(None, "1"), ("3", "3")])
def test_the_command_starts_one_blas_thread_unless_told(given: str | None, used: str) -> None:
    # OpenBLAS starts its threads when NumPy is imported: ~50 ms of CPU on 2 cores
    env = {k: v for k, v in os.environ.items() if k != "OPENBLAS_NUM_THREADS"}
    if given is not None:
        env["OPENBLAS_NUM_THREADS"] = given
    done = subprocess.run(
        [sys.executable, "-c", ENV_PROBE],
        cwd=ROOT,
        env=env,
        capture_output=True,
        text=True,
        timeout=120,
        check=True,
    )
    assert done.stdout.split() == ["ertools", __version__, used]


# What the console command leaves for Python's exit (`ertools --version`): frozen objects and
# the collector's settings.
EXIT_PROBE = """
import gc, sys
from ertools.__main__ import main
sys.argv = ["ertools", "--version"]
code = main()
print(code, gc.get_freeze_count(), len(gc.get_objects()), gc.get_threshold()[0])
"""


def test_the_command_leaves_no_heap_for_the_exits_garbage_collection() -> None:
    # Python's exit collects every generation, the frozen objects excepted: 40 ms after an
    # hour's score (docs/performance.md, "Exit"); the run collects every 100,000 new objects
    done = subprocess.run(
        [sys.executable, "-c", EXIT_PROBE],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=120,
        check=True,
    )
    code, frozen, left, threshold = done.stdout.split()[-4:]
    assert code == "0"
    assert int(frozen) > 1000  # the modules' objects, at least
    assert int(left) < 100  # what the exit's collections would scan
    assert int(threshold) == 100_000  # Python's default is 700
