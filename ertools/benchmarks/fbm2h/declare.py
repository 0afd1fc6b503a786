"""FBM2@Home as the registry sees it: its inputs (the options of ``ertools score fbm2h``, the
manifest keys), how they become :class:`Fbm2hOptions`, and the load -> reached moments ->
score stages.
"""

from __future__ import annotations

import logging
from collections.abc import Mapping, Sequence
from dataclasses import replace
from pathlib import Path
from typing import Any

from ertools.benchmarks.base import (
    Benchmark,
    Explanation,
    FormerName,
    Input,
    Ranking,
    resolve_values,
    tf_value,
)
from ertools.benchmarks.common.ending import EXACT_HELP
from ertools.benchmarks.common.uncertainty import INTERVAL_INPUTS, check_confidence
from ertools.benchmarks.common.validity import SCORE_AS_2015, unscoreable_input
from ertools.benchmarks.fbm2h.benchmark import score_found
from ertools.benchmarks.fbm2h.config import DEFAULT_MAX_GAP_S, NODES, RULE_SETS, Fbm2hOptions
from ertools.benchmarks.fbm2h.logs import Fbm2hLogs, Fbm2hRuns, load, locate_runs
from ertools.benchmarks.fbm2h.result import Fbm2hResult
from ertools.benchmarks.fbm2h.segments import StopParams
from ertools.configs.transform import LIVE_TRANSFORM_KEY, live_transform
from ertools.errors import UsageError

NAME = "fbm2h"
LEGACY = "2015 behaviour (each difference can be undone)"
AUTO = "--reached auto (stop detection)"

INPUTS = (
    Input("goal", "path", "goal list (Listing 10); default: from the log", metavar="FILE"),
    Input(
        "transform",
        "path",
        "marker-to-robot transform (Listing 11)",
        metavar="FILE",
        per_team=True,  # each team's robot carries its own marker set
        # A log the GT logger wrote alone (a test run, reached moments from a timing file or
        # stop detection) is scored as `ertools score` scores it: the identity, with a warning.
        needed_unless=(("reached", ("timing", "auto")),),
    ),
    Input("transforms", "path", "folder of transform-<team>.yaml files", metavar="DIR"),
    Input(
        "team",
        "str",
        "the team that ran it, kept in the result and report (default: a name in the state "
        "payloads, else the log name, else the transform's team); with --transforms DIR: "
        "DIR/transform-NAME.yaml",
        metavar="NAME",
        per_team=True,
    ),
    Input(
        "topic",
        "str",
        "marker set pose topic, any pose type (default /fbm2h/robot_at_home/pose)",
        metavar="TOPIC",
    ),
    Input(
        "tf",
        "str",
        "take the marker set from /tf PARENT -> CHILD instead (e.g. world:robot_at_home)",
        metavar="PARENT:CHILD",
        old_flags=("--tf-frame", "--frame"),
    ),
    Input(
        "time_source",
        "choice",
        "pose time: header stamp (mocap time, default) or bag record time",
        default="header",
        choices=("header", "record"),
    ),
    Input(
        "reached",
        "choice",
        "states | timing FILE | auto (default: states when the log has them)",
        choices=("states", "timing", "auto"),
        with_file=("timing",),
        metavar="MODE",
    ),
    Input(
        "gt_tolerance",
        "float",
        "a reached moment needs a GT sample within S seconds (default 0.1)",
        old_flags=("--max-gap",),
        default=DEFAULT_MAX_GAP_S,
        unit="s",
        positive=True,
    ),
    Input("hits", "int", "the referee's count of hits", minimum=0, metavar="N"),
    Input(
        "orientation_2015",
        "flag",
        "orientation errors as 2015 computed them (unwrapped |dtheta|; wrong across +-pi)",
        group=LEGACY,
    ),
    Input(
        "unscored_segments",
        "choice",
        "segments not scored (RefBox timeout, never reached): null accuracies and exit 1 "
        "(default), or 2015: sums over the scored segments divided by N, the timed-out "
        "segment's time counted",
        default="null",
        choices=("null", "2015"),
        group=LEGACY,
    ),
    Input(
        "segment_clock",
        "choice",
        "segment times with --reached states: client (default: from the BmBox EXECUTING_GOAL to "
        "the Client's COMPLETED_GOAL, the robot's own report) or bmbox (2015: the node's "
        "clock, BmBox state messages at both ends; the pose is taken at the end)",
        default="client",
        choices=("client", "bmbox"),
        group=LEGACY,
    ),
    Input("exact_end_payloads", "flag", EXACT_HELP, group=LEGACY),
    # a segment is unscoreable when the only ground truth within --gt-tolerance of its
    # reached moment is invalid (repeated poses of a lost marker set)
    unscoreable_input(LEGACY, FormerName("unscoreable_segments")),
    Input(
        "rules",
        "choice",
        "every behaviour of one node at once (--orientation-2015 --unscored-segments 2015 "
        "--unscoreable 2015 --segment-clock bmbox --exact-end-payloads, and the node's pose "
        "source, /tf world -> robot_at_home, unless --topic or --tf is given): 2015 "
        "(scripts/fbm2h 50b173b, RoCKIn 2015 Lisbon), 2016 (40ba68b, Lisbon 2016), 2017 "
        "(89dfa75, Lisbon 2017): one file, the same numbers; ertools (default): the options "
        "above decide",
        choices=RULE_SETS,
        group=LEGACY,
    ),
    Input("all_2015", "flag", "= --rules 2015", flag="--2015", group=LEGACY),
    Input("namespace", "str", "benchmark namespace of the state topics", default=NAME),
    Input(
        "stop_speed",
        "float",
        "a stop: the marker set slower than this (default 0.05 m/s)",
        default=0.05,
        unit="m/s",
        positive=True,
        metavar="M_S",
        group=AUTO,
    ),
    Input(
        "stop_yaw_rate",
        "float",
        "a stop: turning slower than this (default 0.1 rad/s)",
        default=0.1,
        unit="rad/s",
        positive=True,
        metavar="RAD_S",
        group=AUTO,
    ),
    Input(
        "stop_min",
        "float",
        "a stop: both for at least this long (default 0.5 s)",
        old_flags=("--stop-min-duration",),
        default=0.5,
        unit="s",
        positive=True,
        group=AUTO,
    ),
    Input(
        "stop_radius",
        "float",
        "a stop counts for a waypoint only this close to it (default 0.5 m)",
        default=0.5,
        unit="m",
        positive=True,
        group=AUTO,
    ),
    *INTERVAL_INPUTS,
)


