"""Robot log vs mocap ground truth: the 2015 offline trajectory benchmark, with a clock audit.

The 2015 ``rockin_offline_trajectory_benchmark`` compared every pose a robot logged for its own
marker set (``/rockin/<team>/marker_pose``) with the mocap pose of that marker set: for each
robot pose it took the GT pose pair (p1, p2) with p1.t <= t <= p2.t, skipped the robot pose when
p1 and p2 had the same position (Motive repeats the last pose when tracking is lost), compared
with p1 ("hold") and reported the mean 3D distance and atan2(sum sin|dyaw|, sum cos|dyaw|).
Where ertools' default differs, one option restores each 2015 behaviour (the ``RULE_*``
constants) and :meth:`TrajectoryConfig.of_2015` (``--2015``) all of them at once.

Shape: load (robot stream, GT files selected by time overlap, read as one stream) -> associate
(hold | nearest | linear, max-gap, tracking lost, coverage) -> metrics -> frozen
:class:`TrajectoryResult`. The clock audit (:mod:`ertools.benchmarks.common.clocks`) runs every
time. :func:`score_streams` is pure; :func:`score` is the IO edge.
"""

from __future__ import annotations

import logging
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace
from itertools import pairwise
from pathlib import Path
from types import MappingProxyType
from typing import TYPE_CHECKING, Any, Literal

import numpy as np
import numpy.typing as npt

from ertools.benchmarks.base import Rows, dump_yaml, jsonable
from ertools.benchmarks.common.clocks import OffsetEstimate, estimate_offset
from ertools.errors import BagError, ClockError, ErtoolsError, ScoringError, TopicError
from ertools.fidelity import Deviation, Rule
from ertools.geometry import (
    Association,
    interpolate_poses,
    row_norm,
    wrap_angle,
    yaw_from_quat,
)
from ertools.streams import PoseStream, Provenance, frame_change_warning
from ertools.timeutil import NS_PER_S, iso_utc, ns_to_s

if TYPE_CHECKING:
    from ertools.io import BagSummary

log = logging.getLogger("ertools.benchmarks.trajectory.benchmark")

F64 = npt.NDArray[np.float64]
I64 = npt.NDArray[np.int64]
U8 = npt.NDArray[np.uint8]

ASSOCIATIONS: tuple[Association, ...] = ("linear", "nearest", "hold")
PERCENTILES = (50.0, 90.0, 95.0, 99.0)

# Per-pose status codes of the association.
COMPARED, GAP, TRACKING_LOST, UNCOVERED = 0, 1, 2, 3
STATUS_NAMES = ("compared", "gap", "tracking_lost", "uncovered")


Ties = Literal["at", "before"]
Gaps = Literal["skip", "compare"]
BeforeGt = Literal["uncovered", "first"]
TIES: tuple[Ties, ...] = ("at", "before")
GAPS: tuple[Gaps, ...] = ("skip", "compare")
BEFORE_GT: tuple[BeforeGt, ...] = ("uncovered", "first")


@dataclass(frozen=True)
class TrajectoryConfig:
    """How to compare.

    Attributes:
        association: ``linear`` (default), ``nearest`` or ``hold`` (2015).
        max_gap_ns: robot poses whose surrounding GT poses are further apart are in a GT gap.
        offset_ns: added to the robot stamps before comparing (``--offset S``).
        auto_offset: ``--offset auto``: estimate the offset (always done for the audit).
        apply_offset: with ``auto_offset``, score with the estimate.
        offset_range_ns: the audit searches offsets within +- this.
        allow_partial: score the covered part when robot poses lie outside the GT.
        ties: with ``hold``, a robot pose stamped exactly at a GT sample is compared with that
            sample (``at``) or with the one before it (``before``, 2015).
        gaps: robot poses in GT gaps are not compared (``skip``) or compared with the GT pose
            given by the association, counted and warned about (``compare``, 2015).
        before_gt: robot poses before the first GT pose are uncovered (``uncovered``) or
            compared with the first GT pose (``first``, 2015).
    """

    association: Association = "linear"
    max_gap_ns: int = NS_PER_S // 10
    offset_ns: int = 0
    auto_offset: bool = False
    apply_offset: bool = False
    offset_range_ns: int = 5 * NS_PER_S
    allow_partial: bool = False
    ties: Ties = "at"
    gaps: Gaps = "skip"
    before_gt: BeforeGt = "uncovered"

    def __post_init__(self) -> None:
        from ertools.errors import ConfigError

        if self.association not in ASSOCIATIONS:
            raise ConfigError(
                f"association {self.association!r} unknown; choose from {', '.join(ASSOCIATIONS)}"
            )
        for name, value, allowed in (
            ("ties", self.ties, TIES),
            ("gaps", self.gaps, GAPS),
            ("before-gt", self.before_gt, BEFORE_GT),
        ):
            if value not in allowed:
                raise ConfigError(f"--{name} {value!r} unknown; choose from {', '.join(allowed)}")
        if self.ties == "before" and self.association != "hold":
            # Only the held pose depends on the tie rule: linear and nearest give the sample at
            # the robot time whichever pair brackets it.
            raise ConfigError(f"--ties before needs --association hold (not {self.association})")
        if self.max_gap_ns <= 0:
            raise ConfigError(f"--max-gap must be positive, not {self.max_gap_ns / NS_PER_S} s")
        if self.offset_range_ns <= 0:
            raise ConfigError("--offset-range must be positive")

    @classmethod
    def of_2015(cls, **overrides: Any) -> TrajectoryConfig:
        """Every 2015 behaviour of ``rockin_trajectory_benchmark.py`` at once (``--2015``).

        Hold association with 2015's tie rule, GT gaps compared against the held pose, robot
        poses before the first GT pose compared with it. ``overrides`` set the other fields
        (offset, max-gap, allow-partial).
        """
        return cls(**{**SETTINGS_2015, **overrides})


# What ``--2015`` selects: each is one option on its own (docs/trajectory.md, the RULE_*
# constants below). Read-only: the CLI and of_2015 copy it.
SETTINGS_2015: Mapping[str, str] = MappingProxyType(
    {"association": "hold", "ties": "before", "gaps": "compare", "before_gt": "first"}
)

