"""NumPy's and OpenBLAS's code paths pinned for the sample generator: ``python -m
ertools.samples`` writes the same bytes on every x86-64 CPU with AVX2.

NumPy chooses some of its functions by instruction set when it is imported. For the float64
functions the generator calls (``arctan2``, ``exp``, ...) its AVX-512 code (the ``X86_V4`` /
``AVX512_*`` targets) differs from the C library's, which every other x86-64 path uses, in
the last bit: the FBM1H sample made on an AVX2 machine had 391 pose2d headings one bit apart
when made on an AVX-512 one (issue 23). OpenBLAS (matrix products, through NumPy and SciPy)
chooses its kernels by CPU when it is loaded: those of AVX-512 CPUs gave the samples' bytes
of the AVX2 (``Haswell``) ones, those of older CPUs (``Sandybridge``, ``Nehalem``) differ in
the last bits of the FBM1H and FBM2H samples. ``python -m ertools.samples`` therefore runs
with NumPy's AVX-512 targets switched off (``NPY_DISABLE_CPU_FEATURES``) and, on a CPU with
AVX2 and FMA, OpenBLAS's Haswell kernels (``OPENBLAS_CORETYPE``): both are read at import, so
the command re-runs itself once with them set. A variable the user set is left as it is.
Pinned is the command only: a ``generate`` or ``write_competition`` call in a process that
imported NumPy unpinned (the tests' own logs, ``make demo``) is not. What still has to match
for identical bytes is the software: Python, NumPy, SciPy, OpenBLAS, rosbags, mcap and the C
library (docs/samples.md).

``python -m ertools.samples.simd`` prints every dispatched target this CPU has, the value of
``NPY_DISABLE_CPU_FEATURES`` that leaves NumPy its baseline code only (``make test``'s second
pass, docs/qa.md); ``--pinned``, the ones the generator switches off.
"""

from __future__ import annotations

import os
import sys
from collections.abc import Sequence

import numpy as np

ENV = "NPY_DISABLE_CPU_FEATURES"
BLAS_ENV = "OPENBLAS_CORETYPE"
# OpenBLAS's kernels for AVX2 and FMA: what an AVX2 CPU picks (AMD's Zen too), and what the
# committed sample_bags/ were made with
BLAS_CORE = "Haswell"


def pinned_targets(dispatched: Sequence[str], available: dict[str, bool]) -> list[str]:
    """The dispatch targets to switch off: x86-64-v4 and the AVX-512 ones the CPU has."""
    return [t for t in dispatched if (t == "X86_V4" or t.startswith("AVX512")) and available.get(t)]


def all_targets(dispatched: Sequence[str], available: dict[str, bool]) -> list[str]:
    """Every dispatch target the CPU has: switched off, NumPy runs its baseline code (the
    baseline itself cannot be: NumPy refuses to import when told to)."""
    return [t for t in dispatched if available.get(t)]


def pinned_blas(available: dict[str, bool]) -> str | None:
    """The OpenBLAS kernels to run on: Haswell's where the CPU has AVX2 and FMA (AVX-512 CPUs
    do), None elsewhere (an older x86-64 CPU cannot run them; not x86-64: other kernels)."""
    return BLAS_CORE if available.get("AVX2") and available.get("FMA3") else None


def pinned_env(
    environ: dict[str, str], dispatched: Sequence[str], available: dict[str, bool]
) -> dict[str, str] | None:
    """The environment the samples are made in, None when ``environ`` is it already.

    ``available``: the CPU's features as NumPy reports them; switching a target off does not
    change them (only the targets' own entries), so a re-run decides as the first run did.
    """
    extra: dict[str, str] = {}
    if ENV not in environ and (targets := pinned_targets(dispatched, available)):
        extra[ENV] = " ".join(targets)
    if BLAS_ENV not in environ and (core := pinned_blas(available)):
        extra[BLAS_ENV] = core
    return {**environ, **extra} if extra else None


def dispatch() -> tuple[list[str], dict[str, bool]]:
    """NumPy's dispatch targets and the CPU's features (``np.show_runtime`` prints the same)."""
    umath = np._core._multiarray_umath  # type: ignore[attr-defined]
    return list(getattr(umath, "__cpu_dispatch__", [])), dict(
        getattr(umath, "__cpu_features__", {})
    )


def rerun_pinned(argv: Sequence[str]) -> None:
    """Re-run ``python -m ertools.samples ARGV`` pinned (:func:`pinned_env`), unless this run
    is (then return: the caller goes on as it is)."""
    env = pinned_env(dict(os.environ), *dispatch())
    if env is None:
        return
    sys.stdout.flush()
    os.execve(sys.executable, [sys.executable, "-m", "ertools.samples", *argv], env)


if __name__ == "__main__":
    if sys.argv[1:] not in ([], ["--pinned"]):
        sys.exit("usage: python -m ertools.samples.simd [--pinned]")
    pick = pinned_targets if sys.argv[1:] else all_targets
    print(" ".join(pick(*dispatch())))
