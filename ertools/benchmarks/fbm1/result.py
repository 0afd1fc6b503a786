"""The frozen FBM1 result: per-run details, the 2015 totals, and their YAML/JSON/CSV forms."""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import field
from typing import Any

from ertools.benchmarks.base import Rows
from ertools.benchmarks.common.interval_output import (
    ScoreRow,
    as_list,
    interval_lines,
    interval_tables,
    low_high,
)
from ertools.benchmarks.common.uncertainty import Interval, Uncertainty, interval_keys
from ertools.benchmarks.common.validity import Validity, cell
from ertools.benchmarks.fbm1.answers import Answer
from ertools.benchmarks.fbm1.formula import PoseErrors, Totals
from ertools.benchmarks.fbm1.gt import GroundTruth
from ertools.benchmarks.results import ResultBase
from ertools.configs.items import Item
from ertools.fidelity import Deviation
from ertools.frozen_dataclass import frozen_dataclass
from ertools.streams import Provenance
from ertools.timeutil import NS_PER_S, ns_to_s


@frozen_dataclass
class Fbm1RunResult:
    """One run: what was shown, what the robot said, the ground truth and the score.

    Attributes:
        index: 1-based run number.
        status: ``scored``, ``no_answer`` (timeout/stop, or the log ends after the goal:
            counted with score 0), ``aborted`` (the goal was never sent: not counted),
            ``unfinished`` (the BmBox states leave a run open although the log goes on past it:
            not counted), ``unscoreable`` (no valid mocap sample for its ground truth: not
            counted, see unscoreable_reason) or ``failed`` (cannot be scored: see error).
        item: the presented item, None when unknown.
        item_text: the text that named it (payload or ``--items-order``).
        answer: the robot's answer, None without one.
        gt: the measured ground truth, None when not measured.
        errors: the pose errors and pose score, None unless scored.
        class_ok: class right (False for a run without answer), None when not counted.
        instance_ok: instance right, likewise.
        execution_time_ns: goal acknowledged -> result, int64 ns (totals are summed in ns,
            so 0.572 + 0.787 s prints as 1.359, not 1.3590000000000002); None when unknown.
        goal_ns: the goal was sent.
        result_ns: the BmBox stopped waiting for the result.
        ended_by: ``timeout``/``stop`` when the RefBox ended the run.
        error: why the run failed.
        warnings: things to check in this run.
        validity: both bodies' samples in the ground truth's window (None when not measured).
        unscoreable_reason: why the ground truth is no measurement (status ``unscoreable``;
            scored with ``--unscoreable 2015`` / ``--rules 2015``, the reason kept).
    """

    index: int
    status: str
    item: Item | None = None
    item_text: str = ""
    answer: Answer | None = None
    gt: GroundTruth | None = None
    errors: PoseErrors | None = None
    class_ok: bool | None = None
    instance_ok: bool | None = None
    execution_time_ns: int | None = None
    goal_ns: int | None = None
    result_ns: int | None = None
    ended_by: str | None = None
    error: str | None = None
    warnings: tuple[str, ...] = ()
    validity: Validity | None = field(default=None, compare=False)
    unscoreable_reason: str | None = None

    @property
    def execution_time_s(self) -> float | None:
        """The execution time in seconds (None when unknown)."""
        return None if self.execution_time_ns is None else ns_to_s(self.execution_time_ns)

    @property
    def pose_score(self) -> float | None:
        """The run's pose score: 0 for a counted run without answer."""
        if self.errors is not None:
            return self.errors.pose_score
        return 0.0 if self.status == "no_answer" else None

    def to_dict(self, t0_ns: int) -> dict[str, Any]:
        """The run's entry in the score YAML (angles in degrees, times from the log start)."""
        out: dict[str, Any] = {"status": self.status}
        if self.item is not None:
            out["item"] = {
                "id": self.item.id,
                "class": self.item.item_class,
                "instance": self.item.instance,
            }
        elif self.item_text:
            out["item"] = {"named": self.item_text}
        if self.answer is not None:
            a = self.answer
            out["answer"] = {
                "item_class": a.item_class,
                "item_instance": a.item_instance,
                "x": a.x,
                "y": a.y,
                "theta": a.theta_deg,
            }
        if self.gt is not None:
            g = self.gt
            out["ground_truth"] = {
                "x": g.x,
                "y": g.y,
                "theta": g.yaw_deg,
                "z": g.z,
                "method": g.method,
                "samples": g.samples,
                "spread_m": g.position_spread_m,
                "spread_deg": g.angle_spread_deg,
                "window_s": [(g.start_ns - t0_ns) / NS_PER_S, (g.end_ns - t0_ns) / NS_PER_S],
            }
            if g.moment:
                out["ground_truth"]["moment_from"] = g.moment
        if self.errors is not None:
            e = self.errors
            out["error"] = {
                "x": e.dx,
                "y": e.dy,
                "translation": e.trans_error_m,
                "theta": e.theta_error_deg,
            }
        if self.class_ok is not None:
            out["class_correct"] = self.class_ok
            out["instance_correct"] = self.instance_ok
        if self.pose_score is not None:
            out["pose_score"] = self.pose_score
        if self.execution_time_s is not None:
            out["execution_time"] = self.execution_time_s
        if self.goal_ns is not None:
            out["goal_s"] = (self.goal_ns - t0_ns) / NS_PER_S
        if self.result_ns is not None:
            out["result_s"] = (self.result_ns - t0_ns) / NS_PER_S
        if self.ended_by:
            out["ended_by"] = self.ended_by
        if self.error:
            out["failure"] = self.error
        if self.warnings:
            out["warnings"] = list(self.warnings)
        if self.validity is not None:
            out.update(self.validity.fields())
        if self.unscoreable_reason is not None:
            out["unscoreable_reason"] = self.unscoreable_reason
        return out

    def row(self, t0_ns: int) -> dict[str, Any]:
        """A flat CSV/terminal row."""
        nan = math.nan
        a, g, e, it = self.answer, self.gt, self.errors, self.item
        return {
            "run": self.index,
            "status": self.status,
            "item_id": it.id if it else None,
            "class": it.item_class if it else None,
            "instance": it.instance if it else None,
            "answer_class": a.item_class if a else None,
            "answer_instance": a.item_instance if a else None,
            "class_correct": self.class_ok,
            "instance_correct": self.instance_ok,
            "x": a.x if a else nan,
            "y": a.y if a else nan,
            "theta_deg": a.theta_deg if a else nan,
            "gt_x": g.x if g else nan,
            "gt_y": g.y if g else nan,
            "gt_theta_deg": g.yaw_deg if g else nan,
            "gt_samples": g.samples if g else 0,
            "gt_spread_mm": g.position_spread_m * 1000.0 if g else nan,
            "gt_spread_deg": g.angle_spread_deg if g else nan,
            "dx": e.dx if e else nan,
            "dy": e.dy if e else nan,
            "trans_error_m": e.trans_error_m if e else nan,
            "theta_error_deg": e.theta_error_deg if e else nan,
            "pose_score": self.pose_score if self.pose_score is not None else nan,
            "execution_time_s": self.execution_time_s if self.execution_time_s is not None else nan,
            "goal_s": (self.goal_ns - t0_ns) / NS_PER_S if self.goal_ns is not None else nan,
            "error": self.error or "",
            "valid_fraction": nan
            if self.validity is None
            else self.validity.fields()["valid_fraction"],
            "invalid_samples": "" if self.validity is None else cell(self.validity.invalid_samples),
            "unscoreable_reason": self.unscoreable_reason or "",
        }


