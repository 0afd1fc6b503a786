"""``ertools export``: any pose source, or the robot/GT pair of the trajectory benchmark, as files
other tools read (TUM and KITTI for evo, CSV for pandas, spreadsheets and plotting tools).

Two library functions, one per mode of the command:

- :func:`export_source`: one pose source (a pose topic or a tf frame, read by
  :func:`ertools.benchmarks.common.sources.read_source`) to one file.
- :func:`trajectory_pair` + :func:`write_pair`: the two streams ``ertools score trajectory``
  compares, as ``robot.<fmt>`` and ``gt.<fmt>`` for ``evo_ape``. Raw (default): the robot
  poses with the applied clock offset added to their stamps and the GT ertools reads around
  them, for evo to associate itself. ``matched``: only the pairs ertools scored, both files
  stamped with the same times, the GT pose at each time given by ertools' association, so
  evo's nearest-time association pairs them one to one and its APE (translation part, no
  alignment) is ertools' position error.

The formatting is in :mod:`ertools.exporting.formats` (pure); this module reads and selects.
"""

from __future__ import annotations

import logging
import os
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from ertools.atomic import write_text
from ertools.benchmarks.common.hygiene import drop_duplicates, drop_invalid
from ertools.benchmarks.common.sources import read_source
from ertools.benchmarks.trajectory.association import COMPARED
from ertools.benchmarks.trajectory.benchmark import score
from ertools.benchmarks.trajectory.inputs import read_gt
from ertools.errors import ClockError, ScoringError, UsageError
from ertools.exporting.formats import SUFFIXES, ExportFormat, format_poses, format_times
from ertools.geometry import interpolate_poses
from ertools.io.text import is_text_trajectory, read_text_poses
from ertools.streams import PoseStream

log = logging.getLogger(__name__)

if TYPE_CHECKING:
    from ertools.benchmarks.common.sources import PoseSpec
    from ertools.benchmarks.trajectory.config import TrajectoryConfig
    from ertools.benchmarks.trajectory.result import TrajectoryResult

# GT read around the robot poses for the raw pair: evo's association only looks a few
# max_diff (0.01 s by default) beyond the robot's span; a second covers any sensible setting.
RAW_GT_MARGIN_NS = 1_000_000_000

KITTI_NEEDS_MATCHED = (
    "KITTI files have no time stamps: evo pairs robot and GT row by row, which only the "
    "scored pairs allow; add --matched, or export as TUM"
)


def export_source(
    paths: Sequence[str | Path],
    spec: PoseSpec,
    fmt: ExportFormat,
) -> tuple[PoseStream, str]:
    """Read one pose source (the one chooser, :func:`ertools.benchmarks.common.sources.
    read_source`: an empty source is refused) and format it: (the stream, the text).

    A message recorded twice (the same bag given twice, two loggers' overlapping files: the
    same stamp and pose) is written once, as ``score`` uses it once."""

    stream, twice = drop_duplicates(read_source(paths, spec, what="poses to export"))
    if twice:
        log.warning(
            "%d pose(s) recorded twice (the same stamp and pose in overlapping files) written once",
            twice,
        )
    return stream, format_poses(stream, fmt)


@dataclass(frozen=True, eq=False)
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

    The scoring itself runs (:func:`ertools.benchmarks.trajectory.score`), so the files,
    topics, offset and association are exactly the ones of the score; the GT is then read
    again (the result keeps only a decimated copy) around the robot poses and cleaned the
    same way (samples recorded twice, NaN or zero quaternions dropped).

    Raises:
        ScoringError: ``matched`` and no pose could be compared; the errors of ``score``.
        ClockError: robot poses outside the GT without ``allow_partial``.
    """

    result = score(
        robot_bag,
        gt_paths,
        config,
        robot_topic=robot_topic,
        gt_topic=gt_topic,
        robot_time=robot_time,
        gt_time=gt_time,
        input_format=input_format,
    )
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


def pair_paths(out_dir: str | Path, fmt: ExportFormat) -> dict[str, Path]:
    """The files :func:`write_pair` writes: ``robot`` and ``gt`` (and their KITTI times)."""
    d = Path(out_dir)
    paths = {"robot": d / f"robot{SUFFIXES[fmt]}", "gt": d / f"gt{SUFFIXES[fmt]}"}
    if fmt == "kitti":
        paths["robot_times"] = d / "robot_times.txt"
        paths["gt_times"] = d / "gt_times.txt"
    return paths


def write_pair(pair: PairExport, out_dir: str | Path, fmt: ExportFormat) -> list[Path]:
    """Write ``robot.<fmt>`` and ``gt.<fmt>`` into ``out_dir``; KITTI also gets the times.

    Raises:
        UsageError: KITTI without ``matched``: KITTI has no time stamps, readers pair the two
            files row by row, which only the matched pairs allow.
    """
    if fmt == "kitti" and not pair.matched:
        raise UsageError(KITTI_NEEDS_MATCHED)
    paths = pair_paths(out_dir, fmt)
    texts = {"robot": format_poses(pair.robot, fmt), "gt": format_poses(pair.gt, fmt)}
    if fmt == "kitti":
        # Both counted from the first robot pose: the same time has the same number.
        t0 = pair.robot.start_ns
        texts["robot_times"] = format_times(pair.robot, t0)
        texts["gt_times"] = format_times(pair.gt, t0)
    Path(out_dir).mkdir(parents=True, exist_ok=True)
    for key, text in texts.items():
        write_text(paths[key], text)
    return [paths[k] for k in texts]


def refuse_inputs(outputs: Sequence[Path], inputs: Sequence[Path]) -> None:
    """A UsageError when an output file is one of the inputs (ertools never overwrites them)."""
    existing = [p for p in inputs if p.exists()]
    for out in outputs:
        if not out.exists():
            continue
        for p in existing:
            if os.path.samefile(p, out):
                raise UsageError(f"{out}: that is an input; ertools never overwrites its inputs")
