"""A Ctrl-C in a program's first moments (issue 36, finding 18): every entry point, the
``ertools`` command and the ``python -m ertools...`` modules, answers one line,
``PROGRAM: interrupted``, and exit status 130, never a traceback of the imports.

The moments are chosen two ways. Exactly: the program runs under a harness whose import hook
sends the process SIGINT as a chosen module starts to load (the KeyboardInterrupt then comes
from inside the import machinery, as a real Ctrl-C there does). And as a user does: a real
SIGINT sent to the running command once /proc shows a library's code loaded, and a moment
after.
"""

from __future__ import annotations

import os
import shutil
import signal
import subprocess
import sys
import textwrap
import time
from collections.abc import Iterator
from importlib import import_module
from pathlib import Path

import pytest

from ertools import launch

pytestmark = pytest.mark.slow

ROOT = Path(__file__).resolve().parents[2]
BAG = ROOT / "sample_bags" / "fbm3w" / "log_fbm3w_mocap_2015-11-20-12-00-00_0.bag"
CONFIG = ROOT / "sample_bags" / "fbm3w" / "fbm3w.yaml"
ERTOOLS = shutil.which("ertools", path=str(Path(sys.executable).parent))
SCORE = ["score", "fbm3w", str(BAG), "--config", str(CONFIG)]
# a loaded 2-core machine: a run takes a few seconds; one that hangs fails the test
TIMEOUT_S = 120

HARNESS = textwrap.dedent(
    """
    import importlib.abc, os, runpy, signal, sys

    class Interrupt(importlib.abc.MetaPathFinder):
        def find_spec(self, name, path=None, target=None):
            if name == WHEN:
                sys.meta_path.remove(self)
                os.kill(os.getpid(), signal.SIGINT)
            return None

    WHEN, kind, target = sys.argv[1:4]
    sys.argv = [target, *sys.argv[4:]]
    sys.meta_path.insert(0, Interrupt())
    if kind == "script":
        runpy.run_path(target, run_name="__main__")
    else:
        sys.argv[0] = "-m"
        runpy.run_module(target, run_name="__main__", alter_sys=True)
    """
)

# (how it is started, what, its arguments, the line it says, modules a Ctrl-C lands in)
PROGRAMS = [
    (
        "script",
        ERTOOLS,
        SCORE,
        "ertools",
        [
            "ertools.cli.main",
            "argparse",
            "ertools.cli.score",
            "numpy",
            "ertools.benchmarks.fbm3w.pipeline",
            "ertools.io.ros1.layout",
            "ertools.benchmarks.fbm3w.formula",
            "yaml",
        ],
    ),
    ("module", "ertools.cli.main", ["info", str(BAG)], "ertools", ["ertools.cli.info", "numpy"]),
    ("module", "ertools", ["info", str(BAG)], "ertools", ["ertools.cli.main", "numpy"]),
    ("module", "ertools.samples", ["--help"], "python -m ertools.samples", ["numpy", "yaml"]),
    (
        "module",
        "ertools.benchmarks.catalogue",
        [],
        "python -m ertools.benchmarks.catalogue",
        ["ertools.benchmarks.fbm1.rules", "ertools.benchmarks.fbm3w.rules"],
    ),
    # the demo's output folder: never reached (interrupted before), in tmp_path all the same
    ("module", "ertools.demo", ["{tmp}"], "python -m ertools.demo", ["ertools.samples"]),
]
CASES = [
    pytest.param(kind, target, args, program, module, id=f"{Path(target).name}-at-{module}")
    for kind, target, args, program, modules in PROGRAMS
    for module in modules
]


@pytest.mark.parametrize(("kind", "target", "args", "program", "module"), CASES)
def test_a_ctrl_c_while_a_module_loads_is_one_line(
    kind: str, target: str, args: list[str], program: str, module: str, tmp_path: Path
) -> None:
    assert target is not None
    args = [a.replace("{tmp}", str(tmp_path / "demo")) for a in args]
    proc = subprocess.run(
        [sys.executable, "-c", HARNESS, module, kind, target, *args],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=TIMEOUT_S,
        check=False,
    )
    assert (proc.returncode, proc.stderr) == (130, f"{program}: interrupted\n")