# The rules of the 2015 script where ertools' default differs (docs/fidelity.md). The 2015
# script is rockin_trajectory_benchmark.py of rockin_offline_trajectory_benchmark (seed
# footnote 15); the seed says only that it compares the GT with the trajectory the robot logged.
_SEED = (
    "seed footnote 15: rockin_offline_trajectory_benchmark compares the GT with the trajectory "
    "logged by the robot; section 4: NTP time makes the association 'straightforward'; no rule "
    "given"
)
RULE_ASSOCIATION = Rule(
    key="trajectory.association",
    benchmark="trajectory",
    title="GT pose at a robot time",
    rulebook=_SEED,
    node_2015=(
        "the GT pose before the first GT pose at or after the robot stamp, not interpolated "
        "(rockin_trajectory_benchmark.py: interpolate() 'not used', returns mocap_pose_1)"
    ),
    ertools=(
        "linear between the GT poses around the robot time (SLERP for orientation): holding "
        "adds up to one GT period of motion (8 ms at 120 Hz, 4 mm at 0.5 m/s) to the error"
    ),
    option="--association hold",
)
RULE_TIES = Rule(
    key="trajectory.ties",
    benchmark="trajectory",
    title="robot pose stamped exactly at a GT sample",
    rulebook=_SEED,
    node_2015=(
        "seek_mocap_pose_at stops at the first pair with p2.t >= t and uses p1: on a tie, the "
        "GT pose before the robot's (rockin_trajectory_benchmark.py)"
    ),
    ertools="with --association hold, the GT sample at the robot time: the GT pose at that time",
    option="--ties before",
)
RULE_GAPS = Rule(
    key="trajectory.gaps",
    benchmark="trajectory",
    title="robot poses in GT gaps",
    rulebook=_SEED,
    node_2015=(
        "compared with the pose held across the gap, only warned: 'consecutive mocap poses very "
        "distant in time, used to calculate the error (result may be invalid)' when t2 - t1 > "
        "0.1 s (rockin_trajectory_benchmark.py)"
    ),
    ertools=(
        "not compared, counted as gaps (--max-gap, default 0.1 s): the held pose may be "
        "seconds old and the error then measures the gap, not the robot"
    ),
    option="--gaps compare",
)
RULE_BEFORE_GT = Rule(
    key="trajectory.before-gt",
    benchmark="trajectory",
    title="robot poses before the first GT pose",
    rulebook=_SEED,
    node_2015=(
        "compared with the first GT pose after printing '[ERROR] ... This should never "
        "happen' (rockin_trajectory_benchmark.py, seek_mocap_pose_at)"
    ),
    ertools=(
        "uncovered: an error naming the span (GT files missing or clocks apart), or not "
        "scored with --allow-partial"
    ),
    option="--before-gt first",
)
RULE_YAW_WRAP = Rule(
    key="trajectory.yaw-wrap",
    benchmark="trajectory",
    title="orientation error across +-pi",
    rulebook=_SEED,
    node_2015=(
        "atan2(sum sin|dyaw|, sum cos|dyaw|) with dyaw = r_theta - m_theta not wrapped, yaws "
        "from tf euler_from_quaternion (rockin_trajectory_benchmark.py, Error.update)"
    ),
    ertools=(
        "dyaw wrapped to [-pi, pi] in orientation_error (a pose crossing +-pi otherwise counts "
        "a ~2pi difference); every run also reports 2015's value as orientation_error_2015, so "
        "no option is needed"
    ),
    option="",
)
RULE_GT_OVERLAP = Rule(
    key="trajectory.gt-overlap",
    benchmark="trajectory",
    title="GT files overlapping in time",
    rulebook=_SEED,
    node_2015=(
        "chained the GT files sorted by start time and scanned them in that order, warning "
        "'poses out of order: result may be invalid' (rockin_trajectory_benchmark.py)"
    ),
    ertools=(
        "poses merged in time order, a message recorded twice used once; no option: 2015's "
        "result there depends on where its scan stood, a defect rather than a rule"
    ),
    option="",
)
RULE_INVALID_POSES = Rule(
    key="trajectory.invalid-poses",
    benchmark="trajectory",
    title="NaN poses and zero quaternions",
    rulebook=_SEED,
    node_2015=(
        "used as they were: a NaN made the score NaN, a zero quaternion gave tf's identity, a "
        "yaw of 0 (rockin_trajectory_benchmark.py, Error.update)"
    ),
    ertools=(
        "ignored and counted in a warning; no option: a NaN score is no score, and a zero "
        "quaternion is a node publishing 'no pose'"
    ),
    option="",
)
RULE_ROBOT_STAMPS = Rule(
    key="trajectory.robot-stamps",
    benchmark="trajectory",
    title="robot stamps that go back in time",
    rulebook=_SEED,
    node_2015=(
        "its GT scan only moves forward: a robot pose stamped before the previous one was "
        "compared with the GT pose of the previous one (rockin_trajectory_benchmark.py)"
    ),
    ertools=(
        "an error naming the message; no option: the 2015 pairing there is not the GT at the "
        "robot's time (--robot-time record scores by the robot bag's record times instead)"
    ),
    option="",
)


@dataclass(frozen=True, eq=False)
class Matched:
    """Robot poses and their GT counterparts.

    Attributes:
        t_ns: (N,) robot times on the GT clock (stamps + offset).
        status: (N,) COMPARED, GAP, TRACKING_LOST or UNCOVERED.
        gt_xyz, gt_yaw: GT at each robot time (NaN unless compared).
        position_error: (N,) 3D distance, metres (NaN unless compared).
        yaw_error: (N,) |wrap(yaw_robot - yaw_gt)|, radians (NaN unless compared).
        yaw_diff_raw: (N,) yaw_robot - yaw_gt unwrapped, both yaws by tf's arithmetic, as
            2015 used it (NaN unless compared).
        exact_ties: robot poses stamped exactly at a GT sample.
        across_gap: (N,) the robot pose lies in a GT gap longer than the max gap (compared
            or not, as the ``gaps`` setting says).
        before_gt: robot poses before the first GT pose.
    """

    t_ns: I64
    status: U8
    gt_xyz: F64
    gt_yaw: F64
    position_error: F64
    yaw_error: F64
    yaw_diff_raw: F64
    exact_ties: int
    across_gap: npt.NDArray[np.bool_]
    before_gt: int

    def count(self, status: int) -> int:
        return int(np.count_nonzero(self.status == status))

    @property
    def gaps_compared(self) -> int:
        """Robot poses compared with a GT pose across a GT gap (``gaps`` ``compare``)."""
        return int(np.count_nonzero(self.across_gap & (self.status == COMPARED)))


