"""``ertools export``'s files: one pose source, or a robot/GT pair, as files other tools read
(TUM and KITTI for evo, CSV for pandas, spreadsheets and plotting tools).

- :func:`export_source`: one pose source (a pose topic or a tf frame, read by
  :func:`ertools.benchmarks.common.sources.read_source`) formatted for one file.
- :func:`write_pair`: the two streams of a pair (the trajectory benchmark's:
  :func:`ertools.benchmarks.trajectory.pairs.trajectory_pair`) as ``robot.<fmt>`` and
  ``gt.<fmt>``.

The formatting is in :mod:`ertools.exporting.formats` (pure); this module reads and writes.
"""

from __future__ import annotations

import logging
import os
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Protocol

from ertools.atomic import write_text
from ertools.benchmarks.common.hygiene import drop_duplicates
from ertools.benchmarks.common.sources import read_source
from ertools.errors import UsageError
from ertools.exporting.formats import SUFFIXES, ExportFormat, format_poses, format_times
from ertools.streams import PoseStream

if TYPE_CHECKING:
    from ertools.benchmarks.common.sources import PoseSpec

log = logging.getLogger(__name__)

KITTI_NEEDS_MATCHED = (
    "KITTI files have no time stamps: evo pairs robot and GT row by row, which only the "
    "scored pairs allow; add --matched, or export as TUM"
)


class Pair(Protocol):
    """Two streams to write side by side; ``matched``: the pairs a score compared, one GT pose
    per robot pose at the same stamp."""

    @property
    def robot(self) -> PoseStream: ...

    @property
    def gt(self) -> PoseStream: ...

    @property
    def matched(self) -> bool: ...


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


def pair_paths(out_dir: str | Path, fmt: ExportFormat) -> dict[str, Path]:
    """The files :func:`write_pair` writes: ``robot`` and ``gt`` (and their KITTI times)."""
    d = Path(out_dir)
    paths = {"robot": d / f"robot{SUFFIXES[fmt]}", "gt": d / f"gt{SUFFIXES[fmt]}"}
    if fmt == "kitti":
        paths["robot_times"] = d / "robot_times.txt"
        paths["gt_times"] = d / "gt_times.txt"
    return paths


def write_pair(pair: Pair, out_dir: str | Path, fmt: ExportFormat) -> list[Path]:
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
