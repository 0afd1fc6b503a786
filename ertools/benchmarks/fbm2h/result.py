"""The FBM2@Home result: per-segment details and the Listing 13 score."""

from __future__ import annotations

import math
from dataclasses import field
from typing import Any

import numpy as np
import numpy.typing as npt
import yaml

from ertools.benchmarks.base import Rows
from ertools.benchmarks.common.interval_output import ScoreRow, interval_lines
from ertools.benchmarks.common.path_gaps import GapOnPath
from ertools.benchmarks.common.uncertainty import Interval, Uncertainty, uncertainty_rows
from ertools.benchmarks.common.validity import Validity, cell
from ertools.benchmarks.fbm2h.goal import GoalList
from ertools.benchmarks.results import ResultBase
from ertools.configs.transform import MarkerTransform
from ertools.fidelity import Deviation
from ertools.frozen_dataclass import frozen_dataclass
from ertools.streams import Provenance
from ertools.timeutil import ns_to_s
from ertools.yamlin import load as load_yaml

Pose2 = tuple[float, float, float]


@frozen_dataclass
class Fbm2hIntervals:
    """The intervals of one result: accuracies, then per scored segment index."""

    position: Interval | None
    orientation: Interval | None
    distance: dict[int, Interval | None]
    angle: dict[int, Interval | None]
    uncertainty: Uncertainty


@frozen_dataclass
class SegmentResult:
    """One segment: from the previous waypoint (or the start) to waypoint ``index``.

    Attributes:
        index: waypoint number, from 0.
        target: the waypoint (x, y, theta).
        status: ``ok``, ``no_gt`` (tracking lost at the reached moment) or ``unreached``.
        start_ns, end_ns: segment start and reached moment (None when unreached).
        robot: robot (x, y, yaw) at the reached moment (None unless ``ok``).
        distance_error: metres (None unless ``ok``).
        orientation_error: radians, as reported (None unless ``ok``).
        dtheta: robot yaw minus target theta, unwrapped (None unless ``ok``).
        gt_offset_ns: time from the reached moment to the nearest GT sample.
        result_payload: the Client's COMPLETED_GOAL payload ("" when none).
        timeout: the segment ended by a RefBox timeout.
        validity: the validity of the GT samples from the segment's start to its reached
            moment (None when not driven).
        unscoreable_reason: why the reached moment has no valid GT (status ``no_gt``; with
            ``--unscoreable 2015`` the segment is scored and this is kept).
        gaps: the segment's invalid stretches where the path plot draws them: their times
            (seconds from the log's first message) and the robot's world (x, y) at their ends,
            the frame of ``Fbm2hResult.path_xyyaw``.
    """

    index: int
    target: Pose2
    status: str
    start_ns: int | None = None
    end_ns: int | None = None
    robot: Pose2 | None = None
    distance_error: float | None = None
    orientation_error: float | None = None
    dtheta: float | None = None
    gt_offset_ns: int | None = None
    result_payload: str = ""
    timeout: bool = False
    validity: Validity | None = field(default=None, compare=False)
    unscoreable_reason: str | None = None
    gaps: tuple[GapOnPath, ...] = field(default=(), compare=False)

    @property
    def segment_time(self) -> float | None:
        if self.start_ns is None or self.end_ns is None:
            return None
        return ns_to_s(self.end_ns - self.start_ns)


def _pose_map(p: Pose2 | None) -> dict[str, float] | None:
    if p is None:
        return None
    return {"x": float(p[0]), "y": float(p[1]), "theta": float(p[2])}


def _payload_value(payload: str) -> Any:
    """The payload as data when it is a YAML mapping, ``{}`` when empty, else the text."""
    text = payload.strip()
    if not text:
        return {}

    try:
        value = load_yaml(text, duplicates=[])  # shown as the 2015 node read it
    except yaml.YAMLError:
        return payload
    return value if isinstance(value, dict) else payload


def _validity_keys(seg: SegmentResult) -> dict[str, Any]:
    """The segment's validity keys, after the listing's (none for a segment never driven)."""
    out: dict[str, Any] = {} if seg.validity is None else seg.validity.fields()
    if seg.unscoreable_reason is not None:
        out["unscoreable_reason"] = seg.unscoreable_reason
    return out


def _as_list(iv: Interval | None) -> list[float] | None:
    return None if iv is None else iv.as_list()


def _num(x: float | None) -> float | None:
    return None if x is None or (isinstance(x, float) and math.isnan(x)) else float(x)


