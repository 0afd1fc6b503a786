"""NumPy's instruction-set dispatch pinned for the sample generator: ``python -m
ertools.samples`` writes the same bytes on every x86-64 CPU.

NumPy chooses some of its functions by instruction set when it is imported. For the float64
functions the generator calls (``arctan2``, ``exp``, ...) its AVX-512 code (the ``X86_V4`` /
``AVX512_*`` targets) differs from the C library's, which every other x86-64 path uses, in
the last bit: the FBM1H sample made on an AVX2 machine had 391 pose2d headings one bit apart
when made on an AVX-512 one (issue 23). ``python -m ertools.samples`` therefore runs with
those targets switched off (``NPY_DISABLE_CPU_FEATURES``, read by NumPy at import: the
command re-runs itself once with it set), so an AVX-512 CPU takes the path every other x86-64
CPU takes. Pinned is the command only: a ``generate`` or ``write_competition`` call in a
process that imported NumPy unpinned (the tests' own logs, ``make demo``) is not. What still
has to match for identical bytes is the software: Python, NumPy, SciPy, rosbags, mcap and the
C library (docs/samples.md).

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


def pinned_targets(dispatched: Sequence[str], available: dict[str, bool]) -> list[str]:
    """The dispatch targets to switch off: x86-64-v4 and the AVX-512 ones the CPU has."""
    return [t for t in dispatched if (t == "X86_V4" or t.startswith("AVX512")) and available.get(t)]


def all_targets(dispatched: Sequence[str], available: dict[str, bool]) -> list[str]:
    """Every dispatch target the CPU has: switched off, NumPy runs its baseline code (the
    baseline itself cannot be: NumPy refuses to import when told to)."""
    return [t for t in dispatched if available.get(t)]


def dispatch() -> tuple[list[str], dict[str, bool]]:
    """NumPy's dispatch targets and the CPU's features (``np.show_runtime`` prints the same)."""
    umath = np._core._multiarray_umath  # type: ignore[attr-defined]
    return list(getattr(umath, "__cpu_dispatch__", [])), dict(
        getattr(umath, "__cpu_features__", {})
    )


def rerun_pinned(argv: Sequence[str]) -> None:
    """Re-run ``python -m ertools.samples ARGV`` with the AVX-512 targets off, when this CPU
    has them and they are not already off (then return: the caller goes on as it is)."""
    if ENV in os.environ:
        return
    targets = pinned_targets(*dispatch())
    if not targets:
        return
    env = {**os.environ, ENV: " ".join(targets)}
    sys.stdout.flush()
    os.execve(sys.executable, [sys.executable, "-m", "ertools.samples", *argv], env)


if __name__ == "__main__":
    if sys.argv[1:] not in ([], ["--pinned"]):
        sys.exit("usage: python -m ertools.samples.simd [--pinned]")
    pick = pinned_targets if sys.argv[1:] else all_targets
    print(" ".join(pick(*dispatch())))
