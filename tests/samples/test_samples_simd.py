"""Samples regenerate bit for bit whatever SIMD code NumPy picks (issue 23, item 8).

NumPy's AVX-512 float64 sin/cos/arctan2 differ from the C library's in the last bit; every
other path it dispatches to on x86-64 gives the C library's values. ``python -m
ertools.samples`` switches the AVX-512 targets off (``ertools.samples.simd``); here the
generator runs once as users run it and once with every dispatched target off (NumPy's
baseline code only), and the bytes must be equal.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

from ertools.samples.simd import ENV, _dispatch, pinned_targets


def _generate(out: Path, env: dict[str, str]) -> dict[str, bytes]:
    proc = subprocess.run(
        [sys.executable, "-m", "ertools.samples", str(out), "--only", "fbm1h", "fbm3w"],
        env=env,
        capture_output=True,
        text=True,
        check=False,
        timeout=300,
    )
    assert proc.returncode == 0, proc.stderr
    return {str(p.relative_to(out)): p.read_bytes() for p in sorted(out.rglob("*")) if p.is_file()}


def test_the_samples_do_not_depend_on_numpys_simd_path(tmp_path: Path) -> None:
    env = {k: v for k, v in os.environ.items() if k != ENV}
    as_run = _generate(tmp_path / "a", env)
    dispatched, _ = _dispatch()
    baseline = _generate(tmp_path / "b", {**env, ENV: " ".join(dispatched)})
    assert as_run.keys() == baseline.keys() and len(as_run) >= 4
    differ = [name for name in as_run if as_run[name] != baseline[name]]
    assert not differ, f"bytes depend on NumPy's SIMD path: {differ}"


def test_only_the_avx512_targets_the_cpu_has_are_switched_off() -> None:
    dispatched = ["X86_V3", "X86_V4", "AVX512_ICL", "AVX512_SPR"]
    have = {"X86_V3": True, "X86_V4": True, "AVX512_ICL": True, "AVX512_SPR": False}
    assert pinned_targets(dispatched, have) == ["X86_V4", "AVX512_ICL"]
    assert pinned_targets(dispatched, {"X86_V3": True}) == []  # an AVX2 CPU: nothing to pin
    assert pinned_targets(["ASIMD", "SVE"], {"ASIMD": True, "SVE": True}) == []
