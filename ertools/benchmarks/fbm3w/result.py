"""The FBM3@Work result: per-run details and the score in the layout of seed Listing 16."""

from __future__ import annotations

import math
from dataclasses import field, replace
from typing import Any

from ertools.benchmarks.base import Rows
from ertools.benchmarks.common.epsilon import NoiseResult
from ertools.benchmarks.common.interval_output import ScoreRow, interval_lines
from ertools.benchmarks.common.path_gaps import GapOnPath, gaps_on_path
from ertools.benchmarks.common.uncertainty import (
    Interval,
    Uncertainty,
    split_interval,
    uncertainty_rows,
)
from ertools.benchmarks.common.validity import Validity, cell
from ertools.benchmarks.fbm3w.formula import PathScore
from ertools.benchmarks.fbm3w.runs import RunWindow
from ertools.benchmarks.results import ResultBase
from ertools.fidelity import Deviation
from ertools.frozen_dataclass import frozen_dataclass
from ertools.streams import Provenance
from ertools.timeutil import ns_to_s

# Listing 16 keys of one run, in the listing's order; ertools' extra keys follow them.
RUN_KEYS = ("spec", "distance_error", "execution_time")


@frozen_dataclass(eq=False)
class RunResult:
    """One run: where it was found, and its score or why it has none.

    Attributes:
        window: the run as found (times, status, mode).
        spec: the shape name scored against.
        score: Eq. (1) details, None when not scored.
        error: why the run could not be scored (a failure), None otherwise.
        samples: pose samples in the path window.
        tracking_losses: consecutive identical poses in the window (Motive repeats).
        reference_xy: the reference position (world), None when unknown.
        target_length: arc length of the target shape, metres.
        d_min: the threshold used.
        sweep: (d_min, distance_error or None) for ``--d-min-sweep``.
        bag_start_ns: the bag's first message, for relative times.
        frame_xy: (N, 2) every sample of the window in the run frame (plots).
        shape_floor: distance_error of a noiseless robot exactly on the target.
        target_dense: (M, 2) the target curve, densely sampled (plots).
        sample_t_ns: (N,) times of the samples of ``frame_xy`` (the Foxglove export).
        validity: the path window's validity mask summary (None when not computed).
        unscoreable_reason: why the valid data cannot support a score (then ``score`` is None
            and the status ``unscoreable``; under ``--unscoreable 2015`` the run is scored
            and this is kept for the warning), None otherwise.
        path_coverage: the fraction of the path window covered by valid data (a tracking loss
            that hid no motion counted as covered), None when not computed.
        interval: the confidence interval of ``distance_error`` (None: not scored, or
            ``--draws 0``).
    """

    window: RunWindow
    spec: str
    score: PathScore | None
    error: str | None
    samples: int
    tracking_losses: int
    reference_xy: tuple[float, float] | None
    target_length: float | None
    d_min: float
    sweep: tuple[tuple[float, float | None], ...] = ()
    bag_start_ns: int = 0
    frame_xy: Any = None
    shape_floor: float | None = None
    target_dense: Any = None
    sample_t_ns: Any = None
    validity: Validity | None = None
    unscoreable_reason: str | None = None
    path_coverage: float | None = None
    interval: Interval | None = None

    @property
    def index(self) -> int:
        return self.window.index

    @property
    def gaps(self) -> tuple[GapOnPath, ...]:
        """The path window's invalid spans (seconds from the bag start) with their (x, y) ends
        in the run frame of ``frame_xy``: what the path plot draws as gaps."""
        if self.validity is None:
            return ()
        return gaps_on_path(self.validity, self.frame_xy, self.bag_start_ns)

    @property
    def status(self) -> str:
        if self.error is not None:
            return "failed"
        if self.score is None and self.unscoreable_reason is not None:
            return "unscoreable"
        if self.score is not None:
            # --timeout-runs 2015 scores a timed-out run on its partial path: say so.
            return "timeout_scored" if self.window.status == "timeout" else "scored"
        return self.window.status

    @property
    def distance_error(self) -> float | None:
        return None if self.score is None else self.score.distance_error

    @property
    def execution_time(self) -> float | None:
        return self.window.execution_time_s

    def _rel(self, t_ns: int | None) -> float | None:
        return None if t_ns is None else round((t_ns - self.bag_start_ns) / 1e9, 6)

    def details(self) -> dict[str, Any]:
        """Listing 16 keys, then ertools' extras."""
        out: dict[str, Any] = {
            "spec": self.spec,
            "distance_error": self.distance_error,
            "execution_time": self.execution_time,
        }
        if self.interval is not None:
            out["distance_error_interval"] = self.interval.as_list()
        out["status"] = self.status
        if self.error is not None:
            out["error"] = self.error
        out["d_min"] = self.d_min
        out["samples"] = self.samples
        if self.score is not None:
            out["kept_samples"] = len(self.score.kept)
            out["path_length"] = self.score.path_length
            out["raw_path_length"] = self.score.raw_length
        if self.target_length is not None:
            out["target_length"] = self.target_length
        if self.shape_floor is not None:
            out["shape_floor"] = self.shape_floor
        out["tracking_losses"] = self.tracking_losses
        out["run_finding"] = self.window.mode
        out["reference_time"] = self._rel(self.window.ref_ns)
        out["start_time"] = self._rel(self.window.start_ns)
        out["end_time"] = self._rel(self.window.end_ns)
        if self.reference_xy is not None:
            out["reference_position"] = [self.reference_xy[0], self.reference_xy[1]]
        if self.score is not None:
            o = self.score.frame.origin
            out["starting_position"] = [o[0], o[1]]
            out["frame_yaw"] = self.score.frame.yaw
        if self.validity is not None:
            out.update(self.validity.fields())
        if self.path_coverage is not None:
            out["path_coverage"] = round(self.path_coverage, 6)
        if self.unscoreable_reason is not None:
            out["unscoreable_reason"] = self.unscoreable_reason
        return out


