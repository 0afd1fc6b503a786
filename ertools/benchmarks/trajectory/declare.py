"""The offline trajectory benchmark as the registry sees it: its inputs (the options of
``ertools score trajectory``, the manifest keys), how they become
:class:`TrajectoryOptions`, and the load -> compare stages.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from ertools.benchmarks.base import Benchmark, Input, Ranking, resolve_values
from ertools.benchmarks.common.interval_output import (
    IntervalSettings,
    ScoreRow,
    interval_lines,
)
from ertools.benchmarks.common.uncertainty import INTERVAL_INPUTS
from ertools.benchmarks.common.validity import unscoreable_input
from ertools.benchmarks.trajectory.benchmark import (
    TrajectoryLogs,
    TrajectoryOptions,
    load,
    locate_runs,
    score_found,
)
from ertools.benchmarks.trajectory.config import (
    ASSOCIATIONS,
    BEFORE_GT,
    GAPS,
    GT_ORDERS,
    SETTINGS_2015,
    TIES,
    TrajectoryConfig,
)
from ertools.benchmarks.trajectory.intervals import FITTED_SUFFIX
from ertools.benchmarks.trajectory.result import TrajectoryResult
from ertools.errors import ConfigError, UsageError
from ertools.io.text import INPUT_FORMATS
from ertools.timeutil import s_to_ns

# Offsets beyond this (about 146 years) are not clock offsets; int64 nanoseconds hold them.
MAX_OFFSET_S = 4.6e9
LEGACY = "2015 behaviour (each difference can be undone)"

INPUTS = (
    Input(
        "robot_topic",
        "str",
        "the robot's pose of its marker set (default: the one /rockin/*/marker_pose)",
        metavar="TOPIC",
    ),
    Input(
        "gt_topic",
        "str",
        "the mocap pose of that marker set (default: the one PoseStamped topic)",
        metavar="TOPIC",
    ),
    Input(
        "association",
        "choice",
        "GT pose at a robot time: interpolated (linear, default), nearest, or the last "
        "before (hold, 2015)",
        choices=ASSOCIATIONS,
        group=LEGACY,
    ),
    Input(
        "ties",
        "choice",
        "with --association hold, a robot pose stamped exactly at a GT sample is compared "
        "with that sample (at, default) or the one before it (before, 2015)",
        choices=TIES,
        group=LEGACY,
    ),
    Input(
        "gaps",
        "choice",
        "robot poses in GT gaps longer than --max-gap: not compared (skip, default) or "
        "compared with the GT pose across the gap and counted (compare, 2015)",
        choices=GAPS,
        group=LEGACY,
    ),
    Input(
        "before_gt",
        "choice",
        "robot poses before the first GT pose: uncovered (default: an error, or not scored "
        "with --allow-partial) or compared with the first GT pose (first, 2015)",
        choices=BEFORE_GT,
        group=LEGACY,
    ),
    Input(
        "gt_order",
        "choice",
        "GT files overlapping in time: their poses merged in time order (time, default) or "
        "the files chained by start time and scanned forward (chain, 2015; needs "
        "--association hold --ties before)",
        choices=GT_ORDERS,
        group=LEGACY,
    ),
    # too few valid pairs make the comparison unscoreable (docs/uncertainty.md)
    unscoreable_input(LEGACY),
    Input(
        "as_2015",
        "flag",
        "compute what the 2015 script did: --association hold --ties before --gaps compare "
        "--before-gt first --gt-order chain --unscoreable 2015 (2015's orientation error is "
        "orientation_error_2015)",
        flag="--2015",
        group=LEGACY,
    ),
    Input(
        "max_gap",
        "float",
        "a robot pose whose surrounding GT poses are further apart is in a GT gap "
        "(default 0.1 s; see --gaps)",
        default=0.1,
        unit="s",
        positive=True,
    ),
    Input(
        "t_max_diff",
        "float",
        "pair as evo does (`evo_ape ... --t_max_diff S`, evo's default 0.01; implies "
        "--association nearest): each pose of the shorter trajectory with the nearest stamp "
        "of the other within S seconds; --max-gap and the tracking-lost rule do not apply",
        unit="s",
        minimum=0.0,
    ),
    Input(
        "offset",
        "str",
        "shift the robot stamps by S seconds, or estimate the shift (auto)",
        default="0",
        metavar="S|auto",
    ),
    Input(
        "apply_offset",
        "flag",
        "with --offset auto: score with the estimated offset (else it is only reported)",
    ),
    Input(
        "offset_range",
        "float",
        "the clock audit searches offsets within +-S seconds (default 5)",
        default=5.0,
        unit="s",
        positive=True,
    ),
    Input(
        "allow_partial",
        "flag",
        "score the covered part when robot poses lie outside the GT",
    ),
    Input(
        "robot_time_source",
        "choice",
        "robot pose time: message stamp (default) or the robot bag's record time (the GT "
        "keeps --time-source)",
        old_flags=("--robot-time",),
        choices=("header", "record"),
    ),
    Input(
        "time_source",
        "choice",
        "the time robot and GT poses are selected and paired by: header stamps (default; "
        "simulation time in a sim bag, as evo uses) or record times",
        choices=("header", "record"),
    ),
    Input(
        "input_format",
        "choice",
        "read every input as this (default: detected by content): a TUM, KITTI (paired row "
        "by row, as evo_ape kitti), EuRoC ground-truth or ertools CSV text trajectory, or a "
        "bag",
        choices=INPUT_FORMATS,
    ),
    *INTERVAL_INPUTS,
)


def _2015_options() -> str:
    return " ".join(f"--{k.replace('_', '-')} {v}" for k, v in SETTINGS_2015.items())


def _offset(text: str) -> float | None:
    """Seconds, or None for ``auto``."""

    if text == "auto":
        return None
    try:
        value = float(text)
    except ValueError:
        raise UsageError(f"--offset takes seconds or 'auto', not {text!r}") from None
    if not (math.isfinite(value) and abs(value) < MAX_OFFSET_S):
        raise UsageError(
            f"--offset {text}: give a finite number smaller than {MAX_OFFSET_S:g} s in size "
            "or 'auto'"
        )
    return value


def make_options(given: Mapping[str, Any]) -> TrajectoryOptions:
    """The values of :data:`INPUTS` -> :class:`TrajectoryOptions`.

    Raises:
        UsageError: a value out of range, or options that contradict each other (exit 2).
    """
    v = resolve_values(INPUTS, given)
    offset = _offset(v["offset"])
    auto = offset is None
    if v["apply_offset"] and not auto:
        raise UsageError("--apply-offset needs --offset auto")
    chosen = {
        k: v[k] for k in ("association", "ties", "gaps", "before_gt", "gt_order", "unscoreable")
    }
    settings = {k: value for k, value in chosen.items() if value is not None}
    if v["as_2015"]:
        clash = [
            f"--{k.replace('_', '-')} {value}"
            for k, value in settings.items()
            if SETTINGS_2015[k] != value
        ]
        if clash:
            raise UsageError(f"--2015 sets {_2015_options()}; it cannot take {', '.join(clash)}")
        settings = dict(SETTINGS_2015)
    if v["t_max_diff"] is not None and "association" not in settings:
        settings["association"] = "nearest"  # evo's pairing is a nearest-stamp one
    if settings.get("ties") == "before" and settings.get("association") != "hold":
        raise UsageError("--ties before needs --association hold")
    try:
        config = TrajectoryConfig(
            **settings,
            max_gap_ns=s_to_ns(v["max_gap"]),
            offset_ns=0 if offset is None else s_to_ns(offset),
            auto_offset=auto,
            apply_offset=v["apply_offset"],
            offset_range_ns=s_to_ns(v["offset_range"]),
            allow_partial=v["allow_partial"],
            t_max_diff=v["t_max_diff"],
        )
    except ConfigError as err:
        raise UsageError(err.message) from None
    both = v["time_source"]
    robot_time = v["robot_time_source"]
    if both is not None and robot_time is not None and both != robot_time:
        raise UsageError(
            f"--time-source {both} sets the robot's time too: it cannot take "
            f"--robot-time-source {robot_time}"
        )
    return TrajectoryOptions(
        config,
        v["robot_topic"],
        v["gt_topic"],
        robot_time or both or "header",
        both or "header",
        v["input_format"],
        IntervalSettings.from_values(v),
    )


def files(bags: Sequence[Path], options: TrajectoryOptions, result: TrajectoryResult) -> list[Path]:
    """The robot log and the GT files a folder held (in evo's bag mode the robot log is also
    the GT file: listed once)."""
    return list(dict.fromkeys([Path(bags[0]), *map(Path, result.gt_files)]))


def sample(samples: Path) -> list[str] | None:
    """The sample robot log against the GT folder beside it, clock offset estimated and
    applied (``make demo``)."""
    folder = samples / "robotlog"
    robots = sorted(folder.glob("FBM2H_*.bag"))
    if not robots:
        return None
    return [str(robots[0]), str(folder), "--offset", "auto", "--apply-offset"]


def notes(result: TrajectoryResult) -> list[str]:
    """One stderr line per main statistic with its interval and the sources' shares."""
    m = result.metrics
    if m is None or result.uncertainty is None:
        return []
    iv = result.intervals
    rows = [
        ScoreRow("position_error", m.position_error, iv.get("position_error"), 1000.0, "mm"),
        ScoreRow("rmse", m.rmse, iv.get("rmse"), 1000.0, "mm"),
        ScoreRow("max", m.max, iv.get("max"), 1000.0, "mm"),
        ScoreRow("orientation_error", m.orientation_error, iv.get("orientation_error"), 1.0, "rad"),
    ]
    fit = result.fitted
    if fit is not None:
        # the score at the offset the data fits, beside the clock audit's warning
        fi = fit.intervals
        suffix = FITTED_SUFFIX
        rows += [
            ScoreRow(
                f"position_error{suffix}",
                fit.metrics.position_error,
                fi.get("position_error"),
                1000.0,
                "mm",
            ),
            ScoreRow(
                f"orientation_error{suffix}",
                fit.metrics.orientation_error,
                fi.get("orientation_error"),
                1.0,
                "rad",
            ),
        ]
    return interval_lines(rows, result.uncertainty)


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

