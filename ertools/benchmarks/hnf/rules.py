"""Where ertools' reading of HNF differs from the RSBB script, each difference a
:class:`~ertools.fidelity.Rule` (season 2019: ``differs from 2019: ...``), and the versions of
the script (docs/hnf.md; the version table of docs/fidelity.md).
"""

from __future__ import annotations

from ertools.fidelity import Rule
from ertools.node_versions import NodeVersion

SCRIPT = "fbm2_navigation.py (rockin-robot-challenge/rsbb 2bb8a41)"
FILE = "rsbb_bmbox/scripts/benchmark_scripts/fbm2_navigation.py"

RULE_ORIENTATION_WRAP = Rule(
    key="hnf.orientation-wrap",
    benchmark="hnf",
    title="orientation accuracy across +-pi",
    rulebook="the orientation error of the robot at each waypoint (ERL @Home rulebook, FBM2)",
    node_2015=(
        f"{SCRIPT} l. 194-203, 229: `sin(fabs(rp.theta - tp.theta))`, `cos(...)` of the "
        "unwrapped yaw difference summed, `atan2(fabs(sum_sin), sum_cos)`: a segment at -3.10 "
        "rad for a waypoint at 3.10 adds sin(6.20) = -0.083, cancelling other segments' errors"
    ),
    ertools=(
        "the yaw difference wrapped to [-pi, pi] before sin and cos (per segment the script's "
        "error is already the angle between the headings; the totals change)"
    ),
    option="--orientation-2019",
    season="2019",
)

RULE_DIVISOR = Rule(
    key="hnf.divisor",
    benchmark="hnf",
    title="the accuracies' divisor",
    rulebook="position accuracy: the mean distance to the waypoints reached",
    node_2015=(
        f"{SCRIPT} l. 130-133, 189-199, 228: every acquired pose's error summed (timed-out "
        "goals too), divided by the completed goals"
    ),
    ertools=(
        "the completed goals with a pose, their errors summed and divided by their number; "
        "a timed-out goal's error is listed in its segment, outside the accuracies"
    ),
    option="--divisor 2019",
    season="2019",
)

RULE_SKIPPED = Rule(
    key="hnf.skipped-waypoints",
    benchmark="hnf",
    title="a completed waypoint the referee skipped",
    rulebook="the accuracy of the waypoints reached",
    node_2015=(
        f"{SCRIPT} l. 133, 159-161: a completed goal whose pose the referee skipped ('s') "
        "counts in the divisor and adds no error: it lowers the mean"
    ),
    ertools="left out of the accuracies (nothing was measured), named in a warning",
    option="--divisor 2019",
    season="2019",
)

RULE_STOPPED = Rule(
    key="hnf.stopped-runs",
    benchmark="hnf",
    title="a run stopped before its last pose",
    rulebook="the benchmark ends at the last waypoint, the global timeout or the referee's stop",
    node_2015=(
        f"{SCRIPT} l. 149-180: a stop (or the global timeout) before the last pose was "
        "acquired returns from the script: the score has no totals"
    ),
    ertools=(
        "the totals over what was scored until the stop, the run said stopped in a warning "
        "(exit 1 when nothing was scored)"
    ),
    option="--rules 2019",
    season="2019",
)

RULE_GT_GAPS = Rule(
    key="hnf.gt-gaps",
    benchmark="hnf",
    title="a pose across a mocap gap",
    rulebook="the robot pose measured by the mocap",
    node_2015=(
        f"{SCRIPT} l. 143 (the helper): tf interpolates the marker set between the samples "
        "around the lookup's moment, however far apart (a body lost and seen again within the "
        "1 s wait)"
    ),
    ertools=(
        "no pose from samples more than --max-gap apart around the moment (default 0.1 s): "
        "the segment is not measured, said in a warning"
    ),
    option="--gt-gaps interpolate",
    season="2019",
)

RULE_SCORE_FORMAT = Rule(
    key="hnf.score-format",
    benchmark="hnf",
    title="target and robot poses in the score",
    rulebook="(layout only)",
    node_2015=(
        f"{SCRIPT} l. 183-184: `yaml.dump` of genpy Pose2D objects, a Python-tagged YAML "
        "document inside a string (`!!python/object/new:geometry_msgs.msg._Pose2D.Pose2D`)"
    ),
    ertools="`{x, y, theta}` mappings (null for a skipped pose)",
    option="--score-format 2019",
    season="2019",
)

VERSIONS = (
    NodeVersion(
        FILE,
        "069fd1d",
        "2017-11-02",
        "development (Enri2077/rsbb; no event evidenced)",
        "first RSBB version: the pose looked up (inline loop) until it succeeds; "
        "`atan2(sin, cos)` without `fabs`: negative errors beyond pi; poses written only "
        "when acquired; key `marker_to_robot_transform`",
        "`--rules 069fd1d`",
    ),
    NodeVersion(
        FILE,
        "f594ff1",
        "2017-11-04",
        "development (Enri2077/rsbb)",
        "the lookup helper (1 s attempts, no limit); `fabs` in the per-segment and total "
        "orientation; both poses always written (None when stopped); a stopped run has "
        "totals",
        "`--rules f594ff1`",
    ),
    NodeVersion(
        FILE,
        "e4769fe",
        "2017-11-07",
        "development (Enri2077/rsbb)",
        "a log message only",
        "`--rules f594ff1`",
    ),
    NodeVersion(
        FILE,
        "00e3106",
        "2017-12-15",
        "ERL @Home 2017-18 (an event in Portugal, week of 14 December 2017)",
        "5 attempts, then the referee's 'try again or skip' (`s`); `manual_operation` field; "
        "a stop during the lookup ends the script (no totals); key "
        "`markerset_to_robot_transform`",
        "`--rules 2017`",
    ),
    NodeVersion(
        FILE,
        "2bb8a41",
        "2019-04-08",
        "ERL @Home 2018-19",
        "the `manual_operation` field removed; the live score's text with a `SCORE SUMMARY`",
        "`--rules 2019`",
    ),
)

# what the registry carries (declare passes it as ``rules=``), in definition order
RULES = (
    RULE_ORIENTATION_WRAP,
    RULE_DIVISOR,
    RULE_SKIPPED,
    RULE_STOPPED,
    RULE_GT_GAPS,
    RULE_SCORE_FORMAT,
)