def loaded(pid: int, library: str) -> bool:
    try:
        return library in Path(f"/proc/{pid}/maps").read_text()
    except OSError:
        return False


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc")
@pytest.mark.parametrize(
    ("library", "after_s"),
    [
        ("_multiarray_umath", 0.0),  # NumPy's core loading
        ("_multiarray_umath", 0.05),
        ("_multiarray_umath", 0.15),
        ("_yaml", 0.0),  # the config read
        ("_generator", 0.0),  # NumPy's random draws: the intervals, well into scoring
    ],
)
def test_a_real_ctrl_c_in_the_first_moments(library: str, after_s: float) -> None:
    """``ertools score`` sent SIGINT once ``library``'s code is mapped, ``after_s`` later: one
    line and 130 (or, where the score finished first, its own exit 0)."""
    assert ERTOOLS is not None
    proc = subprocess.Popen(
        [ERTOOLS, *SCORE],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
        env={**os.environ, "PYTHONDONTWRITEBYTECODE": ""},
    )
    end = time.monotonic() + TIMEOUT_S
    while not loaded(proc.pid, library):
        assert proc.poll() is None, f"{library} was never loaded"
        assert time.monotonic() < end
        time.sleep(0.001)
    time.sleep(after_s)
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=TIMEOUT_S)
    assert "Traceback" not in err
    if proc.returncode != 0:
        assert (proc.returncode, err.splitlines()[-1]) == (130, "ertools: interrupted")


@pytest.fixture(autouse=False)
def sigint_kept() -> Iterator[None]:
    """``launch.run`` sets the SIGINT handler of the process it runs in: pytest's is put back."""
    handler = signal.getsignal(signal.SIGINT)
    yield
    signal.signal(signal.SIGINT, handler)


@pytest.mark.usefixtures("sigint_kept")
def test_an_import_error_made_of_an_interrupt_is_one_line(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    """NumPy's C core, interrupted while it loads, raises an ImportError of its own (with its
    advice on reinstalling) whose context is the KeyboardInterrupt: still one line and 130."""
    (tmp_path / "numpyish.py").write_text(
        "try:\n"
        "    raise KeyboardInterrupt\n"
        "except KeyboardInterrupt as exc:\n"
        "    raise ImportError('IMPORTANT: PLEASE READ THIS FOR ADVICE') from exc\n",
        encoding="utf-8",
    )
    monkeypatch.syspath_prepend(str(tmp_path))
    assert launch.run(lambda: import_module("numpyish"), "ertools") == launch.INTERRUPTED
    assert capsys.readouterr().err == "ertools: interrupted\n"


@pytest.mark.usefixtures("sigint_kept")
def test_an_import_error_of_its_own_is_not_an_interrupt(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    (tmp_path / "broken.py").write_text("raise ImportError('no such thing')\n", encoding="utf-8")
    monkeypatch.syspath_prepend(str(tmp_path))
    with pytest.raises(ImportError, match="no such thing"):
        launch.run(lambda: import_module("broken"), "ertools")


SWALLOWED = textwrap.dedent(
    """
    import signal, sys, time

    class Dropped:
        def __del__(self):
            # the handler runs here, where Python cannot raise: it would print
            # "Exception ignored in" and carry on
            signal.raise_signal(signal.SIGINT)
            time.sleep(0.01)

    def main():
        Dropped()
        end = time.monotonic() + 30
        while time.monotonic() < end:
            pass
        print("finished as if no key had been pressed")
        return 0
    """
)


def test_a_ctrl_c_inside_a_callback_is_delivered_again(tmp_path: Path) -> None:
    """A Ctrl-C that lands in a ``__del__`` or a weakref callback of the import machinery (a
    real one did, in CI) still ends the program with one line and 130: not Python's "Exception
    ignored" traceback followed by a complete run."""
    (tmp_path / "swallowing.py").write_text(SWALLOWED)
    proc = subprocess.run(
        [
            sys.executable,
            "-c",
            "import sys; from ertools import launch; from swallowing import main; "
            "sys.exit(launch.run(main, 'prog'))",
        ],
        cwd=tmp_path,
        env={**os.environ, "PYTHONPATH": str(tmp_path)},
        capture_output=True,
        text=True,
        timeout=TIMEOUT_S,
        check=False,
    )
    assert (proc.returncode, proc.stdout, proc.stderr) == (130, "", "prog: interrupted\n")