@frozen_dataclass(eq=False)
class Fbm3wResult(ResultBase):
    """Implements :class:`ertools.benchmarks.base.BenchmarkResult` for FBM3@Work."""

    runs: tuple[RunResult, ...]
    d_min: float
    noise: NoiseResult | None = None
    sweep_values: tuple[float, ...] = ()
    name: str = "fbm3w"
    warnings: tuple[str, ...] = ()
    deviations: tuple[Deviation, ...] = ()
    failures: tuple[str, ...] = ()
    provenance: Provenance = field(default_factory=Provenance)
    count_stopped: bool = True
    best_interval: Interval | None = None
    uncertainty: Uncertainty | None = None

    @property
    def nothing_scored(self) -> bool:
        """Every run failed (none scored, timed out, stopped or interrupted): the CLI prints
        only the failures (``ertools.benchmarks.document.all_failed``)."""
        return all(r.status == "failed" for r in self.runs)

    @property
    def best_run(self) -> int | None:
        """The scored run with the smallest distance_error (the first on ties, as 2015)."""
        best: RunResult | None = None
        for run in self.runs:
            err = run.distance_error
            if err is not None and (best is None or err < (best.distance_error or math.inf)):
                best = run
        return None if best is None else best.index

    @property
    def best_distance_error(self) -> float | None:
        best = self.best_run
        run = None if best is None else self._by_index(best)
        return None if run is None else run.distance_error

    def validity_lines(self) -> list[str]:
        """One stderr line per run with a validity mask: its valid fraction, the invalid samples
        and the longest gap, and the verdict when unscoreable."""
        out = []
        for r in self.runs:
            if r.validity is None:
                continue
            line = "validity: " + r.validity.text(f"run {r.index}", r.bag_start_ns)
            if r.status == "unscoreable":
                line += f"; unscoreable: {r.unscoreable_reason}"
            out.append(line)
        return out

    @property
    def unscoreable_reason(self) -> str | None:
        """Why the execution has no score when no run was scored and some were unscoreable
        (the rescore's ``unscoreable`` status), None otherwise."""
        if self.best_run is not None:
            return None
        bad = [r for r in self.runs if r.status == "unscoreable"]
        if not bad:
            return None
        return "no run can be scored: " + "; ".join(
            f"run {r.index}: {r.unscoreable_reason}" for r in bad
        )

    def _by_index(self, index: int) -> RunResult | None:
        return next((r for r in self.runs if r.index == index), None)

    @property
    def execution_time(self) -> float:
        """Sum of the run times, timed-out runs included (as the 2015 node added them).

        Stopped runs are included unless ``count_stopped`` is False (``--stopped-runs 2015``:
        the 2015 node skipped them before adding the time).
        """
        # Summed in int64 ns: a sum of float seconds prints binary noise (24.549999999999997).
        w = [r.window for r in self.runs if self.count_stopped or r.window.status != "stopped"]
        return ns_to_s(
            sum(x.end_ns - x.start_ns for x in w if x.start_ns is not None and x.end_ns is not None)
        )

    def listing(self) -> dict[Any, Any]:
        """Listing 16: best_distance_error, best_run, execution_time, runs_details {i: ...}."""
        out: dict[str, Any] = {
            "best_distance_error": self.best_distance_error,
            "best_run": self.best_run,
            "execution_time": self.execution_time,
            "runs_details": {r.index: r.details() for r in self.runs},
        }
        # Listing 16's keys first, in its order; the intervals are extra keys after them.
        if self.uncertainty is not None:
            best = self.best_interval
            out["best_distance_error_interval"] = None if best is None else best.as_list()
            out["uncertainty"] = self.uncertainty.to_dict()
        return out

    def interval_lines(self) -> list[str]:
        """The stderr lines of the intervals (:func:`interval_lines`): the best run's, each
        run's, then the sources."""
        rows = [ScoreRow("best_distance_error", self.best_distance_error, self.best_interval)]
        rows += [
            ScoreRow(
                f"run {r.index} distance_error",
                r.distance_error,
                r.interval,
                key=f"runs_details.{r.index}.distance_error",
            )
            for r in self.runs
        ]
        return interval_lines([replace(r, scale=1000.0, unit="mm") for r in rows], self.uncertainty)

    def tables(self) -> dict[str, Rows]:
        runs: Rows = []
        for r in self.runs:
            row = {"run": r.index, **r.details()}
            split_interval(row, "distance_error")
            for key in ("reference_position", "starting_position"):
                if key in row:
                    row[key] = " ".join(f"{v:.6f}" for v in row[key])
            if "invalid_samples" in row:
                row["invalid_samples"] = cell(row["invalid_samples"])
            runs.append(row)
        points: Rows = []
        for r in self.runs:
            s = r.score
            if s is None:
                continue
            for i in range(len(s.kept)):
                points.append(
                    {
                        "run": r.index,
                        "i": i,
                        "sample": int(s.kept[i]),
                        "x": float(s.kept_frame[i, 0]),
                        "y": float(s.kept_frame[i, 1]),
                        "l_norm": float(s.l_norm[i]),
                        "target_x": float(s.target[i, 0]),
                        "target_y": float(s.target[i, 1]),
                        "error": float(s.errors[i]),
                    }
                )
        out: dict[str, Rows] = {"runs": runs, "points": points}
        spans = [
            {
                "run": r.index,
                **s.to_dict(r.bag_start_ns),
                "start_x": None if g.start_xy is None else g.start_xy[0],
                "start_y": None if g.start_xy is None else g.start_xy[1],
                "end_x": None if g.end_xy is None else g.end_xy[0],
                "end_y": None if g.end_xy is None else g.end_xy[1],
            }
            for r in self.runs
            if r.validity is not None
            for s, g in zip(r.validity.spans, r.gaps, strict=True)
        ]
        if spans:
            out["invalid_spans"] = spans
        if self.sweep_values:
            out["d_min_sweep"] = [
                {"d_min": d, **{f"run_{r.index}": e for r, (_, e) in _sweep_cells(self.runs, k)}}
                for k, d in enumerate(self.sweep_values)
            ]
        if self.noise is not None:
            out["noise"] = self.noise.tables()["summary"]
        if self.uncertainty is not None:
            out["uncertainty"] = uncertainty_rows(self.uncertainty)
        return out

    def sweep_text(self) -> str:
        """The d_min sweep as a table in millimetres (for the terminal)."""
        if not self.sweep_values:
            return ""
        head = "d_min [mm]  " + "".join(f"run {r.index:<6d}" for r in self.runs)
        lines = [head]
        for k, d in enumerate(self.sweep_values):
            cells = []
            for _, (_, e) in _sweep_cells(self.runs, k):
                cells.append(f"{e * 1000:<10.3f}" if e is not None else f"{'-':<10}")
            lines.append(f"{d * 1000:<10.4f}  " + "".join(cells))
        return "\n".join(lines) + "\n(distance_error in mm)\n"


def _sweep_cells(
    runs: tuple[RunResult, ...], k: int
) -> list[tuple[RunResult, tuple[float, float | None]]]:
    return [(r, r.sweep[k] if k < len(r.sweep) else (math.nan, None)) for r in runs]
