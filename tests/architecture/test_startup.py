"""A command imports what it runs (issue 39, item 2): the modules a command leaves in
``sys.modules``, seen in a fresh interpreter. Sets of modules, never timings (timings go to
``make bench``): a heavy module that comes back into a command's imports fails here whatever
the machine's speed."""

from __future__ import annotations

import json
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
    own = packages()["trajectory"]
    others = {p for p in packages().values() if p != own}
    assert {p for p in others if loaded(modules, p)} == set()
    assert loaded(modules, "ertools.report") == []  # nothing asked for a report or a figure


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
