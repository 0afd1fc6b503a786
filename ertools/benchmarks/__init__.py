"""One module per benchmark; each has the same shape: load -> find runs -> score -> result.

``REGISTRY`` maps a benchmark name to the module implementing it (imported lazily), as rosbags
registers its storage plugins.
"""

from __future__ import annotations

REGISTRY: dict[str, str] = {
    "fbm1h": "ertools.benchmarks.fbm1.benchmark",
    "fbm1w": "ertools.benchmarks.fbm1.benchmark",
    "fbm2h": "ertools.benchmarks.fbm2h.benchmark",
    "fbm3w": "ertools.benchmarks.fbm3w.benchmark",
    "trajectory": "ertools.benchmarks.trajectory.benchmark",
    "noise": "ertools.benchmarks.noise.benchmark",
}
