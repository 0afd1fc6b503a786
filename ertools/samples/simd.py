"""NumPy's instruction-set dispatch pinned for the sample generator: samples regenerate bit for
bit on every x86-64 CPU.

NumPy chooses its float64 ``sin``, ``cos``, ``arctan2``, ``exp``... by instruction set when it is
imported: on an AVX-512 CPU (its x86-64-v4 / AVX512_* targets) it runs its own vectorised code,
elsewhere the C library's. The two agree to an ulp, not bit for bit: the FBM1H sample made on an
AVX2 machine had 391 pose2d headings one bit apart when made on an AVX-512 one (issue 23).
``python -m ertools.samples`` therefore runs with those targets switched off
(``NPY_DISABLE_CPU_FEATURES``, read by NumPy at import: the command re-runs itself once with it
set), so an AVX-512 CPU takes the path every other x86-64 CPU takes. What still has to match
for identical bytes is the software: Python, NumPy, SciPy, rosbags, mcap and the C library
(docs/samples.md).
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


def _dispatch() -> tuple[list[str], dict[str, bool]]:
    # NumPy's own record of what it dispatches to (np.show_runtime prints the same).
    umath = np._core._multiarray_umath  # type: ignore[attr-defined]
    return list(getattr(umath, "__cpu_dispatch__", [])), dict(
        getattr(umath, "__cpu_features__", {})
    )


def rerun_pinned(argv: Sequence[str]) -> None:
    """Re-run ``python -m ertools.samples ARGV`` with the AVX-512 targets off, when this CPU
    has them and they are not already off (then return: the caller goes on as it is)."""
    if ENV in os.environ:
        return
    targets = pinned_targets(*_dispatch())
    if not targets:
        return
    env = {**os.environ, ENV: " ".join(targets)}
    sys.stdout.flush()
    os.execve(sys.executable, [sys.executable, "-m", "ertools.samples", *argv], env)