def associate(
    robot: PoseStream,
    gt: PoseStream,
    method: Association,
    max_gap_ns: int,
    *,
    ties: Ties = "at",
    gaps: Gaps = "skip",
    before_gt: BeforeGt = "uncovered",
) -> Matched:
    """Pair every robot pose with the GT pose at its time.

    Rules, in this order: a robot pose after the last GT pose is UNCOVERED, and so is one
    before the first unless ``before_gt`` is ``first`` (then it is held at the first GT pose,
    as 2015 did). One whose surrounding GT poses are more than ``max_gap_ns`` apart lies in a
    GT gap: a GAP, not compared, unless ``gaps`` is ``compare`` (2015). One whose GT pair
    (the first GT pose at or after it and the one before that, the 2015 pair) has the same
    position is TRACKING_LOST; every other pose is COMPARED against the GT pose given by
    ``method``.

    The surrounding GT poses are the last at or before and the first at or after the robot
    time (one sample on an exact tie); with ``ties`` ``before`` (hold only) they are the 2015
    pair on ties too, and ``hold`` takes the first of the pair: the pose before the tie.
    """
    if len(gt) == 0:
        raise ScoringError("the GT stream is empty")
    n_gt = len(gt)
    q = robot.t_ns
    interp = interpolate_poses(gt, q, method)
    before = interp.hi == 0  # the first GT pose is at or after the robot time
    early = before & (q < gt.t_ns[0])
    # The 2015 pair (GT[k-1], GT[k]): k the first GT pose at or after the robot time; the
    # 2015 script started its scan at the pair (GT[0], GT[1]), so k is at least 1 there.
    second = interp.hi
    if ties == "before" or before_gt == "first":
        widen = early if ties == "at" else before
        second = np.where(widen, 1, second)
    first = second - 1
    has_pair = (first >= 0) & (second < n_gt)
    fi, si = np.clip(first, 0, n_gt - 1), np.clip(second, 0, n_gt - 1)
    inside = interp.inside | (early if before_gt == "first" else False)
    if ties == "before":
        pair_gap = gt.t_ns.take(si) - gt.t_ns.take(fi)
        gap_ns = np.where(has_pair, pair_gap, np.iinfo(np.int64).max)
        gt_xyz_at = _rows(gt.xyz, fi)
        gt_quat_at = _rows(gt.quat_xyzw, fi)
    else:
        gap_ns = interp.gap_ns
        if before_gt == "first" and n_gt > 1:
            # Held at the first GT pose: the pair around it is (GT[0], GT[1]), as in 2015.
            gap_ns = np.where(early, int(gt.t_ns[1] - gt.t_ns[0]), gap_ns)
        gt_xyz_at, gt_quat_at = interp.xyz, interp.quat_xyzw
    status = np.full(len(q), COMPARED, dtype=np.uint8)
    status[~inside] = UNCOVERED
    across = inside & (gap_ns > max_gap_ns)
    if gaps == "skip":
        status[across] = GAP
    same = has_pair & _same_rows(gt.xyz, fi, si)
    status[(status == COMPARED) & same] = TRACKING_LOST
    ok = status == COMPARED

    nan3 = np.full((len(q), 3), np.nan)
    gt_xyz = np.where(ok[:, None], gt_xyz_at, nan3)
    gt_yaw = np.where(ok, yaw_from_quat(gt_quat_at), np.nan)
    robot_yaw = yaw_from_quat(robot.quat_xyzw)
    pos_err = np.where(ok, row_norm(robot.xyz - gt_xyz_at), np.nan)
    yaw_err = np.abs(wrap_angle(np.where(ok, robot_yaw - gt_yaw, np.nan)))
    raw = np.where(ok, yaw_tf(robot.quat_xyzw) - yaw_tf(gt_quat_at), np.nan)
    ties_n = int(np.count_nonzero(interp.inside & (interp.lo == interp.hi)))
    return Matched(
        q, status, gt_xyz, gt_yaw, pos_err, yaw_err, raw, ties_n, across, int(early.sum())
    )


# tf.transformations' ``_EPS`` (4 machine epsilons): its gimbal-lock and zero-norm thresholds.
_TF_EPS = float(np.finfo(np.float64).eps) * 4.0


def yaw_tf(quat_xyzw: F64) -> F64:
    """Yaw as ``tf.transformations.euler_from_quaternion(q)[2]`` computes it (2015's scripts).

    tf normalises the quaternion inside its rotation matrix, so a quaternion slightly off unit
    norm gives the yaw of its unit quaternion: atan2(2(xy + zw), w^2 + x^2 - y^2 - z^2), which
    is :func:`ertools.geometry.yaw_from_quat` for a unit quaternion. At gimbal lock (pitch
    +-90 degrees) and for a zero quaternion tf returns a yaw of 0.
    """
    q = np.asarray(quat_xyzw, dtype=np.float64)
    x, y, z, w = q[..., 0], q[..., 1], q[..., 2], q[..., 3]
    n = np.einsum("...i,...i->...", q, q)
    with np.errstate(invalid="ignore", divide="ignore"):  # a zero quaternion: set to 0 below
        s = 2.0 / n
        m00 = 1.0 - (y * y + z * z) * s
        m10 = (x * y + z * w) * s
    out = np.arctan2(m10, m00)
    # tf: identity below _EPS of squared norm; yaw 0 where cos(pitch) (the norm of the
    # matrix's first column in x, y) is at most _EPS. Squares compared: no square root.
    flat = (n < _TF_EPS) | (m00 * m00 + m10 * m10 <= _TF_EPS * _TF_EPS)
    if flat.any():
        out = np.where(flat, 0.0, out)
    return np.asarray(out, dtype=np.float64)


def _rows(a: F64, index: npt.NDArray[np.intp]) -> F64:
    """``a[index]`` for a 2D array (``take`` gathers whole rows)."""
    return np.take(a, index, axis=0)


def _same_rows(a: F64, i: npt.NDArray[np.intp], j: npt.NDArray[np.intp]) -> npt.NDArray[np.bool_]:
    """``np.all(a[i] == a[j], axis=1)``: whole rows gathered by ``take``, compared by column."""
    ai = np.take(a, i, axis=0)
    aj = np.take(a, j, axis=0)
    same: npt.NDArray[np.bool_] = ai[:, 0] == aj[:, 0]
    for k in range(1, a.shape[1]):
        same &= ai[:, k] == aj[:, k]
    return same


@dataclass(frozen=True)
class Metrics:
    """Errors over the compared poses.

    Attributes:
        position_error: mean 3D distance (the 2015 score), metres.
        orientation_error: atan2(sum sin|dyaw|, sum cos|dyaw|) with dyaw wrapped (2015 form).
        rmse, median, max: of the 3D distances, metres.
        percentiles: (percent, value) of the 3D distances.
        orientation_error_2015: the same with dyaw not wrapped, as the 2015 script computed it.
    """

    position_error: float
    orientation_error: float
    rmse: float
    median: float
    max: float
    percentiles: tuple[tuple[float, float], ...]
    orientation_error_2015: float


