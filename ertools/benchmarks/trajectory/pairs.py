"""The robot/GT pair of a trajectory comparison, as ``ertools export --out-dir`` writes it
for ``evo_ape`` (:mod:`ertools.exporting.write` writes the files).

:func:`trajectory_pair` gives the two streams ``ertools score trajectory`` compares. Raw
(default): the robot poses with the applied clock offset added to their stamps and the GT
ertools reads around them, for evo to associate itself. ``matched``: only the pairs ertools
scored, both stamped with the same times, the GT pose at each time given by ertools'
association, so evo's nearest-time association pairs them one to one and its APE
(translation part, no alignment) is ertools' position error.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from ertools.benchmarks.common.hygiene import drop_duplicates, drop_invalid
from ertools.benchmarks.scoring import run_stages
from ertools.benchmarks.trajectory.association import COMPARED
from ertools.benchmarks.trajectory.config import TrajectoryOptions
from ertools.benchmarks.trajectory.declare import BENCHMARK
from ertools.benchmarks.trajectory.logs import read_gt
from ertools.errors import ClockError, ScoringError
from ertools.frozen_dataclass import frozen_dataclass
from ertools.geometry import interpolate_poses
from ertools.io.text import is_text_trajectory, read_text_poses
from ertools.streams import PoseStream

if TYPE_CHECKING:
    from ertools.benchmarks.trajectory.config import TrajectoryConfig
    from ertools.benchmarks.trajectory.result import TrajectoryResult

# GT read around the robot poses for the raw pair: evo's association only looks a few
# max_diff (0.01 s by default) beyond the robot's span; a second covers any sensible setting.
RAW_GT_MARGIN_NS = 1_000_000_000


@frozen_dataclass(eq=False)
class PairExport:
    """The robot and GT streams of a trajectory comparison, ready to write.

    Attributes:
        robot: the robot poses, stamps on the GT clock (the applied offset added).
        gt: the GT poses (matched: one per robot pose, at the same stamps).
        matched: True when ``robot`` and ``gt`` are the scored pairs.
        result: what ``ertools score trajectory`` computed with the same settings.
    """

    robot: PoseStream
    gt: PoseStream
    matched: bool
    result: TrajectoryResult


def trajectory_pair(
    robot_bag: str | Path,
    gt_paths: Sequence[str | Path],
    config: TrajectoryConfig,
    *,
    robot_topic: str | None = None,
    gt_topic: str | None = None,
    robot_time: str = "header",
    gt_time: str = "header",
    input_format: str | None = None,
    matched: bool = False,
) -> PairExport:
    """The robot and GT streams ``score trajectory`` compares with these settings.

    The scoring itself runs (:func:`ertools.benchmarks.scoring.run_stages`), so the files,
    topics, offset and association are exactly the ones of the score; the GT is then read
    again (the result keeps only a decimated copy) around the robot poses and cleaned the
    same way (samples recorded twice, NaN or zero quaternions dropped).

    Raises:
        ScoringError: ``matched`` and no pose could be compared; the errors of the score.
        ClockError: robot poses outside the GT without ``allow_partial``.
    """

    options = TrajectoryOptions(config, robot_topic, gt_topic, robot_time, gt_time, input_format)
    result = run_stages(BENCHMARK, [Path(p) for p in (robot_bag, *gt_paths)], options)
    if result.uncovered and not config.allow_partial:
        # The score prints the covered part when the uncovered poses precede the GT (a
        # failure); files written for another tool would carry no such mark: refused.
        raise ClockError("; ".join(result.failures))
    m = result.matched
    robot = result.robot
    shifted = PoseStream(
        m.t_ns,  # the robot stamps plus the applied offset: the times ertools compared at
        robot.xyz,
        robot.quat_xyzw,
        robot.frame_id,
        robot.child_frame_id,
        f"{result.robot_file}:{result.robot_topic}",
    )
    if matched:
        ok = m.status == COMPARED
        if not ok.any():
            raise ScoringError(
                f"{result.robot_file}: no robot pose could be compared, so there are no pairs "
                f"to export ({'; '.join(result.failures)})"
            )
        shifted = shifted.take(ok)
        if m.gt_quat_xyzw is not None:
            # evo's pairs (--t-max-diff): the GT pose of each pair as scored, at the robot's
            # stamp, so that evo pairs the two files one to one.
            gt_pairs = PoseStream(
                shifted.t_ns, m.gt_xyz[ok], m.gt_quat_xyzw[ok], source=result.gt_topic
            )
            return PairExport(robot=shifted, gt=gt_pairs, matched=True, result=result)
        # Every compared pose has GT samples around it within max_gap: this window holds them.
        margin = config.max_gap_ns + RAW_GT_MARGIN_NS
        lo, hi = shifted.start_ns - margin, shifted.end_ns + margin
    else:
        lo, hi = int(m.t_ns.min()) - RAW_GT_MARGIN_NS, int(m.t_ns.max()) + RAW_GT_MARGIN_NS
    gt_kind = (
        is_text_trajectory(result.gt_files[0], input_format) if len(result.gt_files) == 1 else None
    )
    if gt_kind is not None:
        whole = read_text_poses(result.gt_files[0], gt_kind)
        gt = whole.take(np.argsort(whole.t_ns, kind="stable")).window(lo, hi)
    else:
        files = list(result.gt_files)
        gt = read_gt(files, result.gt_topic, lo, hi, time_source=gt_time)
        if len(gt) < 2:
            # Header stamps on another clock than the record times (simulation time): the
            # record-time prefilter finds nothing; the score read them without it.
            gt = read_gt(files, result.gt_topic, lo, hi, time_source=gt_time, prefilter=False)
    gt, _ = drop_duplicates(gt)
    gt, _ = drop_invalid(gt)
    if matched:
        gt = _gt_at(gt, shifted.t_ns, config, m.gt_xyz[m.status == COMPARED])
    return PairExport(robot=shifted, gt=gt, matched=matched, result=result)


def _gt_at(
    gt: PoseStream, t_ns: np.ndarray, config: TrajectoryConfig, scored_xyz: np.ndarray
) -> PoseStream:
    """GT poses at the robot times by the benchmark's association (the same function it uses).

    The positions are checked against the ones the score used: the pairs written must be the
    pairs scored, and a difference would mean the second read saw other GT than the first.
    """

    at = interpolate_poses(gt, t_ns, config.association)
    if not np.array_equal(at.xyz, scored_xyz):
        raise RuntimeError("the re-read GT differs from the GT the score used")
    return PoseStream(t_ns, at.xyz, at.quat_xyzw, gt.frame_id, gt.child_frame_id, gt.source)