def make_options(given: Mapping[str, Any]) -> Fbm2hOptions:
    """The values of :data:`INPUTS` -> :class:`Fbm2hOptions`.

    Raises:
        UsageError: a value out of range, or options that exclude each other (exit 2).
    """
    v = resolve_values(INPUTS, given)
    if v["topic"] is not None and v["tf"] is not None:
        raise UsageError("give either --topic or --tf, not both")
    tf = tf_value("--tf", v["tf"])
    if v["transform"] is not None and v["transforms"] is not None:
        raise UsageError("give either --transform FILE or --team NAME --transforms DIR")
    if v["transforms"] is not None and v["team"] is None:
        raise UsageError("--transforms DIR needs --team NAME (DIR/transform-NAME.yaml)")
    reached: tuple[str | None, ...] = v["reached"] or (None,)
    chosen = {v["rules"]} - {None} | ({"2015"} if v["all_2015"] else set())
    if len(chosen) > 1:
        raise UsageError(f"--rules/--2015 name {len(chosen)} nodes; give one")
    rules = chosen.pop() if chosen else "ertools"
    node = rules != "ertools"
    return Fbm2hOptions(
        goal=v["goal"],
        transform=v["transform"],
        team=v["team"],
        transforms_dir=v["transforms"],
        topic=v["topic"],
        tf_frame=None if tf is None else tf[1],
        tf_parent="world" if tf is None else tf[0],
        time_source=v["time_source"],
        reached=reached[0],
        timing=Path(str(reached[1])) if len(reached) > 1 else None,
        max_gap_s=v["gt_tolerance"],
        hits=None if v["hits"] is None else int(v["hits"]),
        orientation_2015=v["orientation_2015"] or node,
        unscored_2015=v["unscored_segments"] == "2015" or node,
        segment_clock="bmbox" if node else v["segment_clock"],
        pose_2015=node,
        exact_end_payloads=bool(v["exact_end_payloads"] or node),
        namespace=v["namespace"],
        unscoreable_2015=v["unscoreable"] == SCORE_AS_2015 or node,
        rules=rules,
        stops=StopParams(
            speed=v["stop_speed"],
            yaw_rate=v["stop_yaw_rate"],
            min_duration_s=v["stop_min"],
            radius=v["stop_radius"],
        ),
        confidence=check_confidence(v["confidence"]),
        draws=v["draws"],
        seed=v["seed"],
    )


