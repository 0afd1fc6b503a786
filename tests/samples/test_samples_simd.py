"""``python -m ertools.samples`` writes the same bytes whatever SIMD code NumPy picks (issue 23,
item 8; issue 36).

NumPy's AVX-512 float64 arctan2, exp... differ from the C library's in the last bit; the
other paths it dispatches to on x86-64 give the C library's values for the functions the
generator calls. The command switches the AVX-512 targets off (``ertools.samples.simd``);
here it runs once as users run it and once with every target this CPU has off (NumPy's
baseline code only), and the bytes must be equal. On a CPU without AVX-512 the first run is
the AVX2 path, unpinned, and the comparison still holds. (The competition's generator is
compared so by ``tests/samples/test_competition.py``.)
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from ertools.samples.scenario import scenarios
from ertools.samples.simd import (
    BLAS_ENV,
    ENV,
    all_targets,
    dispatch,
    pinned_env,
    pinned_targets,
)
from tests.helpers.simd_paths import baseline_env, unpinned_env


def _generate(out: Path, env: dict[str, str]) -> dict[str, bytes]:
    proc = subprocess.run(
        [sys.executable, "-m", "ertools.samples", str(out)],
        env=env,
        capture_output=True,
        text=True,
        check=False,
        timeout=300,
    )
    assert proc.returncode == 0, proc.stderr
    return {str(p.relative_to(out)): p.read_bytes() for p in sorted(out.rglob("*")) if p.is_file()}


@pytest.mark.slow
def test_the_samples_do_not_depend_on_numpys_simd_path(tmp_path: Path) -> None:
    as_run = _generate(tmp_path / "a", unpinned_env())
    baseline = _generate(tmp_path / "b", baseline_env())
    assert as_run.keys() == baseline.keys()
    # each scenario's folder, and the answers some write beside it (the season's)
    tops = {name.split("/")[0].removesuffix(".answers.yaml") for name in as_run}
    assert tops == set(scenarios())
    differ = [name for name in as_run if as_run[name] != baseline[name]]
    assert not differ, f"bytes depend on NumPy's SIMD path: {differ}"


def test_the_targets_switched_off() -> None:
    dispatched = ["X86_V3", "X86_V4", "AVX512_ICL", "AVX512_SPR"]
    have = {"X86_V3": True, "X86_V4": True, "AVX512_ICL": True, "AVX512_SPR": False}
    # the generator: the AVX-512 ones the CPU has
    assert pinned_targets(dispatched, have) == ["X86_V4", "AVX512_ICL"]
    assert pinned_targets(dispatched, {"X86_V3": True}) == []  # an AVX2 CPU: nothing to pin
    assert pinned_targets(["ASIMD", "SVE"], {"ASIMD": True, "SVE": True}) == []
    # make test's second pass: every one the CPU has (not AVX512_SPR: this CPU lacks it)
    assert all_targets(dispatched, have) == ["X86_V3", "X86_V4", "AVX512_ICL"]
    assert all_targets(["ASIMDHP", "SVE"], {"ASIMDHP": True}) == ["ASIMDHP"]


def test_the_command_pins_numpy_and_openblas_once() -> None:
    dispatched = ["X86_V3", "X86_V4", "AVX512_ICL"]
    avx512 = {"AVX2": True, "FMA3": True, "X86_V3": True, "X86_V4": True, "AVX512_ICL": True}
    env = pinned_env({"HOME": "/h"}, dispatched, avx512)
    assert env == {"HOME": "/h", ENV: "X86_V4 AVX512_ICL", BLAS_ENV: "Haswell"}
    # the re-run: NumPy then reports the targets off, the features as they are
    rerun = {**avx512, "X86_V4": False, "AVX512_ICL": False}
    assert pinned_env(env, dispatched, rerun) is None
    # an AVX2 CPU: OpenBLAS's kernels only (those it would pick anyway, by name)
    avx2 = {"AVX2": True, "FMA3": True, "X86_V3": True}
    assert pinned_env({}, dispatched, avx2) == {BLAS_ENV: "Haswell"}
    # an older x86-64 CPU, or not x86-64: nothing it can run to pin
    assert pinned_env({}, dispatched, {"AVX": True}) is None
    assert pinned_env({}, ["ASIMDHP", "SVE"], {"ASIMDHP": True, "SVE": True}) is None
    # what the user set is left as it is
    mine = {ENV: "", BLAS_ENV: "Nehalem"}
    assert pinned_env(mine, dispatched, avx512) is None
    assert pinned_env({BLAS_ENV: "Nehalem"}, dispatched, avx512) == {
        BLAS_ENV: "Nehalem",
        ENV: "X86_V4 AVX512_ICL",
    }


@pytest.mark.slow
def test_the_printed_targets_leave_numpy_its_baseline() -> None:
    """``python -m ertools.samples.simd`` (the Makefile's value of the variable) switches off
    every dispatched target: NumPy, imported with it, reports none of them."""
    env = unpinned_env()
    run = [sys.executable, "-m", "ertools.samples.simd"]
    printed = subprocess.run(run, env=env, capture_output=True, text=True, check=True).stdout
    if ENV not in os.environ:  # else this process's NumPy reports the targets as missing
        assert printed.split() == all_targets(*dispatch())
    probe = (
        "import numpy as np; u = np._core._multiarray_umath; "
        "print(sorted(t for t in u.__cpu_dispatch__ if u.__cpu_features__.get(t)))"
    )
    left = subprocess.run(
        [sys.executable, "-c", probe],
        env={**env, ENV: printed.strip()},
        capture_output=True,
        text=True,
        check=True,
    ).stdout
    assert left.strip() == "[]"
    pinned = subprocess.run([*run, "--pinned"], env=env, capture_output=True, text=True, check=True)
    assert set(pinned.stdout.split()) <= set(printed.split())