@frozen_dataclass(eq=False)
class Fbm2hResult(ResultBase):
    """A scored FBM2@Home run (implements ``BenchmarkResult``).

    Attributes:
        segments: one per waypoint.
        position_accuracy: mean distance error, metres (None when a segment failed).
        orientation_accuracy: atan2(sum sin, sum cos) of the orientation errors (None idem).
        execution_time: sum of the segment times, seconds.
        hits: the referee's count, None when not given.
        timeout_segments: segments ended by a timeout.
        transform: the marker-to-robot transform used.
        goal: the goal list.
        reached_method: ``states``, ``timing`` or ``auto``.
        orientation_2015: True when errors were computed the 2015 way (unwrapped).
        unscored_2015: True when the segments were counted as 2015 did (the one a RefBox
            END or the log's end cut short scored, the others 0 in the sums and 1 in N); the
            listing then writes ``refbox_timeout: false`` as the node always did, ``timeout``
            on the segment ``Timeout()`` was true after, and their count.
        path_t_ns, path_xyyaw: the robot's path (decimated) for the figures.
        notes: how the reached moments were found.
        origin_ns: the log's first message; table times count from it (from the first
            segment start when None).
        intervals: the confidence intervals of the scores (None with ``--draws 0``).
    """

    segments: tuple[SegmentResult, ...]
    position_accuracy: float | None
    orientation_accuracy: float | None
    execution_time: float
    hits: int | None
    timeout_segments: int
    transform: MarkerTransform
    goal: GoalList
    reached_method: str
    orientation_2015: bool
    path_t_ns: npt.NDArray[np.int64]
    path_xyyaw: npt.NDArray[np.float64]
    notes: tuple[str, ...] = ()
    origin_ns: int | None = None
    unscored_2015: bool = False
    warnings: tuple[str, ...] = ()
    deviations: tuple[Deviation, ...] = ()
    failures: tuple[str, ...] = ()
    provenance: Provenance = field(default_factory=Provenance)
    name: str = "fbm2h"
    intervals: Fbm2hIntervals | None = None

    @property
    def nothing_scored(self) -> bool:
        """Not one segment scored and the data is at fault (ground truth lost): the CLI prints
        only the failures (``ertools.benchmarks.document``). A benchmark the RefBox ended, or a
        log ended, before any waypoint was reached is still printed: its segments null, its
        execution_time, and the warning saying what 2015 gave (``--unscored-segments 2015``)."""
        if any(s.status == "ok" for s in self.segments):
            return False
        return any(s.status == "no_gt" for s in self.segments)

    def _segment_listing(self, seg: SegmentResult) -> dict[str, Any]:
        # Keys and order of Listing 13 (the 2015 node wrote "dinstance_error" so, typo included),
        # then the intervals of its two errors (issue 28) as extra keys.
        out = self._segment_listing_2015(seg)
        iv = self.intervals
        if iv is not None and seg.index in iv.distance:
            out["dinstance_error_interval"] = _as_list(iv.distance[seg.index])
            out["orientation_error_interval"] = _as_list(iv.angle.get(seg.index))
        out.update(_validity_keys(seg))
        return out

    def _segment_listing_2015(self, seg: SegmentResult) -> dict[str, Any]:
        return {
            "dinstance_error": _num(seg.distance_error),
            "end_segment_time": None if seg.end_ns is None else ns_to_s(seg.end_ns),
            "orientation_error": _num(seg.orientation_error),
            # 2015 (scripts/fbm2h 50b173b, l. 158-164): `Timeout() and not Running()` never
            # holds, so the node always wrote False here.
            "refbox_timeout": bool(seg.timeout) and not self.unscored_2015,
            "result_payload": _payload_value(seg.result_payload),
            "robot_pose": _pose_map(seg.robot),
            "segment_time": seg.segment_time,
            "start_segment_time": None if seg.start_ns is None else ns_to_s(seg.start_ns),
            "target_pose": _pose_map(seg.target),
            "timeout": bool(seg.timeout),
        }

    def listing(self) -> dict[Any, Any]:
        """The Listing 13 score (segment indices as integer keys)."""
        details = {s.index: self._segment_listing(s) for s in self.segments}
        out: dict[str, Any] = {
            "position_accuracy": _num(self.position_accuracy),
            "orientation_accuracy": _num(self.orientation_accuracy),
            "execution_time": float(self.execution_time),
            "hits": self.hits,
            "timeout_segments": int(self.timeout_segments),
            "details": {
                "marker-robot transform": self.transform.as_listing(),
                "segments_details": details,
            },
        }
        if self.intervals is not None:
            out["position_accuracy_interval"] = _as_list(self.intervals.position)
            out["orientation_accuracy_interval"] = _as_list(self.intervals.orientation)
            out["uncertainty"] = self.intervals.uncertainty.to_dict()
        reason = self.unscoreable_reason
        if reason is not None:
            out["status"] = "unscoreable"
            out["unscoreable_reason"] = reason
        return out

    @property
    def unscoreable_reason(self) -> str | None:
        """Why the accuracies are null when a reached moment had no valid ground truth (the
        rescore's ``unscoreable`` status), None otherwise."""
        if self.position_accuracy is not None:
            return None
        bad = [s for s in self.segments if s.status == "no_gt" and s.unscoreable_reason]
        if not bad:
            return None
        return "; ".join(f"segment {s.index}: {s.unscoreable_reason}" for s in bad)

    def validity_lines(self) -> list[str]:
        """The stderr lines: one per driven segment with invalid GT samples or no valid GT at
        its reached moment, else one line saying every segment's GT was valid."""
        t0 = self.origin_ns
        if t0 is None:
            t0 = next((s.start_ns for s in self.segments if s.start_ns is not None), 0)
        out = []
        driven = [s for s in self.segments if s.validity is not None]
        for s in driven:
            assert s.validity is not None
            if not s.validity.invalid_samples and s.unscoreable_reason is None:
                continue
            line = "validity: " + s.validity.text(f"segment {s.index}", t0)
            if s.unscoreable_reason is not None:
                verdict = "scored as 2015 did" if s.status == "ok" else "no GT"
                line += f"; {verdict}: {s.unscoreable_reason}"
            out.append(line)
        if driven and not out:
            out.append(f"validity: segments 0-{driven[-1].index} 100.0% valid")
        return out

    def interval_lines(self) -> list[str]:
        """The stderr lines of the intervals (:func:`interval_lines`): the accuracies, then
        each segment's errors, then the sources."""
        iv = self.intervals
        if iv is None:
            return []
        rows = [
            ScoreRow("position_accuracy", self.position_accuracy, iv.position, 1000.0, "mm"),
            ScoreRow(
                "orientation_accuracy", self.orientation_accuracy, iv.orientation, 1000.0, "mrad"
            ),
        ]
        for s in self.segments:
            if s.distance_error is None or s.index not in iv.distance:
                continue
            name = f"segment {s.index}"
            rows.append(
                ScoreRow(
                    f"{name} distance_error", s.distance_error, iv.distance[s.index], 1000.0, "mm"
                )
            )
            angle = iv.angle.get(s.index)
            rows.append(
                ScoreRow(f"{name} orientation_error", s.orientation_error, angle, 1000.0, "mrad")
            )
        return interval_lines(rows, iv.uncertainty)

    def tables(self) -> dict[str, Rows]:
        """``segments`` (one row per waypoint) and ``summary``."""
        t0 = self.origin_ns
        if t0 is None:
            t0 = next((s.start_ns for s in self.segments if s.start_ns is not None), None)

        def rel(t: int | None) -> float | None:
            return None if t is None or t0 is None else ns_to_s(t - t0)

        rows: Rows = []
        for s in self.segments:
            rows.append(
                {
                    "segment": s.index,
                    "status": s.status,
                    "start_s": rel(s.start_ns),
                    "reached_s": rel(s.end_ns),
                    "segment_time_s": s.segment_time,
                    "target_x": s.target[0],
                    "target_y": s.target[1],
                    "target_theta": s.target[2],
                    "robot_x": None if s.robot is None else s.robot[0],
                    "robot_y": None if s.robot is None else s.robot[1],
                    "robot_theta": None if s.robot is None else s.robot[2],
                    "distance_error_m": _num(s.distance_error),
                    **self._interval_columns("distance_error_m", s.index, "distance"),
                    "orientation_error_rad": _num(s.orientation_error),
                    **self._interval_columns("orientation_error_rad", s.index, "angle"),
                    "dtheta_unwrapped_rad": _num(s.dtheta),
                    "gt_offset_ms": None if s.gt_offset_ns is None else s.gt_offset_ns / 1e6,
                    "valid_fraction": None
                    if s.validity is None
                    else round(s.validity.valid_fraction, 6),
                    "invalid_samples": ""
                    if s.validity is None
                    else cell(s.validity.invalid_samples),
                    "unscoreable_reason": s.unscoreable_reason,
                }
            )
        summary: Rows = [
            {
                "position_accuracy_m": _num(self.position_accuracy),
                **self._interval_columns("position_accuracy_m", None, "position"),
                "orientation_accuracy_rad": _num(self.orientation_accuracy),
                **self._interval_columns("orientation_accuracy_rad", None, "orientation"),
                "execution_time_s": self.execution_time,
                "hits": self.hits,
                "timeout_segments": self.timeout_segments,
                "reached": self.reached_method,
                "transform": self.transform.robot_info or self.transform.source,
                "orientation_mode": "2015" if self.orientation_2015 else "wrapped",
            }
        ]
        out: dict[str, Rows] = {"segments": rows, "summary": summary}
        if self.intervals is not None:
            out["uncertainty"] = uncertainty_rows(self.intervals.uncertainty)
        return out

    def _interval_columns(self, column: str, index: int | None, which: str) -> dict[str, Any]:
        """``column_low``/``column_high`` of one interval (none with ``--draws 0``)."""
        iv = self.intervals
        if iv is None:
            return {}
        found: Interval | None
        if which == "distance" and index is not None:
            found = iv.distance.get(index)
        elif which == "angle" and index is not None:
            found = iv.angle.get(index)
        else:
            found = iv.position if which == "position" else iv.orientation
        return {
            f"{column}_low": None if found is None else found.low,
            f"{column}_high": None if found is None else found.high,
        }
