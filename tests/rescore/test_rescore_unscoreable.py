"""An execution whose valid data cannot support a score (issue 28) is listed by the rescore as
``unscoreable`` with its reason, its score document kept: a verdict on the data, not a failure
of the tool."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from ertools.competition.jobs import Job, run_job
from tests.rescore.rescore_toy import Toy, ToyOptions, ToyResult

REASON = "valid data covers only 61.0% of the window (12 tracking_lost); at least 90% is needed"


@dataclass(frozen=True)
class ThinResult(ToyResult):
    unscoreable_reason: str | None = None


def _score_thin(loaded: list[float], runs: list[float], options: ToyOptions) -> ThinResult:
    mean = sum(runs) / len(runs)
    # a log whose first number is negative stands for one whose valid data is too thin
    reason = REASON if runs[0] < 0 else None
    return ThinResult("thin", mean, len(runs), 0.0, unscoreable_reason=reason)


class Thin(Toy):
    """The toy whose scorer says when its data is too thin."""

    name = "thin"

    def score_runs(self, loaded: list[float], runs: list[float], options: ToyOptions) -> ThinResult:
        return _score_thin(loaded, runs, options)


THIN = Thin()


def _job(tmp_path: Path, numbers: str) -> Job:
    log = tmp_path / "thin.txt"
    log.write_text(numbers, encoding="utf-8")
    return Job("thin-1", "thin", "tests.rescore.test_rescore_unscoreable:THIN", "team", (str(log),))


def test_an_unscoreable_execution_is_a_verdict(tmp_path: Path) -> None:
    outcome = run_job(_job(tmp_path, "-1\n2\n"))
    assert outcome.status == "unscoreable"
    assert outcome.reason == REASON
    assert outcome.score == {"toy": {"value": 0.5, "count": 2, "offset": 0.0}}
    assert outcome.error is None


def test_a_scoreable_execution_is_scored(tmp_path: Path) -> None:
    outcome = run_job(_job(tmp_path, "1\n2\n"))
    assert outcome.status == "scored" and outcome.reason is None