def metrics(m: Matched) -> Metrics | None:
    """The error statistics of the compared poses, None when none was compared."""
    ok = m.status == COMPARED
    if not ok.any():
        return None
    d = m.position_error[ok]
    dyaw = m.yaw_error[ok]
    raw = np.abs(m.yaw_diff_raw[ok])
    pct = np.percentile(d, PERCENTILES)
    return Metrics(
        position_error=float(d.mean()),
        orientation_error=float(np.arctan2(np.sin(dyaw).sum(), np.cos(dyaw).sum())),
        rmse=float(np.sqrt(np.mean(d * d))),
        median=float(np.median(d)),
        max=float(d.max()),
        percentiles=tuple((p, float(v)) for p, v in zip(PERCENTILES, pct, strict=True)),
        orientation_error_2015=float(np.arctan2(np.sin(raw).sum(), np.cos(raw).sum())),
    )


def _spans(t_ns: I64, mask: npt.NDArray[np.bool_]) -> list[tuple[int, int]]:
    """(first, last) times of each run of consecutive True in ``mask``."""
    idx = np.flatnonzero(mask)
    if idx.size == 0:
        return []
    breaks = np.flatnonzero(np.diff(idx) > 1)
    starts = np.concatenate([[idx[0]], idx[breaks + 1]])
    ends = np.concatenate([idx[breaks], [idx[-1]]])
    return [(int(t_ns[a]), int(t_ns[b])) for a, b in zip(starts, ends, strict=True)]


@dataclass(frozen=True, eq=False)
class TrajectoryResult:
    """A scored robot log (implements ``BenchmarkResult``).

    Attributes:
        robot_file, robot_topic, gt_topic: what was compared.
        gt_files: the GT files used, by start time.
        config: the comparison settings.
        offset_ns: the offset applied to the robot stamps.
        metrics: None when no pose could be compared.
        matched: the per-pose association (the error series of the figures).
        robot: the robot stream (stamps on the robot clock).
        gt_path: the GT positions, decimated to at most a few thousand points, for figures.
        audit: the clock-offset estimate.
        uncovered_spans: robot-time spans outside the GT, (start_ns, end_ns) on the GT clock.
    """

    robot_file: str
    robot_topic: str
    gt_topic: str
    gt_files: tuple[str, ...]
    config: TrajectoryConfig
    offset_ns: int
    metrics: Metrics | None
    matched: Matched
    robot: PoseStream
    gt_path: PoseStream
    audit: OffsetEstimate
    uncovered_spans: tuple[tuple[int, int], ...] = ()
    warnings: tuple[str, ...] = ()
    deviations: tuple[Deviation, ...] = ()
    failures: tuple[str, ...] = ()
    provenance: Provenance = field(default_factory=Provenance)
    name: str = "trajectory"

    @property
    def nothing_scored(self) -> bool:
        """No robot pose compared, so no metric: the CLI prints only the failure."""
        return self.metrics is None

    @property
    def compared(self) -> int:
        return self.matched.count(COMPARED)

    @property
    def gaps(self) -> int:
        return self.matched.count(GAP)

    @property
    def tracking_lost(self) -> int:
        return self.matched.count(TRACKING_LOST)

    @property
    def uncovered(self) -> int:
        return self.matched.count(UNCOVERED)

    def to_dict(self) -> dict[str, Any]:
        """Scores, counts and the clock audit (the keys scripts depend on come first)."""
        m = self.metrics
        a = self.audit
        data: dict[str, Any] = {
            "position_error": None if m is None else m.position_error,
            "orientation_error": None if m is None else m.orientation_error,
            "rmse": None if m is None else m.rmse,
            "median": None if m is None else m.median,
            "max": None if m is None else m.max,
            "compared": self.compared,
            "gaps": self.gaps,
            "tracking_lost": self.tracking_lost,
            "gt_files": list(self.gt_files),
            "association": self.config.association,
            "offset": ns_to_s(self.offset_ns),
            "percentiles": None if m is None else {f"p{p:g}": v for p, v in m.percentiles},
            "orientation_error_2015": None if m is None else m.orientation_error_2015,
            "uncovered": self.uncovered,
            "gaps_compared": self.matched.gaps_compared,
            "before_gt": self.matched.before_gt,
            "ties": self.config.ties,
            "gap_poses": self.config.gaps,
            "before_gt_poses": self.config.before_gt,
            "robot_poses": len(self.matched.t_ns),
            "partial": self.uncovered > 0,
            "uncovered_spans": [[ns_to_s(s), ns_to_s(e)] for s, e in self.uncovered_spans],
            "max_gap": ns_to_s(self.config.max_gap_ns),
            "robot_file": self.robot_file,
            "robot_topic": self.robot_topic,
            "gt_topic": self.gt_topic,
            "clock_audit": {
                "estimated_offset": a.offset_s,
                "uncertainty": a.uncertainty_s,
                "applied": self.config.auto_offset and self.config.apply_offset,
                "residual": None if a.offset_ns is None else ns_to_s(a.offset_ns - self.offset_ns),
                "search_range": ns_to_s(a.search_range_ns),
                "poses_used": a.poses_used,
                "mean_error_at_estimate": a.mean_error,
                "mean_error_at_zero": a.mean_error_at_zero,
                "method": a.method,
                "note": a.note,
            },
            "warnings": list(self.warnings),
            "deviations": list(self.deviations),
        }
        out: dict[str, Any] = jsonable(data)
        return out

    def to_yaml(self) -> str:
        """The same as :meth:`to_dict` as YAML (the 2015 script printed two text lines)."""
        return dump_yaml(self.to_dict())

    def tables(self) -> dict[str, Rows]:
        """``samples`` (one row per robot pose: the error series) and ``summary``."""
        mt = self.matched
        t0 = int(mt.t_ns[0]) if len(mt.t_ns) else 0
        ryaw = self.robot.yaw
        rows: Rows = [
            {
                "t": ns_to_s(int(t)),
                "t_rel_s": (int(t) - t0) / NS_PER_S,
                "status": STATUS_NAMES[int(s)],
                "in_gt_gap": bool(g_),
                "robot_x": float(r[0]),
                "robot_y": float(r[1]),
                "robot_z": float(r[2]),
                "robot_yaw": float(ry),
                "gt_x": _f(g[0]),
                "gt_y": _f(g[1]),
                "gt_z": _f(g[2]),
                "gt_yaw": _f(gy),
                "position_error": _f(e),
                "yaw_error": _f(ye),
            }
            for t, s, g_, r, ry, g, gy, e, ye in zip(
                mt.t_ns.tolist(),
                mt.status.tolist(),
                mt.across_gap.tolist(),
                self.robot.xyz,
                ryaw.tolist(),
                mt.gt_xyz,
                mt.gt_yaw.tolist(),
                mt.position_error.tolist(),
                mt.yaw_error.tolist(),
                strict=True,
            )
        ]
        d = self.to_dict()
        summary = {
            k: d[k]
            for k in (
                "position_error",
                "orientation_error",
                "rmse",
                "median",
                "max",
                "compared",
                "gaps",
                "tracking_lost",
                "uncovered",
                "association",
                "offset",
                "orientation_error_2015",
                "gaps_compared",
            )
        }
        summary["estimated_offset"] = d["clock_audit"]["estimated_offset"]
        summary["offset_uncertainty"] = d["clock_audit"]["uncertainty"]
        return {"samples": rows, "summary": [summary]}


