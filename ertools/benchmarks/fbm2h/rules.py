"""Where FBM2@Home scoring differs from the 2015 node, each difference a
:class:`~ertools.fidelity.Rule` (the catalogue of :mod:`ertools.fidelity`: what the rulebook
says, what the node did, what ertools does and why, the option restoring 2015).
"""

from __future__ import annotations

from ertools.fidelity import Rule

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
