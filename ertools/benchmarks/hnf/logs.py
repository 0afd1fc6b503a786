"""What HNF's :func:`~ertools.benchmarks.hnf.pipeline.load` read: the run bag's events and
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
class HnfLogs:
    """A run bag and what the script read.

    Attributes:
        bag: the run bag.
        run: its RefBox/BmBox events and live scores.
        body: the robot's marker set on ``/tf``.
        stamps: the script's ``/robot`` lookups (their ``now``).
        waypoints: the config's waypoints, values as typed (an integer stays one).
        config_source: where the waypoints came from.
        transform: the team transform as the script broadcast it.
        transform_source: its file.
        result_file: the run's result file (None: not found).
        team: the team.
        log_end_ns: the bag's last message.
        warnings: what loading met (the config and the log's goals disagree...).
    """

    bag: Path
    run: RsbbRun
    body: TfTrack
    stamps: I64
    waypoints: tuple[tuple[Any, Any, Any], ...]
    config_source: str
    transform: Transform
    transform_source: str
    result_file: RsbbResult | None
    team: str | None
    log_end_ns: int
    warnings: tuple[str, ...]
