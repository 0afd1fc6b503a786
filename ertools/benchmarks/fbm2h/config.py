"""FBM2@Home's inputs (the options of ``ertools score fbm2h``, the manifest keys), its
defaults and how the inputs become :class:`Fbm2hOptions` (:func:`make_options`, every check
once). NumPy-free: the command's parser imports it.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ertools.benchmarks.base import FormerName, Input, resolve_values, tf_value
from ertools.benchmarks.common.inputs import (
    DEFAULT_CONFIDENCE,
    DEFAULT_DRAWS,
    DEFAULT_SEED,
    EXACT_HELP,
    INTERVAL_INPUTS,
    SCORE_AS_2015,
    check_confidence,
    unscoreable_input,
)
from ertools.errors import UsageError
from ertools.frozen_dataclass import frozen_dataclass

if TYPE_CHECKING:  # annotations only: the transform's module is NumPy
    from ertools.configs.transform import MarkerTransform

NAMESPACE = "fbm2h"  # of the state topics
DEFAULT_TOPIC = "/fbm2h/robot_at_home/pose"
# The 2015 node looked the marker set up in tf (scripts/fbm2h): world -> robot_at_home.
TF_2015 = ("world", "robot_at_home")
DEFAULT_MAX_GAP_S = 0.1


# The nodes ``--rules`` reproduces: rockin-robot-challenge/benchmark_and_scoring_fbm
# scripts/fbm2h, read at each commit (the version table of docs/fidelity.md). One file (blob
# 9abe295) served the three competitions: the names say which one a score reproduces.
NODES = {
    "2015": "scripts/fbm2h at 50b173b (RoCKIn 2015 Lisbon; 0e7a367's arithmetic)",
    "2016": "scripts/fbm2h at 40ba68b (the Lisbon 2016 second local competition; = 50b173b)",
    "2017": "scripts/fbm2h at 89dfa75 (the Lisbon 2017 major tournament; = 50b173b)",
}
RULE_SETS = ("ertools", *NODES)


@frozen_dataclass
class StopParams:
    """Thresholds of the ``auto`` stop detector.

    Attributes:
        speed: m/s; the robot counts as stopped below it (mocap jitter on a still marker set
            gives ~1 mm over the window, i.e. a few mm/s; the 2015 test robot crept at a few
            cm/s while "standing" at its waypoints).
        yaw_rate: rad/s; also required, so a robot turning on the spot is not "stopped".
        min_duration_s: a stop lasts at least this long (the 2015 robot paused 0.7 to 3 s).
        window_s: speeds are displacements over this window (per-sample differences of 120 Hz
            mocap are dominated by jitter).
        radius: metres; a stop is assigned to a waypoint only if it lies this close to it.
    """

    speed: float = 0.05
    yaw_rate: float = 0.1
    min_duration_s: float = 0.5
    window_s: float = 0.5
    radius: float = 0.5


@frozen_dataclass
class Fbm2hOptions:
    """Everything ``ertools score fbm2h`` can be told.

    Attributes:
        goal: Listing 10 goal list file; None = the goal payload in the state topics.
        transform: Listing 11 file; None with ``team``+``transforms_dir`` = DIR/transform-TEAM.yaml;
            None otherwise = identity (said in the warnings).
        team: picks the transform with ``transforms_dir``; alone it changes nothing here (the
            CLI keeps it as the result's team, see :mod:`ertools.benchmarks.common.teams`).
        topic / tf_frame: where the marker set's poses are (PoseStamped/Pose2D topic, or a /tf
            child frame of ``world``).
        time_source: ``header`` (mocap stamp) or ``record`` (bag time).
        reached: ``states``, ``timing``, ``auto`` or None (states when present).
        timing: the timing file for ``reached == "timing"``.
        max_gap_s: a reached moment needs a GT sample this close.
        hits: the referee's count of hits.
        orientation_2015: compute orientation errors as 2015 did (unwrapped).
        unscored_2015: accuracies as 2015 computed them when segments are not scored: the
            sums over the scored segments divided by N (the waypoints), the segment the RefBox
            timed out counted in execution_time (``--unscored-segments 2015``).
        segment_clock: with ``reached`` states, ``client`` (a segment ends at the Client's
            COMPLETED_GOAL) or ``bmbox`` (the 2015 node's clock: BmBox messages at both ends,
            ``--segment-clock bmbox``); see :func:`ertools.benchmarks.fbm2h.runs.from_states`.
        unscoreable_2015: a reached moment whose only ground truth within ``max_gap_s`` is
            invalid (repeated poses of a lost marker set) is scored from it as 2015 did, with a
            warning (``--unscoreable 2015``); by default the segment has no GT.
        pose_2015: with no ``topic``/``tf_frame``, read the marker set from /tf
            ``world -> robot_at_home`` first, the 2015 node's source (``--2015``).
        exact_end_payloads: RefBox END payloads read as the 2015 BmBox did (only
            ``reason: timeout`` / ``reason: stop``; :func:`ertools.states.end_reason`).
        namespace: the benchmark namespace of the state topics.
        stops: thresholds for ``auto``.
        confidence, draws, seed: the score intervals (level, Monte Carlo draws, 0 for none;
            seed), :mod:`ertools.benchmarks.fbm2h.intervals`.
        marker_transform: a transform already in hand (``ertools audit``: the one the live
            score says the node used); None = from ``transform``/``team``, else identity.
        rules: the node every 2015 behaviour reproduces (``2015``, ``2016``, ``2017``: keys
            of :data:`NODES`), or ``ertools`` (the single options decide).
    """

    goal: Path | None = None
    transform: Path | None = None
    team: str | None = None
    transforms_dir: Path | None = None
    topic: str | None = None
    tf_frame: str | None = None
    tf_parent: str = "world"
    time_source: str = "header"
    reached: str | None = None
    timing: Path | None = None
    max_gap_s: float = DEFAULT_MAX_GAP_S
    hits: int | None = None
    orientation_2015: bool = False
    unscored_2015: bool = False
    segment_clock: str = "client"
    pose_2015: bool = False
    exact_end_payloads: bool = False
    namespace: str = NAMESPACE
    unscoreable_2015: bool = False
    stops: StopParams = field(default_factory=StopParams)
    marker_transform: MarkerTransform | None = None
    confidence: float = DEFAULT_CONFIDENCE
    draws: int = DEFAULT_DRAWS
    seed: int = DEFAULT_SEED
    rules: str = "ertools"


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
    Input("namespace", "str", "benchmark namespace of the state topics", default=NAMESPACE),
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
