"""The package as a user installs it: a wheel built from the tree, into a fresh Python."""

from __future__ import annotations

import re
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

pytestmark = pytest.mark.slow

ROOT = Path(__file__).resolve().parents[2]


def _run(*argv: str | Path, cwd: Path) -> str:
    proc = subprocess.run(
        [str(a) for a in argv], cwd=cwd, capture_output=True, text=True, timeout=300, check=False
    )
    assert proc.returncode == 0, proc.stderr[-2000:]
    return proc.stdout


def test_wheel_installs_on_a_fresh_python_and_answers_version(tmp_path: Path) -> None:
    build = subprocess.run(
        [sys.executable, "-m", "pip", "wheel", "--no-deps", "-q", "-w", str(tmp_path / "dist"),
         str(ROOT)],
        cwd=tmp_path, capture_output=True, text=True, timeout=300, check=False,
    )  # fmt: skip
    assert build.returncode == 0, build.stderr[-2000:]
    # `make demo` and `make test` install the same way: no packaging deprecation on the way
    # (project.license as an SPDX string, not the table form setuptools deprecated)
    assert "deprecat" not in build.stderr.lower(), build.stderr[-2000:]
    (wheel,) = (tmp_path / "dist").glob("ertools-*.whl")
    names = zipfile.ZipFile(wheel).namelist()
    # Typed for users' mypy; the simulator travels (``python -m ertools.samples``), tests do not.
    assert "ertools/py.typed" in names
    assert "ertools/samples/__main__.py" in names
    assert not any(n.startswith(("tests/", "sample_bags/", "bench")) for n in names)
    # The report pages are rendered from templates: every one of the tree's is package data,
    # and Jinja2 is a declared dependency.
    templates = sorted(
        p.relative_to(ROOT).as_posix() for p in (ROOT / "ertools/report/templates").glob("*.j2")
    )
    assert "ertools/report/templates/report.html.j2" in templates
    assert sorted(n for n in names if n.startswith("ertools/report/templates/")) == templates
    with zipfile.ZipFile(wheel) as zf:
        (meta,) = [n for n in zf.namelist() if n.endswith(".dist-info/METADATA")]
        requires = [
            line
            for line in zf.read(meta).decode().splitlines()
            if line.startswith("Requires-Dist:")
        ]
    assert any(line.split()[1].lower().startswith("jinja2") for line in requires), requires
    # A Python that never saw the source tree; --no-deps: `--version` needs no dependency
    # (the CLI imports NumPy and the readers only for the command it runs).
    _run(sys.executable, "-m", "venv", "--without-pip", tmp_path / "fresh", cwd=tmp_path)
    bin_dir = tmp_path / "fresh" / "bin"
    _run(
        sys.executable, "-m", "pip", "--python", bin_dir / "python", "install", "-q",
        "--no-deps", wheel, cwd=tmp_path,
    )  # fmt: skip
    version = _run(bin_dir / "ertools", "--version", cwd=tmp_path)
    expected = _run(sys.executable, "-m", "ertools.cli.main", "--version", cwd=ROOT)
    assert version.strip() == expected.strip() != ""


def test_the_makefiles_editable_install_shows_no_packaging_warning(tmp_path: Path) -> None:
    """`make demo`'s first lines: the editable install as the Makefile runs it (its pip flags)
    into a fresh Python prints no warning box (setuptools' notice on every editable install,
    which pip 25+ passes on; a deprecated pyproject form)."""
    makefile = (ROOT / "Makefile").read_text(encoding="utf-8")
    (flags,) = re.findall(r"^PIP := \$\(BIN\)/python -m pip install (.*)$", makefile, re.M)
    assert "$(PIP) -e .\n" in makefile
    _run(sys.executable, "-m", "venv", "--without-pip", tmp_path / "fresh", cwd=tmp_path)
    proc = subprocess.run(
        [sys.executable, "-m", "pip", "--python", str(tmp_path / "fresh" / "bin" / "python"),
         "install", *flags.split(), "--no-deps", "-e", str(ROOT)],
        cwd=tmp_path, capture_output=True, text=True, timeout=300, check=False,
    )  # fmt: skip
    assert proc.returncode == 0, proc.stderr[-2000:]
    shown = (proc.stdout + proc.stderr).lower()
    assert "warning" not in shown and "deprecat" not in shown, shown[-2000:]
