"""What HPFF's :func:`~ertools.benchmarks.hpff.pipeline.load` read: the run bag's events and
mocap, and the side files as the script read them."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from ertools.arrays import I64
from ertools.frozen_dataclass import frozen_dataclass
from ertools.rsbb.log import RsbbRun
from ertools.rsbb.results import RsbbResult
from ertools.rsbb.tf import TfTrack

Transform = tuple[tuple[float, float, float], tuple[float, float, float, float]]


@frozen_dataclass(eq=False)
class HpffLogs:
    """A run bag and what the script read.

    Attributes:
        bag: the run bag.
        run: its events and live scores.
        robot, person: the marker sets on ``/tf`` (``robot_markerset``, ``actor_markerset``).
        stamps: the script's ``/robot`` lookups (relative and absolute alike).
        params: the config's distances and ``goal_timeout`` (numbers as typed).
        config_source, transform, transform_source: the side files as read.
        result_file: the run's result file (None: not found).
        team: the team.
        log_end_ns: the bag's last message.
    """

    bag: Path
    run: RsbbRun
    robot: TfTrack
    person: TfTrack
    stamps: I64
    params: dict[str, Any]
    config_source: str
    transform: Transform
    transform_source: str
    result_file: RsbbResult | None
    team: str | None
    log_end_ns: int