def notes(result: Fbm2hResult) -> list[str]:
    """The score intervals, how the reached moments were found (with ``-v``) and the
    per-segment table."""
    out = result.interval_lines()
    rules = dict(result.provenance.parameters).get("rules", "ertools")
    if rules in NODES:
        out.append(f"reproducing: {NODES[rules]}")
    if logging.getLogger("ertools").isEnabledFor(logging.INFO):  # -v
        out += list(result.notes)
    out.append(
        f"reached moments: {result.reached_method}; transform: {result.transform.described}; "
        + (
            f"goal: {result.goal.source} ({result.goal.layout} layout); "
            if result.goal.layout != "listing-10"
            else ""
        )
        + "times from the log's first message"
    )
    n = len(result.segments)
    scored = sum(s.status == "ok" for s in result.segments)
    if result.position_accuracy is None:
        averaged = "none (a segment is not scored: see the warnings)"
    elif result.unscored_2015:
        averaged = f"sum over the {scored} scored segment(s) / N = {n} (2015)"
    else:
        averaged = f"mean over all {n} segments"
    out.append(f"accuracies: {averaged}")
    values = ("reached_s", "segment_time_s", "distance_error_m", "orientation_error_rad")
    for row in result.tables()["segments"]:
        if row["status"] != "ok" or any(row[k] is None for k in values):
            out.append(f"  segment {row['segment']}: {row['status']}")
            continue
        out.append(
            f"  segment {row['segment']}: reached {row['reached_s']:.3f} s, "
            f"time {row['segment_time_s']:.3f} s, distance {row['distance_error_m']:.4f} m, "
            f"orientation {row['orientation_error_rad']:.4f} rad"
        )
    return out


TIMING_SUFFIX = "_reached_waypoint_timing.yaml"


def gt_only(bags: Sequence[Path]) -> dict[str, Any] | str:
    """A GT-only FBM2@Home log (no state topics) is an execution when the 2015 reached-waypoint
    timing file lies beside it (``<log stem>_reached_waypoint_timing.yaml``, as the 2015 test
    logs ship): ``reached: [timing, FILE]``."""
    first = bags[0]
    stem = first.name.removesuffix(".active").removesuffix(".bag")
    timing = first.with_name(stem + TIMING_SUFFIX)
    if timing.is_file():
        return {"reached": ("timing", timing)}
    return (
        "the GT logger's FBM2@Home log alone: no state topics and no "
        f"{timing.name} beside it, so nothing says when each waypoint was reached (list it "
        "under executions: with reached: auto or [timing, FILE] to score it)"
    )


def sample(samples: Path) -> list[str] | None:
    """The FBM2@Home sample log with its goal list and transform (``make demo``)."""
    folder = samples / NAME
    bags = sorted(folder.glob("*.bag"))
    goals = sorted(folder.glob("*goal*.yaml"))
    transforms = sorted(folder.glob("transform-*.yaml"))
    if not (bags and goals and transforms):
        return None
    return [str(bags[0]), "--goal", str(goals[0]), "--transform", str(transforms[0])]


def from_live(options: Fbm2hOptions, live: Any) -> tuple[Fbm2hOptions, tuple[str, ...]]:
    """The audit's options: without ``--transform``/``--transforms``, the transform the live
    score says the node used, and a note saying so (``--team`` alone picks no transform)."""
    if options.transform is not None or options.transforms_dir is not None:
        return options, ()
    found = live_transform(live)
    if found is None:
        return options, ()
    t = ", ".join(f"{v:g}" for v in found.translation)
    q = ", ".join(f"{v:.6g}" for v in found.quat_xyzw)
    return replace(options, marker_transform=found), (
        f"transform taken from the live score (details.{LIVE_TRANSFORM_KEY}: [[{t}], [{q}]]); "
        "give --transform or --team/--transforms to use another",
    )


