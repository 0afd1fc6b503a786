"""Environments that choose NumPy's code paths for a child process (``ertools.samples.simd``).

The targets are asked of a fresh interpreter without ``NPY_DISABLE_CPU_FEATURES``: this
process's NumPy may have been imported with some switched off (``make test``'s second pass),
and it then reports them as missing.
"""

from __future__ import annotations

import os
import subprocess
import sys

from ertools.samples.simd import BLAS_ENV, ENV


def unpinned_env() -> dict[str, str]:
    """``os.environ`` without ``NPY_DISABLE_CPU_FEATURES`` and ``OPENBLAS_CORETYPE``: as
    users run a command."""
    return {k: v for k, v in os.environ.items() if k not in (ENV, BLAS_ENV)}


def baseline_env() -> dict[str, str]:
    """``os.environ`` with every dispatched target this CPU has switched off: NumPy's
    baseline code only (``python -m ertools.samples.simd`` prints them)."""
    env = unpinned_env()
    targets = subprocess.run(
        [sys.executable, "-m", "ertools.samples.simd"],
        env=env,
        capture_output=True,
        text=True,
        check=True,
        timeout=60,
    ).stdout.strip()
    return {**env, ENV: targets}
