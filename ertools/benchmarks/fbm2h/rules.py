"""Where FBM2@Home scoring differs from the 2015 node, each difference a
:class:`~ertools.fidelity.Rule` (the catalogue of :mod:`ertools.fidelity`: what the rulebook
says, what the node did, what ertools does and why, the option restoring 2015).
"""

from __future__ import annotations

from ertools.fidelity import Rule
from ertools.node_versions import NodeVersion

NODE_SOURCE = "scripts/fbm2h (50b173b, RoCKIn 2015; unchanged in 2016-17)"

# The catalogue rows (ertools.fidelity) of every way FBM2@Home differs from the 2015 node.
RULE_ORIENTATION_WRAP = Rule(
    key="fbm2h.orientation-wrap",
    benchmark="fbm2h",
    title="orientation error across +-pi",
    rulebook="orientation error of the robot pose at each waypoint (RoCKIn@Home rulebook 5.2.7)",
    node_2015=(
        f"{NODE_SOURCE}: `sin(fabs(rp.theta - tp.theta))` and `cos(...)` of the unwrapped yaw "
        "difference: a robot at -3.07 rad for theta = pi scored -0.073 rad"
    ),
    ertools="the yaw difference wrapped to [0, pi] before sin/cos (the angle between headings)",
    option="--orientation-2015",
)

RULE_SEGMENT_CLOCK = Rule(
    key="fbm2h.segment-clock",
    benchmark="fbm2h",
    title="segment times and the reached moment",
    rulebook="the time the robot takes from one waypoint to the next; the robot pose when it "
    "reaches the waypoint (seed 7.2.1, Listing 13 segment_time)",
    node_2015=(
        f"{NODE_SOURCE}: `start_segment_time = time.time()` after `SendGoal()` returned and "
        "`end_segment_time = time.time()` after `WaitResult()` returned, the BmBox's own "
        "transitions (out of TRANSMITTING_GOAL; out of WAITING_RESULT), the pose looked up then"
    ),
    ertools=(
        "from the BmBox EXECUTING_GOAL to the Client's COMPLETED_GOAL, the robot's own report "
        "of arrival, the pose taken at it: the BmBox moves on only once it has received that "
        "report, up to one 10 Hz publishing period later in the log"
    ),
    option="--segment-clock bmbox",
)

RULE_POSE_SOURCE = Rule(
    key="fbm2h.pose-source",
    benchmark="fbm2h",
    title="marker set pose source",
    rulebook="the robot's marker set tracked by the mocap (seed 7.2.1)",
    node_2015=f"{NODE_SOURCE}: `lookupTransform('/world', '/robot_at_home', ...)` from /tf",
    ertools=(
        "the pose topic /fbm2h/robot_at_home/pose (the same mocap poses, stamped a few "
        "microseconds before their /tf copies), /tf when asked"
    ),
    option="--tf world:robot_at_home",
)

RULE_POSE_MOMENT = Rule(
    key="fbm2h.pose-moment",
    benchmark="fbm2h",
    title="robot pose moment",
    rulebook="the robot pose when it reaches the waypoint (seed 7.2.1)",
    node_2015=(
        f"{NODE_SOURCE}: tf `world -> actual_robot` at the ROS time `now` the node took just after "
        "`WaitResult()` returned, a few ms after the result"
    ),
    ertools=(
        "the marker pose interpolated (linear + SLERP, as tf) at the logged reached moment "
        "(with --segment-clock bmbox the BmBox message after WAITING_RESULT, the closest the "
        "log gets to `now`); no option: the moment the node handled the result is not in the log"
    ),
    option="",
)

RULE_UNSCORED = Rule(
    key="fbm2h.unscored-segments",
    benchmark="fbm2h",
    title="segments not scored",
    rulebook="accuracy over the waypoints reached; a waypoint not reached in time scores no "
    "points on that path (seed 7.2, RoCKIn@Home rulebook 5.2.7)",
    node_2015=(
        f"{NODE_SOURCE}: every segment whose `WaitResult()` returned is scored there, whatever "
        "ended it: the stop check is commented out (l. 175-179) and `if benchmark.Timeout(): "
        "timeouts = timeouts + 1` (l. 168-173) only counts a RefBox timeout in "
        "timeout_segments; `while benchmark.Running() and not benchmark.Timeout()` (l. 97) "
        "then ends the loop; `position_accuracy = sum_d / N` (l. 225), N = the number of "
        "waypoints: a segment never sent adds 0 to the sums but counts in N (since 97be032; "
        "before it a timed-out segment added its time and no error, a stopped one nothing)"
    ),
    ertools=(
        "the segment a RefBox timeout or stop (or the log's end) cut short and the segments "
        "never reached listed with null errors and named in a warning, accuracies null and "
        "exit 1 (a robot stopped on its way was not at the waypoint, and a sum over fewer "
        "segments divided by N rewards reaching fewer waypoints); execution_time and the "
        "scored segments still given; a log that ends inside the benchmark is the benchmark "
        "stopped there"
    ),
    option="--unscored-segments 2015",
)