def _f(x: float) -> float | None:
    return None if np.isnan(x) else float(x)


# --- pure scoring ----------------------------------------------------------------------------


def check_increasing(robot: PoseStream, where: str) -> None:
    """Raise when the robot stamps (in recording order) do not strictly increase."""
    if len(robot) < 2:
        return
    bad = np.flatnonzero(robot.t_ns[1:] <= robot.t_ns[:-1])
    if bad.size:
        i = int(bad[0]) + 1
        raise ScoringError(
            f"{where}: robot stamps do not increase: message {i} is stamped "
            f"{iso_utc(int(robot.t_ns[i]))}, not after message {i - 1} at "
            f"{iso_utc(int(robot.t_ns[i - 1]))} ({bad.size} such place(s)); "
            "fix the robot's clock or use --robot-time record"
        )


def drop_duplicates(gt: PoseStream) -> tuple[PoseStream, int]:
    """GT without samples identical to the previous one in time and pose.

    Two loggers recording the same mocap topic (overlapping GT files) store every message
    twice; kept, each pair would look like Motive's tracking-loss repeat. A real repeat has a
    fresh stamp, so it is not dropped.
    """
    if len(gt) < 2:
        return gt, 0
    # Equal stamps are rare: compare the poses only there, not over the whole stream.
    at = np.flatnonzero(gt.t_ns[1:] == gt.t_ns[:-1])
    if at.size:
        same = np.all(gt.xyz[at + 1] == gt.xyz[at], axis=1) & np.all(
            gt.quat_xyzw[at + 1] == gt.quat_xyzw[at], axis=1
        )
        at = at[same]
    if not at.size:
        return gt, 0
    keep = np.ones(len(gt), dtype=bool)
    keep[at + 1] = False
    return gt.take(keep), int(at.size)


CHECK_ROWS = 1 << 14  # rows per chunk of the all-valid check: its buffers stay in cache


def _all_valid(stream: PoseStream) -> bool:
    """Whether :func:`drop_invalid` keeps every sample, shown cheaply or not at all.

    Squared quaternion norms by einsum far from both limits (NaN fails the comparisons too)
    and finite positions, chunk by chunk so that the temporaries stay in cache. False sends
    the stream to the exact per-sample test.
    """
    q, xyz = stream.quat_xyzw, stream.xyz
    buf = np.empty(min(len(q), CHECK_ROWS))
    for a in range(0, len(q), CHECK_ROWS):
        rows = slice(a, a + CHECK_ROWS)
        sq = np.einsum("ij,ij->i", q[rows], q[rows], out=buf[: len(q[rows])])
        if not (np.isfinite(xyz[rows]).all() and sq.min() > 1e-17 and sq.max() < 1e300):
            return False
    return True


def drop_invalid(stream: PoseStream) -> tuple[PoseStream, int]:
    """The stream without samples whose position or orientation is not usable.

    NaN or infinite values, or a zero quaternion (a node publishing "no pose"), cannot be
    compared; dropping them (and saying how many) beats a NaN score.
    """
    if _all_valid(stream):
        return stream, 0
    with np.errstate(over="ignore"):  # an overflowing norm is not finite: dropped below
        norm = row_norm(stream.quat_xyzw)
    ok = np.all(np.isfinite(stream.xyz), axis=1) & np.isfinite(norm) & (norm > 1e-9)
    if ok.all():
        return stream, 0
    return stream.take(ok), int((~ok).sum())