BENCHMARK: Benchmark[TrajectoryOptions, TrajectoryLogs, None, TrajectoryResult] = Benchmark(
    name="trajectory",
    title="Offline trajectory benchmark",
    # the robot's own log: /rockin/<team>/marker_pose
    namespace="rockin",
    source_inputs=("robot_topic", "gt_topic"),
    summary="robot log vs mocap ground truth, with clock audit",
    example="ertools score trajectory robot.bag gt/ --robot-topic /rockin/homer/marker_pose",
    description="""Compare a robot's own pose log with the mocap ground truth (2015 offline
trajectory benchmark).

The GT files are picked from GT_PATH (bags or folders) by time overlap with the robot log and
read as one stream; without GT_PATH the GT topic is read from the robot log itself (evo's
`bag` mode). Every run also audits the clocks: it estimates the offset between the
robot's stamps and the GT clock and says when it matters.""",
    epilog=EPILOG,
    bags_help="the robot's log, then GT bags or folders of them (none: the GT topic is in "
    "ROBOT_BAG itself)",
    logs_may_be_text=True,
    inputs=INPUTS,
    make_options=make_options,
    load=load,
    find_runs=locate_runs,
    score_runs=score_found,
    ranking=Ranking(
        key=lambda r: None if r.metrics is None else r.metrics.position_error,
        lower_is_better=True,
        text="position_error (metres, the mean 3D distance to the GT): lower is better",
    ),
    figures="ertools.report.plots_trajectory:figure_specs",
    foxglove="ertools.report.foxglove.trajectory:content",
    files=files,
    bags_metavar=("ROBOT_BAG", "GT_PATH"),
    score_keys=frozenset({"position_error", "association"}),
    values_2015={"as_2015": True},
    sample=sample,
    notes=notes,
)