RULE_SCORE_FORMAT = Rule(
    key="fbm2h.score-format",
    benchmark="fbm2h",
    title="score layout",
    rulebook="Listing 13: segments_details under details, poses per segment",
    node_2015=(
        f"{NODE_SOURCE}: `yaml.dump` of segments_details at the top level, poses as dumps of "
        "Pose2D objects, times from the BmBox machine's time.time()"
    ),
    ertools=(
        "Listing 13 nesting, poses as {x, y, theta}, times from the log's clock; no option: "
        "the numbers are the same, only the layout differs"
    ),
    option="",
)

# The versions of scripts/fbm2h since its rewrite (rows of the version table,
# ertools.node_versions.NodeVersion); the RoCKIn Camp 2015 node before it became old_fbm2h
# (a59151c).
_F = "scripts/fbm2h"
_DEV = "not restorable: a development version, run in no competition"
VERSIONS = (
    NodeVersion(
        _F,
        "198dbed",
        "2015-10-23",
        "development",
        "a new node: the pose the last /fbm2h/robot_at_home/pose2d message; segments 1 to "
        "N = waypoints - 1 (waypoint 0 the start); a RefBox timeout: the segment's time, no "
        "error; a stop: nothing; a Client `result` other than i skips the segment; "
        "segment_time > penalty_time counted, > timeout_time: its time, no error",
        _DEV,
    ),
    NodeVersion(
        _F,
        "723c68e",
        "2015-10-25",
        "development",
        "the marker pose from tf at `now` after the result, no marker-to-robot transform (a "
        "failed lookup kept the previous pose)",
        _DEV,
    ),
    NodeVersion(_F, "d7e3ef5", "2015-10-25", "development", "none (a comment)", _DEV),
    NodeVersion(_F, "117a5d0", "2015-10-26", "development", "none (an unused lookup added)", _DEV),
    NodeVersion(_F, "8acb18d", "2015-10-26", "development", "none", _DEV),
    NodeVersion(
        _F,
        "0852153",
        "2015-10-27",
        "development",
        "a 2D marker-to-robot offset measured at waypoint 0 added to the marker's latest tf "
        "pose (`Time(0)`)",
        _DEV,
    ),
    NodeVersion(
        _F,
        "224722f",
        "2015-10-27",
        "development",
        "the marker-to-robot transform measured through tf at the start; the robot pose tf "
        "world -> actual_robot at `now`",
        _DEV,
    ),
    NodeVersion(_F, "5f82023", "2015-10-27", "development", "none (a comment)", _DEV),
    NodeVersion(_F, "59e9fd8", "2015-10-28", "development", "none (a comment)", _DEV),
    NodeVersion(
        _F,
        "2fd8452",
        "2015-10-29",
        "development",
        "the pose lookup retried until it succeeds, at `Time(0)` (the broadcast's `now`)",
        _DEV,
    ),
    NodeVersion(
        _F,
        "d2b22bf",
        "2015-10-29",
        "development",
        "N = the number of waypoints, segments from 0 (the starting pose apart); a `result` "
        "other than i no longer skips the segment",
        _DEV,
    ),
    NodeVersion(
        _F,
        "fe85324",
        "2015-10-30",
        "development",
        "the start's transform measurement retried until it succeeds",
        _DEV,
    ),
    NodeVersion(_F, "4470d9e", "2015-10-30", "development", "none (comments)", _DEV),
    NodeVersion(
        _F, "a0557f0", "2015-11-04", "development", "none (no ENTER before the start)", _DEV
    ),
    NodeVersion(
        _F,
        "97be032",
        "2015-11-05",
        "development",
        "every segment whose WaitResult() returned is scored there: a RefBox timeout's too, "
        "counted in timeout_segments, and a stop's (its check commented out); the "
        "penalty_time and timeout_time rules dropped",
        _DEV,
    ),
    NodeVersion(
        _F,
        "709ab28",
        "2015-11-05",
        "development",
        "the Client's payload no longer parsed (one without `reached_waypoint` ended the node)",
        _DEV,
    ),
    NodeVersion(
        _F,
        "0e7a367",
        "2015-11-20",
        "RoCKIn 2015 Lisbon, from competition day one (its commit)",
        "the marker-to-robot transform read from the team's transform file (Listing 11), no "
        "longer measured at the starting pose",
        "`--rules 2015` (the same arithmetic; 50b173b differs only where a tf lookup timed out)",
    ),
    NodeVersion(
        _F,
        "50b173b",
        "2015-11-30",
        "RoCKIn 2015 Lisbon (its final state)",
        "a tf lookup that timed out (no mocap) retried, no longer ending the node",
        "`--rules 2015` (`--2015`)",
    ),
    NodeVersion(
        _F,
        "40ba68b",
        "2017-01-26",
        "Lisbon 2016 second local competition",
        "none: 50b173b's file (blob 9abe295)",
        "`--rules 2016` (= `--rules 2015`)",
    ),
    NodeVersion(
        _F,
        "89dfa75",
        "2017-11-10",
        "Lisbon 2017 major tournament",
        "none: 50b173b's file; only config/fbm2h.yaml's waypoints changed (the goal comes from "
        "the log's goal payload or --goal)",
        "`--rules 2017` (= `--rules 2015`)",
    ),
)

# Every rule above, in the catalogue's order (the benchmark's ``rules``).
RULES = (
    RULE_ORIENTATION_WRAP,
    RULE_SEGMENT_CLOCK,
    RULE_POSE_SOURCE,
    RULE_POSE_MOMENT,
    RULE_UNSCORED,
    RULE_SCORE_FORMAT,
)