@frozen_dataclass
class Fbm1Result(ResultBase):
    """An FBM1@Home or FBM1@Work score (implements ``BenchmarkResult``; ``to_dict``,
    ``to_yaml``, ``to_frames`` from :class:`~ertools.benchmarks.results.ResultBase`).

    Attributes:
        name: ``fbm1h`` or ``fbm1w``.
        runs: every run found, in order.
        totals: the 2015 score's four numbers.
        logged_score: the score the 2015 node sent (BmBox TRANSMITTING_SCORE), if logged.
        t0_ns: the log's start; times in the output are seconds from it.
        warnings: things a referee should check.
        deviations: where ertools deliberately differs from the 2015 node.
        failures: runs that could not be scored (one line each, naming the run).
        provenance: inputs and parameters.
        reference: which reference the rules reproduce (ertools, the 2015 node, the 2016-17
            node).
        intervals: the confidence interval of each ground-truth-derived number, by dotted key
            (``pose_score``, ``runs.3.error.translation``...; :mod:`ertools.benchmarks.fbm1.
            intervals`); empty with ``--draws 0``.
        uncertainty: how the intervals were obtained (None without intervals).
    """

    name: str
    runs: tuple[Fbm1RunResult, ...]
    totals: Totals
    logged_score: dict[str, Any] | None = None
    t0_ns: int = 0
    warnings: tuple[str, ...] = ()
    deviations: tuple[Deviation, ...] = ()
    failures: tuple[str, ...] = ()
    provenance: Provenance = field(default_factory=Provenance)
    reference: str = "ertools default"
    intervals: Mapping[str, Interval | None] = field(default_factory=dict)
    uncertainty: Uncertainty | None = None

    @property
    def nothing_scored(self) -> bool:
        """No run counted (scored, or without answer with score 0): no total is a number, so
        the CLI prints only the failures (``ertools.benchmarks.document.all_failed``)."""
        return not any(r.status in ("scored", "no_answer") for r in self.runs)

    def validity_lines(self) -> list[str]:
        """The stderr lines: one per run whose ground truth's window holds invalid samples or
        none valid, else one line saying all were valid."""
        measured = [r for r in self.runs if r.validity is not None]
        out = []
        for r in measured:
            assert r.validity is not None
            if not r.validity.invalid_samples and r.unscoreable_reason is None:
                continue
            line = "validity: " + r.validity.text(f"run {r.index} ground truth", self.t0_ns)
            if r.unscoreable_reason is not None:
                verdict = "unscoreable" if r.status == "unscoreable" else "scored as 2015 did"
                line += f"; {verdict}: {r.unscoreable_reason}"
            out.append(line)
        if measured and not out:
            first, last = measured[0].index, measured[-1].index
            out.append(f"validity: ground truth of runs {first}-{last} 100.0% valid")
        return out

    def score(self) -> dict[str, Any]:
        """The four keys of the 2015 score payload, in the order ``yaml.dump`` sorted them."""
        t = self.totals
        return {
            "class_accuracy": t.class_accuracy,
            "execution_time": t.execution_time,
            "instance_accuracy": t.instance_accuracy,
            "pose_score": t.pose_score,
        }

    def listing(self) -> dict[Any, Any]:
        """The 2015 score (its four keys, as the node sent them) then the details."""
        out: dict[str, Any] = {**self.score()}
        if self.intervals:
            # after the four keys of the 2015 listing, which keep their order
            out["pose_score_interval"] = as_list(self.intervals.get("pose_score"))
        out["benchmark"] = self.name
        out["reference"] = self.reference
        out["counted_runs"] = {
            "accuracy": self.totals.accuracy_runs,
            "pose": self.totals.pose_runs,
        }
        out["runs"] = {
            str(r.index): _with_intervals(r.to_dict(self.t0_ns), r.index, self.intervals)
            for r in self.runs
        }
        if self.logged_score is not None:
            out["logged_2015_score"] = self.logged_score
        for key in ("warnings", "deviations", "failures"):
            values = getattr(self, key)
            if values:
                out[key] = list(values)
        if self.uncertainty is not None:
            out["uncertainty"] = self.uncertainty.to_dict()
        return out

    def tables(self) -> dict[str, Rows]:
        rows = []
        for r in self.runs:
            row = r.row(self.t0_ns)
            if self.intervals:
                for column, key in CSV_INTERVALS:
                    row.update(low_high(column, self.intervals.get(f"runs.{r.index}.{key}")))
            rows.append(row)
        return {"runs": rows, **interval_tables(self.intervals, self.uncertainty)}