def _decimate(stream: PoseStream, limit: int = 5000) -> PoseStream:
    step = max(1, len(stream) // limit)
    return stream.take(slice(None, None, step))


def score_streams(
    robot: PoseStream,
    gt: PoseStream,
    config: TrajectoryConfig,
    *,
    robot_file: str = "",
    robot_topic: str = "",
    gt_topic: str = "",
    gt_files: Sequence[str] = (),
    warnings: Sequence[str] = (),
) -> TrajectoryResult:
    """Compare a robot stream (stamps on the robot clock, recording order) with GT.

    Raises:
        ScoringError: robot stamps not strictly increasing, or empty streams.
        ClockError: robot poses outside the GT without ``allow_partial``, or no overlap at all.
    """
    where = f"{robot_file}:{robot_topic}" if robot_file else "robot log"
    if len(robot) == 0:
        raise ScoringError(f"{where}: no robot poses")
    if len(gt) < 2:
        raise ScoringError(f"GT {gt_topic}: {len(gt)} pose(s) in the robot log's span")
    check_increasing(robot, where)
    notes = list(warnings)
    notes.extend(w for w in (frame_change_warning(gt), frame_change_warning(robot)) if w)
    gt, dropped = drop_duplicates(gt)
    invalid: list[Deviation] = []
    if dropped:
        notes.append(f"{dropped} GT sample(s) recorded twice (overlapping GT files) were used once")
    gt, bad_gt = drop_invalid(gt)
    robot, bad_robot = drop_invalid(robot)
    if bad_gt:
        notes.append(f"{bad_gt} GT sample(s) with NaN or zero-norm poses ignored")
    if bad_gt or bad_robot:
        invalid.append(
            RULE_INVALID_POSES.deviation(
                f"{bad_gt} GT and {bad_robot} robot pose(s) with NaN or zero-norm quaternions "
                "ignored (2015 used them: a NaN score, or a yaw of 0)"
            )
        )
    if bad_robot:
        notes.append(f"{bad_robot} robot pose(s) with NaN or zero-norm poses ignored")
    if len(robot) == 0:
        raise ScoringError(
            f"{where}: no valid robot poses left to compare (NaN or zero quaternions)"
        )
    if len(gt) < 2:
        raise ScoringError(
            f"GT {gt_topic} in {', '.join(gt_files) or 'the GT files'}: {len(gt)} valid pose(s) "
            "left in the robot log's span (the others are NaN or zero quaternions)"
        )
    audit = estimate_offset(
        robot, gt, search_range_ns=config.offset_range_ns, max_gap_ns=config.max_gap_ns
    )
    offset_ns = config.offset_ns
    if config.auto_offset and config.apply_offset:
        if audit.offset_ns is None:
            raise ClockError(f"{where}: cannot apply the estimated clock offset: {audit.note}")
        offset_ns = audit.offset_ns
    shifted = PoseStream(
        robot.t_ns + offset_ns,
        robot.xyz,
        robot.quat_xyzw,
        robot.frame_id,
        robot.child_frame_id,
        robot.source,
    )
    matched = associate(
        shifted,
        gt,
        config.association,
        config.max_gap_ns,
        ties=config.ties,
        gaps=config.gaps,
        before_gt=config.before_gt,
    )
    outside = matched.status == UNCOVERED
    spans = _spans(matched.t_ns, outside)
    n_out = int(outside.sum())
    if n_out == len(matched.t_ns):
        raise ClockError(
            f"{where}: no robot pose lies within the GT ({iso_utc(gt.start_ns)} to "
            f"{iso_utc(gt.end_ns)}); robot poses span {iso_utc(int(shifted.t_ns[0]))} to "
            f"{iso_utc(int(shifted.t_ns[-1]))} (offset {ns_to_s(offset_ns):+.3f} s)"
        )
    if n_out:
        text = ", ".join(
            f"{iso_utc(a)} to {iso_utc(b)} ({ns_to_s(b - a):.1f} s)" for a, b in spans[:3]
        )
        more = f" and {len(spans) - 3} more" if len(spans) > 3 else ""
        msg = f"{n_out} of {len(matched.t_ns)} robot poses lie outside the GT: {text}{more}"
        if not config.allow_partial:
            early = int(np.count_nonzero(outside & (matched.t_ns < gt.t_ns[0])))
            hint = (
                f" ({early} lie before the first GT pose: 2015 compared them with it, "
                "--before-gt first)"
                if early
                else ""
            )
            raise ClockError(f"{where}: {msg}; give the missing GT files or --allow-partial{hint}")
        notes.append(f"partial: {msg}; only the covered part is scored")

    m = metrics(matched)
    failures: list[str] = []
    if m is None:
        failures.append(
            f"no robot pose could be compared ({matched.count(GAP)} in GT gaps, "
            f"{matched.count(TRACKING_LOST)} while tracking was lost)"
        )
    if matched.count(GAP):
        notes.append(
            f"{matched.count(GAP)} robot pose(s) fall in GT gaps longer than "
            f"{ns_to_s(config.max_gap_ns):g} s and are not compared"
        )
    if matched.gaps_compared:
        notes.append(
            f"{matched.gaps_compared} robot pose(s) fall in GT gaps longer than "
            f"{ns_to_s(config.max_gap_ns):g} s and are compared with the GT pose "
            f"{'held' if config.association == 'hold' else 'bridging'} across the gap "
            "(--gaps compare; 2015: 'result may be invalid')"
        )
    if config.before_gt == "first" and matched.before_gt:
        notes.append(
            f"{matched.before_gt} robot pose(s) before the first GT pose are compared with "
            "the first GT pose (--before-gt first; 2015 printed an error and went on)"
        )
    if matched.count(TRACKING_LOST):
        notes.append(
            f"{matched.count(TRACKING_LOST)} robot pose(s) fall where mocap tracking was lost "
            "(repeated GT poses) and are not compared"
        )
    notes.extend(_audit_warnings(audit, offset_ns))
    result = TrajectoryResult(
        robot_file=robot_file,
        robot_topic=robot_topic,
        gt_topic=gt_topic,
        gt_files=tuple(gt_files),
        config=config,
        offset_ns=offset_ns,
        metrics=m,
        matched=matched,
        robot=robot,
        gt_path=_decimate(gt),
        audit=audit,
        uncovered_spans=tuple(spans),
        warnings=tuple(notes),
        deviations=(*_deviations(config, matched, m), *invalid),
        failures=tuple(failures),
        provenance=Provenance(
            inputs=(robot_file, *gt_files),
            parameters=(
                ("robot_topic", robot_topic),
                ("gt_topic", gt_topic),
                ("association", config.association),
                ("ties", config.ties),
                ("gaps", config.gaps),
                ("before_gt", config.before_gt),
                ("max_gap", f"{ns_to_s(config.max_gap_ns):g}"),
                ("offset", f"{ns_to_s(offset_ns):g}"),
            ),
        ),
    )
    return result


def _audit_warnings(audit: OffsetEstimate, applied_ns: int) -> list[str]:
    if audit.offset_ns is None:
        return [f"clock audit: no offset estimate ({audit.note})"]
    out = []
    residual = audit.offset_ns - applied_ns
    sigma = audit.uncertainty_ns or 0
    # Worth a warning when the residual is both significant (3 sigma) and large enough to
    # matter for the score (10 ms: 5 mm at a typical 0.5 m/s).
    if abs(residual) > max(3 * sigma, 10_000_000):
        out.append(
            f"clock audit: the robot stamps fit the GT best shifted by "
            f"{ns_to_s(audit.offset_ns):+.3f} +- {ns_to_s(sigma):.3f} s, but the score uses "
            f"{ns_to_s(applied_ns):+.3f} s; check the clocks, or re-run with "
            "--offset auto --apply-offset"
        )
    if audit.note:
        out.append(f"clock audit: {audit.note}")
    return out


def _deviations(config: TrajectoryConfig, m: Matched, metr: Metrics | None) -> list[Deviation]:
    out = []
    if config.association != "hold":
        out.append(
            RULE_ASSOCIATION.deviation(
                f"association {config.association} (2015: hold, the GT pose before the robot pose)"
            )
        )
    elif config.ties == "at" and m.exact_ties:
        out.append(
            RULE_TIES.deviation(
                f"{m.exact_ties} robot pose(s) stamped exactly at a GT sample use that sample "
                "(2015 used the one before it)"
            )
        )
    if m.count(GAP):
        out.append(
            RULE_GAPS.deviation(
                f"{m.count(GAP)} robot pose(s) in GT gaps > {ns_to_s(config.max_gap_ns):g} s "
                "not compared (2015 compared them with the held pose and only warned)"
            )
        )
    if config.before_gt == "uncovered" and m.before_gt:
        out.append(
            RULE_BEFORE_GT.deviation(
                f"{m.before_gt} robot pose(s) before the first GT pose not scored (2015 compared "
                "them with the first GT pose)"
            )
        )
    wrapped = int(np.count_nonzero(np.abs(m.yaw_diff_raw[m.status == COMPARED]) > np.pi))
    if wrapped and metr is not None:
        out.append(
            RULE_YAW_WRAP.deviation(
                f"yaw differences wrapped to [-pi, pi] ({wrapped} pose(s) crossed +-pi; 2015 did "
                f"not wrap: its orientation error, orientation_error_2015, is "
                f"{metr.orientation_error_2015:.4f} rad)"
            )
        )
    return out


# --- the IO edge -------------------------------------------------------------------------------


@dataclass(frozen=True)
class Inputs:
    """Selected inputs: the robot stream in recording order and the GT files to read."""

    robot: PoseStream
    robot_file: str
    robot_topic: str
    gt_files: tuple[str, ...]
    gt_topic: str
    warnings: tuple[str, ...]


def _pose_topics(s: BagSummary) -> list[str]:
    from ertools.io.model import POSE_TYPES

    return [
        t.name for t in s.topics if t.msgtype in POSE_TYPES and t.name not in ("/tf", "/tf_static")
    ]


def _pick_robot_topic(s: BagSummary, topic: str | None) -> str:
    if topic is not None:
        if s.topic(topic) is None:
            raise TopicError(
                f"robot topic {topic} not in {s.path}; pose topics there: "
                f"{', '.join(_pose_topics(s)) or 'none'}"
            )
        return topic
    cands = [
        t.name
        for t in s.topics
        if t.name.startswith("/rockin/") and t.name.endswith("/marker_pose")
    ]
    if len(cands) == 1:
        return cands[0]
    raise TopicError(
        f"{s.path}: give --robot-topic (found {len(cands)} /rockin/*/marker_pose topics; "
        f"pose topics there: {', '.join(_pose_topics(s)) or 'none'})"
    )


def read_robot(path: str, topic: str, time_source: str) -> PoseStream:
    """The robot's poses in recording order (not sorted: non-increasing stamps are errors)."""
    from ertools.io.files import open_bag
    from ertools.io.model import POSE_TYPES, TF_TYPES
    from ertools.io.reader import load_pose_batch

    with open_bag(path) as bag:
        conns = bag.topic_conns(topic)
        types = {c.msgtype for c in conns}
        if not types or not types <= set(POSE_TYPES):
            raise TopicError(
                f"robot topic {topic} has type {', '.join(sorted(types)) or 'unknown'}, "
                f"not a pose type ({', '.join(POSE_TYPES)})",
                path=path,
            )
        if "geometry_msgs/Pose2D" in types and time_source == "header":
            raise TopicError(
                f"robot topic {topic} has type geometry_msgs/Pose2D, which has no header "
                "stamp; give --robot-time record",
                path=path,
            )
        batch = load_pose_batch(bag, conns, None, None)
    if (
        types & set(TF_TYPES)
        and len(batch)
        and (
            np.any(batch.child_idx != batch.child_idx[0])
            or np.any(batch.frame_idx != batch.frame_idx[0])
        )
    ):
        # A tf topic with several transforms: rows of different bodies, not one trajectory.
        names = zip(batch.frame_names(), batch.child_names(), strict=True)
        pairs = sorted({f"{a} -> {b}" for a, b in names})
        raise TopicError(
            f"robot topic {topic} holds the poses of several frames ({', '.join(pairs[:4])}"
            f"{' ...' if len(pairs) > 4 else ''}); give a topic with one body's poses",
            path=path,
        )
    t = batch.t_header if time_source == "header" else batch.t_record
    return PoseStream(t, batch.xyz, batch.quat_xyzw, source=f"{path}:{topic}")


def select_gt(
    summaries: Sequence[BagSummary],
    start_ns: int,
    end_ns: int,
    gt_topic: str | None,
) -> tuple[list[BagSummary], str, list[str]]:
    """GT files overlapping [start, end] that hold the GT topic, by start time.

    Returns the files, the topic (guessed when None and unambiguous) and warnings.
    """
    overlapping = sorted(
        (s for s in summaries if s.message_count and s.start_ns <= end_ns and s.end_ns >= start_ns),
        key=lambda s: (s.start_ns, s.path),
    )
    if not overlapping:
        spans = "; ".join(
            f"{Path(s.path).name} {iso_utc(s.start_ns)} to {iso_utc(s.end_ns)}"
            for s in sorted(summaries, key=lambda s: s.start_ns)[:4]
        )
        raise ClockError(
            f"no GT file overlaps the robot log ({iso_utc(start_ns)} to {iso_utc(end_ns)}, "
            "search margin included); "
            f"GT files: {spans or 'none'}{' ...' if len(summaries) > 4 else ''}; "
            "if the robot's clock was far off, give --offset S"
        )
    if gt_topic is None:
        cands = sorted(
            {
                t.name
                for s in overlapping
                for t in s.topics
                if t.msgtype == "geometry_msgs/PoseStamped" and not t.name.startswith("/rockin/")
            }
        )
        if len(cands) != 1:
            raise TopicError(
                f"give --gt-topic: the overlapping GT files hold {len(cands)} PoseStamped "
                f"topics ({', '.join(cands) or 'none'})"
            )
        gt_topic = cands[0]
    with_topic = [s for s in overlapping if s.topic(gt_topic) is not None]
    if not with_topic:
        topics = sorted({n for s in overlapping for n in _pose_topics(s)})
        raise TopicError(
            f"GT topic {gt_topic} is in none of the {len(overlapping)} GT file(s) overlapping "
            f"the robot log ({Path(overlapping[0].path).name}...); pose topics there: "
            f"{', '.join(topics) or 'none'}"
        )
    warnings = []
    for a, b in pairwise(with_topic):
        if b.start_ns < a.end_ns:
            warnings.append(
                f"GT files {Path(a.path).name} and {Path(b.path).name} overlap in time "
                f"({ns_to_s(a.end_ns - b.start_ns):.1f} s); their poses are merged in time order"
            )
    return with_topic, gt_topic, warnings


def read_gt(files: Sequence[str], topic: str, start_ns: int, end_ns: int) -> PoseStream:
    """GT poses with header stamps in [start_ns, end_ns], in one read of all the files.

    The reader streams a ROS1 bag's chunks into preallocated arrays: one read of an hour of
    120 Hz GT peaks at ~85 MiB (measured, docs/performance.md), so the 10-minute windows this
    once took (each re-reading 60 s of extra chunks at both ends) only cost time.
    """
    from ertools.io import read_poses

    return read_poses(files, topic, start_ns=start_ns, end_ns=end_ns)


def same_bag(robot_bag: str | Path, gt_paths: Sequence[str | Path]) -> bool:
    """Whether the GT is read from the robot log itself: no GT path, or only the robot log."""
    robot_real = Path(robot_bag).resolve()
    return all(Path(p).resolve() == robot_real for p in gt_paths)


def _pick_gt_in_robot_bag(
    s: BagSummary, gt_topic: str | None, robot_topic: str, gt_paths: Sequence[str | Path]
) -> str:
    """The GT topic in a robot log that holds both (evo's ``bag`` mode), or a one-line error."""
    how = "the robot log itself" if gt_paths else "no GT_PATH given"
    others = [n for n in _pose_topics(s) if n != robot_topic]
    if gt_topic is not None:
        if gt_topic == robot_topic:
            raise TopicError(f"the GT topic {gt_topic} is the robot topic; give the mocap topic")
        if s.topic(gt_topic) is None:
            raise TopicError(
                f"GT topic {gt_topic} is not in the robot log {s.path} (GT read from {how}); "
                f"other pose topics there: {', '.join(others) or 'none'}; "
                "give the GT files or their folder as GT_PATH"
            )
        return gt_topic
    cands = [
        t.name
        for t in s.topics
        if t.msgtype == "geometry_msgs/PoseStamped"
        and not t.name.startswith("/rockin/")
        and t.name != robot_topic
    ]
    if len(cands) == 1:
        return cands[0]
    if not cands:
        raise TopicError(
            f"{s.path}: the GT is read from {how}, but it holds no GT pose topic besides the "
            f"robot topic {robot_topic}; give the mocap GT files or their folder as GT_PATH"
        )
    raise TopicError(
        f"{s.path}: give --gt-topic (the GT is read from {how}; its PoseStamped topics: "
        f"{', '.join(cands)})"
    )


def _gt_files(
    robot_path: str,
    gt_paths: Sequence[str | Path],
    start_ns: int,
    end_ns: int,
    gt_topic: str | None,
) -> tuple[list[BagSummary], str, list[str], list[str]]:
    """The GT files of GT_PATH overlapping [start, end], their topic, warnings, damaged files."""
    from ertools.io import summary
    from ertools.timeline.scan import find_bags

    found = find_bags([Path(p) for p in gt_paths])
    if not found.bags:
        raise ClockError(
            f"no GT bags found in {', '.join(map(str, gt_paths))}"
            + (f" ({found.problems[0].problem})" if found.problems else "")
        )
    robot_real = Path(robot_path).resolve()
    if all(Path(b).resolve() == robot_real for b in found.bags):
        raise ClockError(
            f"the only bag in GT_PATH ({', '.join(map(str, gt_paths))}) is the robot log "
            "itself: give the mocap GT files or their folder"
        )
    # Named on the command line (a file or a rosbag2 folder): unreadable is an error, not a skip.
    explicit = {Path(p) for p in gt_paths}
    skipped: list[str] = []
    for problem in found.problems:
        if not Path(problem.path).exists():
            # A mistyped GT path must not pass unnoticed behind the other GT files.
            raise BagError(f"GT path: {problem.problem}", path=problem.path)
        skipped.append(f"GT path {problem.path}: {problem.problem}")
    gt_summaries = []
    broken: list[str] = []
    for p in found.bags:
        if Path(p).resolve() == Path(robot_path).resolve():
            continue
        try:
            s = summary(p)
        except ErtoolsError as err:
            if Path(p) in explicit:
                raise
            # A broken bag elsewhere in a GT folder must not stop the scoring: say so.
            skipped.append(f"skipped unreadable file in the GT folder: {p}: {err.message}")
            continue
        gt_summaries.append(s)
        damaged = [pr for pr in s.problems if not pr.startswith("not indexed")]
        if damaged:
            # Read up to the damage: GT poses past it are missing, which the coverage check
            # then reports; say why here.
            skipped.append(f"GT file {p} is damaged: {'; '.join(damaged)}")
            broken.append(str(p))
    try:
        chosen, gtopic, warnings = select_gt(gt_summaries, start_ns, end_ns, gt_topic)
    except ClockError as err:
        if not skipped:
            raise
        raise ClockError(f"{err}; also: {'; '.join(skipped)}") from err
    return chosen, gtopic, skipped + warnings, broken


def score(
    robot_bag: str | Path,
    gt_paths: Sequence[str | Path],
    config: TrajectoryConfig | None = None,
    *,
    robot_topic: str | None = None,
    gt_topic: str | None = None,
    robot_time: str = "header",
) -> TrajectoryResult:
    """Score a robot log against the GT files (or folders of them) that cover it.

    With no GT path, or the robot log itself as the only one, the GT topic is read from the
    robot log (evo's ``bag`` mode: one bag recorded both topics).

    Raises:
        BagError, TopicError: unreadable files, missing topics.
        ClockError: no GT overlapping the robot log, poses outside the GT.
        ScoringError: non-increasing robot stamps.
    """
    from ertools.io import summary

    cfg = config or TrajectoryConfig()
    robot_path = str(robot_bag)
    rs = summary(robot_path)
    topic = _pick_robot_topic(rs, robot_topic)
    robot = read_robot(robot_path, topic, robot_time)
    if len(robot) == 0:
        raise ScoringError(f"{robot_path}: robot topic {topic} has no messages")
    # The robot's span on the GT clock, widened by the clock audit's search range.
    lo = int(robot.t_ns.min()) + cfg.offset_ns
    hi = int(robot.t_ns.max()) + cfg.offset_ns
    margin = max(cfg.offset_range_ns, NS_PER_S)
    if same_bag(robot_path, gt_paths):
        # evo's `bag` mode: one bag holds both the robot's topic and the GT topic.
        chosen, gtopic = [rs], _pick_gt_in_robot_bag(rs, gt_topic, topic, gt_paths)
        warnings: list[str] = []
        broken: list[str] = []
    else:
        chosen, gtopic, warnings, broken = _gt_files(
            robot_path, gt_paths, lo - margin, hi + margin, gt_topic
        )
    files = [s.path for s in chosen]
    gt = read_gt(files, gtopic, lo - margin, hi + margin)
    try:
        result = score_streams(
            robot,
            gt,
            cfg,
            robot_file=robot_path,
            robot_topic=topic,
            gt_topic=gtopic,
            gt_files=files,
            warnings=warnings,
        )
    except ClockError as err:
        if not broken:
            raise
        # The warnings die with the error: name the damaged GT file where the user looks.
        raise ClockError(
            f"{err}; damaged GT file(s), read only up to the damage: {', '.join(broken)}"
        ) from err
    overlaps = sum(1 for a, b in pairwise(chosen) if b.start_ns < a.end_ns)
    if overlaps:
        dev = RULE_GT_OVERLAP.deviation(
            f"{overlaps} pair(s) of GT files overlap in time: their poses are merged in time "
            "order, a message recorded twice used once (2015 chained the files by start time "
            "and scanned the poses out of order)"
        )
        result = replace(result, deviations=(*result.deviations, dev))
    return result