# Why an audit's recomputed value may differ from the live one.
EXPLANATIONS = (
    Explanation(
        r"orientation_(error|accuracy)$",
        "the 2015 node took sin and cos of the unwrapped |robot yaw - target yaw|; ertools "
        "wraps the difference to [-pi, pi] first (identical unless the difference crosses "
        "+-pi); the robot pose also depends on the marker-to-robot transform",
        ("transform", "source", "topic", "reached"),
    ),
    Explanation(
        r"(dinstance_error|distance_error|position_accuracy|position_error|robot_pose)$",
        "the live node used the latest mocap pose when the result arrived; ertools "
        "interpolates the logged ground truth at the logged moment the waypoint was reached "
        "and applies the marker-to-robot transform as a full SE(3) composition",
        ("transform", "source", "topic", "reached", "max_gap", "association"),
    ),
)


EPILOG = """examples:
  ertools score fbm2h run.bag --team homer --transforms transforms/
  ertools score fbm2h run.bag --goal configs/fbm2h.yaml --transform transform-homer.yaml
  ertools score fbm2h log.bag --goal goal.yaml --transform configs/transform-identity.yaml \\
      --reached timing log_reached_waypoint_timing.yaml
  ertools score fbm2h log.bag --goal goal.yaml --reached auto --format json

--reached: states (default when the bag has /fbm2h/bmbox_state): segment i starts when the
BmBox has sent the goal and ends at the Client's COMPLETED_GOAL; timing FILE: a reached-waypoint
timing file (p0 starts, p(k+1) closes segment k, seconds from the bag's first message); auto:
stops detected in the ground truth, assigned to the waypoints in order.
Orientation errors are wrapped to [0, pi]; --orientation-2015 reproduces the 2015 numbers.
Accuracies are null (exit 1) when a segment is not scored (RefBox timeout or stop, or a log
that ends inside the benchmark, taken as stopped there); --unscored-segments 2015 scores the
segment cut short where the node's wait returned and divides the sums by N as 2015 did.
--segment-clock bmbox times segments between the BmBox's own transitions as the node did.
--2015 (= --rules 2015: scripts/fbm2h at 50b173b, RoCKIn 2015; --rules 2016 and 2017 name the
same file at 40ba68b and 89dfa75): every 2015 behaviour at once, with the node's pose source
(/tf world -> robot_at_home)."""

BENCHMARK: Benchmark[Fbm2hOptions, Fbm2hLogs, Fbm2hRuns, Fbm2hResult] = Benchmark(
    name=NAME,
    title="FBM2@Home",
    summary="FBM2@Home navigation: waypoint errors",
    example="ertools score fbm2h run.bag --goal goal.yaml --transform transform-homer.yaml",
    description="""Recompute an FBM2@Home (navigation) score from the logs (seed 7.2, Listing 13).

Per waypoint: the robot pose when it was reached (ground-truth marker pose interpolated at that
moment, composed with the team's marker-to-robot transform), its distance and orientation
error, the segment time; then position_accuracy, orientation_accuracy and execution_time.""",
    epilog=EPILOG,
    inputs=INPUTS,
    make_options=make_options,
    load=load,
    find_runs=locate_runs,
    score_runs=score_found,
    ranking=Ranking(
        key=lambda r: r.position_accuracy,
        lower_is_better=True,
        text="position_accuracy (metres, the mean distance to the waypoints): lower is better",
    ),
    notes=notes,
    figures="ertools.report.plots_fbm2h:figure_specs",
    foxglove="ertools.report.foxglove.fbm2h:content",
    score_keys=frozenset({"position_accuracy", "orientation_accuracy"}),
    state_topics=True,
    values_2015={"all_2015": True},
    sample=sample,
    from_live=from_live,
    explanations=EXPLANATIONS,
    gt_only=gt_only,
)