# CSV column prefix -> dotted key under ``runs.<index>.`` of the run's interval.
CSV_INTERVALS = (
    ("gt_x", "ground_truth.x"),
    ("gt_y", "ground_truth.y"),
    ("gt_theta_deg", "ground_truth.theta"),
    ("trans_error_m", "error.translation"),
    ("theta_error_deg", "error.theta"),
    ("pose_score", "pose_score"),
)


def _with_intervals(
    entry: dict[str, Any], index: int, intervals: Mapping[str, Interval | None]
) -> dict[str, Any]:
    """A run's YAML entry with ``K_interval`` beside each key that has an interval."""
    prefix = f"runs.{index}."
    mine = {k[len(prefix) :]: v for k, v in intervals.items() if k.startswith(prefix)}
    if not mine:
        return entry
    for section in ("ground_truth", "error"):
        sub = {k.split(".", 1)[1]: v for k, v in mine.items() if k.startswith(section + ".")}
        if sub and isinstance(entry.get(section), dict):
            entry[section] = interval_keys(entry[section], sub)
    return interval_keys(entry, {k: v for k, v in mine.items() if "." not in k})


def _fmt(value: object, spec: str) -> str:
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return "-"
    if isinstance(value, bool):
        return "yes" if value else "no"
    return format(value, spec)


