"""The offline trajectory benchmark as the registry sees it: its inputs and options
(``config``), help, the load -> compare stages (``pipeline``) and the parts a report, a
competition and the demo use. NumPy-free: ``ertools score trajectory``'s parser imports it.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ertools.benchmarks.base import (
    Benchmark,
    Described,
    Discovered,
    Ranking,
    Reported,
    Simulated,
)
from ertools.benchmarks.trajectory.inputs import INPUTS

if TYPE_CHECKING:  # annotations only: the stages import NumPy and the readers
    from ertools.benchmarks.trajectory.config import TrajectoryOptions
    from ertools.benchmarks.trajectory.pipeline import TrajectoryLogs
    from ertools.benchmarks.trajectory.result import TrajectoryResult
    from ertools.fidelity import Rule

DESCRIPTION = """Compare a robot's own pose log with the mocap ground truth (2015 offline
trajectory benchmark).

The GT files are picked from GT_PATH (bags or folders) by time overlap with the robot log and
read as one stream; without GT_PATH the GT topic is read from the robot log itself (evo's
`bag` mode). Every run also audits the clocks: it estimates the offset between the
robot's stamps and the GT clock and says when it matters."""

EPILOG = """examples:
  ertools score trajectory robot.bag gt/ --robot-topic /rockin/homer/marker_pose \\
      --gt-topic /fbm2h/robot_at_home/pose
  ertools score trajectory robot.bag gt/ --2015        # what the 2015 script computed
  ertools score trajectory robot.bag gt/ --association hold --gaps compare
  ertools score trajectory robot.bag gt/ --offset auto --apply-offset --format json
  ertools score trajectory robot.bag gt/log_0.bag gt/log_1.bag --offset -0.35 --plots figs/
  ertools score trajectory ROS_example.bag --robot-topic ORB-SLAM --gt-topic groundtruth \\
      --association nearest --t-max-diff 0.01
      # the pairs and numbers of: evo_ape bag ROS_example.bag groundtruth ORB-SLAM
  ertools score trajectory est.txt gt.txt --t-max-diff 0.01   # = evo_ape tum gt.txt est.txt
  ertools score trajectory est_kitti.txt gt_kitti.txt     # = evo_ape kitti (row by row)
  ertools score trajectory both.bag --robot-topic /rockin/homer/marker_pose \\
      --gt-topic /fbm2h/robot_at_home/pose     # one bag holding both topics (evo's bag mode)

ROBOT_BAG is the robot's log; GT_PATH: GT bags or folders of them (none: the GT topic is in
ROBOT_BAG itself). Either may be a TUM, KITTI, EuRoC or ertools CSV text trajectory.
offset: seconds added to the robot's stamps to put them on the GT clock (negative when the
robot's clock runs ahead). exit status: 0 scored, 1 unusable data, 2 usage
error.
"""


class Trajectory(
    Benchmark["TrajectoryOptions", "TrajectoryLogs", None, "TrajectoryResult"],
    Described,
    Reported["TrajectoryOptions", "TrajectoryResult"],
    Discovered,
    Simulated,
):
    """A robot's own pose log against the mocap ground truth (no state topics: not audited)."""

    name = "trajectory"
    title = "Offline trajectory benchmark"
    inputs = INPUTS
    sample_seed = 2018  # Simulated: sample_bags/ was written with it
    sample_folder = "robotlog"  # Simulated: a robot's own log, GT folder beside it
    example = "ertools score trajectory robot.bag gt/ --robot-topic /rockin/homer/marker_pose"
    description = DESCRIPTION
    epilog = EPILOG
    bags_help = (
        "the robot's log, then GT bags or folders of them (none: the GT topic is in ROBOT_BAG "
        "itself)"
    )
    bags_metavar = ("ROBOT_BAG", "GT_PATH")
    score_keys = frozenset({"position_error", "association"})
    ranking = Ranking(
        key=lambda r: None if r.metrics is None else r.metrics.position_error,
        lower_is_better=True,
        text="position_error (metres, the mean 3D distance to the GT): lower is better",
    )
    log_namespace = "rockin"  # the robot's own log: /rockin/<team>/marker_pose
    logs_may_be_text = True
    source_inputs = ("robot_topic", "gt_topic")

    @property
    def rules(self) -> tuple[Rule, ...]:
        from ertools.benchmarks.trajectory.rules import RULES  # lazy: fidelity, 1.5 ms

        return RULES

    def make_options(self, values: Mapping[str, Any]) -> TrajectoryOptions:
        from ertools.benchmarks.trajectory.config import (  # lazy: 2 dataclasses, 1.5 ms
            make_options,
        )

        return make_options(values)

    def load(self, logs: Sequence[Path], options: TrajectoryOptions) -> TrajectoryLogs:
        from ertools.benchmarks.trajectory import pipeline  # lazy: NumPy, the readers, 250 ms

        return pipeline.load(logs, options)

    def find_runs(self, loaded: TrajectoryLogs, options: TrajectoryOptions) -> None:
        from ertools.benchmarks.trajectory import pipeline  # lazy: NumPy, the readers, 250 ms

        return pipeline.find_runs(loaded, options)  # one run: the whole robot log

    def score_runs(
        self, loaded: TrajectoryLogs, runs: None, options: TrajectoryOptions
    ) -> TrajectoryResult:
        from ertools.benchmarks.trajectory import pipeline  # lazy: NumPy, the readers, 250 ms

        return pipeline.score_runs(loaded, runs, options)

    def notes(self, result: TrajectoryResult) -> Sequence[str]:
        """One stderr line per main statistic with its interval and the sources' shares."""
        from ertools.benchmarks.trajectory.result import notes  # lazy: NumPy, 100 ms

        return notes(result)

    def figures(self, result: TrajectoryResult) -> Sequence[Any]:
        from ertools.benchmarks.trajectory.plots import figure_specs  # lazy: the charts, 40 ms

        return figure_specs(result)

    def foxglove(self, out: Any, result: TrajectoryResult, *, limit: int) -> None:
        from ertools.benchmarks.trajectory.foxglove import content  # lazy: protobuf, 50 ms

        content(out, result, limit=limit)

    def input_files(
        self, logs: Sequence[Path], options: TrajectoryOptions, result: TrajectoryResult
    ) -> list[Path]:
        """The robot log and the GT files a folder held (in evo's bag mode the robot log is
        also the GT file: listed once)."""
        return list(dict.fromkeys([Path(logs[0]), *map(Path, result.gt_files)]))

    def sample_args(self, samples: Path) -> Sequence[str] | None:
        """The sample robot log against the GT folder beside it, clock offset estimated and
        applied (``make demo``)."""
        folder = samples / self.sample_folder
        robots = sorted(folder.glob("FBM2H_*.bag"))
        if not robots:
            return None
        return [str(robots[0]), str(folder), "--offset", "auto", "--apply-offset"]


BENCHMARK = Trajectory()
