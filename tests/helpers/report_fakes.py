"""Results for report tests: a minimal BenchmarkResult with a hostile payload in it."""

from __future__ import annotations

from ertools.streams import Provenance
from tests.helpers.fakes import FakeResult

EVIL = "<script>alert('x')</script>"
EVIL_IMG = '<img src=x onerror="alert(1)">'


def fbm3w_like(best: float = 0.0123, team_param: str | None = None) -> FakeResult:
    params: tuple[tuple[str, str], ...] = (("d_min", "0.00033 m"), ("topic", EVIL_IMG))
    if team_param is not None:
        params += (("team", team_param),)
    return FakeResult(
        "fbm3w",
        {
            "best_distance_error": best,
            "best_run": 1,
            "execution_time": 41.5,
            "runs_details": {"0": {"spec": "line", "distance_error": best + 0.001}},
        },
        table={
            "runs": [
                {"run": 0, "spec": EVIL, "distance_error": best + 0.001, "start_time": 1.4e9},
                {"run": 1, "spec": "spline", "distance_error": best, "start_time": 1.4e9 + 30.5},
            ],
        },
        warnings=(f"warning with {EVIL}",),
        deviations=("ertools estimates the noise", EVIL),
        provenance=Provenance(parameters=params),
    )