def notes(result: Fbm1Result) -> list[str]:
    """The reference reproduced and the per-run table (stdout keeps the parseable score)."""
    out = [f"reproducing: {result.reference}", f"{result.name}: {len(result.runs)} run(s)"]
    out.append(
        f"{'run':>3} {'item':<14} {'answer':<14} {'cls':>3} {'ins':>3} "
        f"{'dx mm':>7} {'dy mm':>7} {'dth deg':>8} {'pose':>6} {'time s':>7}  status"
    )
    for r in result.runs:
        e = r.errors
        item = f"{r.item.id}:{r.item.instance}" if r.item else (r.item_text or "?")
        ans = r.answer.item_instance if r.answer else "-"
        out.append(
            f"{r.index:>3} {item[:14]:<14} {ans[:14]:<14} {_fmt(r.class_ok, ''):>3} "
            f"{_fmt(r.instance_ok, ''):>3} {_fmt(e.dx * 1000 if e else None, '7.1f'):>7} "
            f"{_fmt(e.dy * 1000 if e else None, '7.1f'):>7} "
            f"{_fmt(e.theta_error_deg if e else None, '8.2f'):>8} "
            f"{_fmt(r.pose_score, '6.3f'):>6} {_fmt(r.execution_time_s, '7.2f'):>7}  {r.status}"
        )
    t = result.totals
    out.append(
        f"class_accuracy {_fmt(t.class_accuracy, '.3f')}  instance_accuracy "
        f"{_fmt(t.instance_accuracy, '.3f')}  pose_score {_fmt(t.pose_score, '.4f')}  "
        f"execution_time {t.execution_time:.2f} s"
    )
    if result.logged_score:
        logged = ", ".join(f"{k} {v}" for k, v in result.logged_score.items())
        out.append(f"the 2015 node sent: {logged}")
    out += interval_lines(
        [ScoreRow("pose_score", t.pose_score, result.intervals.get("pose_score"))],
        result.uncertainty,
    )
    if result.uncertainty is not None:
        out.append(
            "interval: class_accuracy, instance_accuracy and execution_time are counts and "
            "state times: no mocap noise enters them (no interval)"
        )
    return out
