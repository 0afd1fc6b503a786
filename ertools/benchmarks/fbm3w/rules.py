"""Where FBM3@Work scoring differs from the 2015 node, each difference a
:class:`~ertools.fidelity.Rule` (the catalogue of :mod:`ertools.fidelity`: what the rulebook
says, what the node did, what ertools does and why, the option restoring 2015).
"""

from __future__ import annotations

from ertools.benchmarks.fbm3w.config import DEFAULT_FRAME, DEFAULT_TOPIC, FALLBACK_TOPIC
from ertools.fidelity import Rule
from ertools.node_versions import NodeVersion

NODE_SOURCE = "scripts/fbm3w (50b173b, RoCKIn 2015)"

# The catalogue rows (ertools.fidelity) of every way FBM3@Work differs from the 2015 node.
RULE_TIMEOUT_RUNS = Rule(
    key="fbm3w.timeout-runs",
    benchmark="fbm3w",
    title="timed-out runs",
    rulebook="the RefBox ends a benchmark with END and payload timeout (seed 6.2.3); seed 7.3 "
    "does not say how such a run is scored",
    node_2015=(
        f'{NODE_SOURCE}: `if benchmark.Timeout(): print "TIMEOUT"` only (l. 234-237, the time '
        "and `continue` commented out by 7942ea2): a timed-out run is timed, scored on the path "
        "it covered, eligible as best run, and the loop goes on with the next run (before "
        "7942ea2: its time added, no score, the same run number again)"
    ),
    ertools=(
        "listed with its time and no distance_error, never the best run: a partial path "
        "compared with the whole target at l/L says nothing about following it"
    ),
    option="--timeout-runs 2015",
)

RULE_STOPPED_RUNS = Rule(
    key="fbm3w.stopped-runs",
    benchmark="fbm3w",
    title="stopped runs' time",
    rulebook="the RefBox ends a benchmark with END and payload halt (seed 6.2.3)",
    node_2015=(
        f"{NODE_SOURCE}: `if not benchmark.Running(): continue` (l. 239-241) comes before the "
        "time is added: a run stopped by `reason: stop` (BmBox.py `Running()`) was aborted, no "
        "score and no time, and the loop ended"
    ),
    ertools=(
        "no score, its time counted in execution_time (the robot did spend it); a log that "
        "ends inside a run is that run stopped there"
    ),
    option="--stopped-runs 2015",
)

RULE_LIVE_CLOCK = Rule(
    key="fbm3w.live-clock",
    benchmark="fbm3w",
    title="reference pose and run times",
    rulebook="reference acquired when the manual operation completes; execution time of each "
    "run (seed 7.3.3, Listing 16)",
    node_2015=(
        f"{NODE_SOURCE}: tf's latest pose (`lookupTransform(..., rospy.Time(0))`) once "
        "`ManualOperation()` returned (l. 206-208), and its own wall clock at the transitions"
    ),
    ertools=(
        "the last logged pose at or before the BmBox left WAITING_MANUAL_OPERATION (for "
        "COMPLETED_MANUAL_OPERATION, or READY on a RefBox END) and the state messages' record "
        "times; no option: the live tf and wall clock are not in the log"
    ),
    option="",
)

RULE_RUN_FINDING = Rule(
    key="fbm3w.run-finding",
    benchmark="fbm3w",
    title="finding the runs",
    rulebook="the BmBox state machine delimits each run (seed 7.3.3)",
    node_2015=f"{NODE_SOURCE}: its state machine only",
    ertools=(
        "the BmBox states when logged; also explicit windows (--run) or motion (--runs auto) "
        "for bags without them"
    ),
    option="--runs states",
)

RULE_POSE_TOPIC = Rule(
    key="fbm3w.pose-topic",
    benchmark="fbm3w",
    title="pose source",
    rulebook="the end effector's marker set from the mocap (seed 7.3.3)",
    node_2015=f"{NODE_SOURCE}: subscribed to {DEFAULT_TOPIC}",
    ertools=f"{DEFAULT_TOPIC}, else {FALLBACK_TOPIC}, else the tf frame {DEFAULT_FRAME}",
    option=f"--topic {DEFAULT_TOPIC}",
)

RULE_D_MIN = Rule(
    key="fbm3w.d-min",
    benchmark="fbm3w",
    title="subsampling threshold d_min",
    rulebook="d_min = c * epsilon, c chosen experimentally (seed 7.3.2, 7.3.5)",
    node_2015=f"{NODE_SOURCE}: `D_MIN = 0.00033` hard-coded (l. 20; the seed's value)",
    ertools="the config's d_min (default 0.00033 m), warned when below the bag's own noise",
    option="--d-min 0.00033",
)

RULE_USER_SHAPES = Rule(
    key="fbm3w.user-shapes",
    benchmark="fbm3w",
    title="target shapes",
    rulebook="mathematically defined curves hard-coded in the script (seed 7.3.7, Listing 15)",
    node_2015=(
        f"{NODE_SOURCE}: line_path (0.15 l, 0.045 l) and sine (= spline_path) since 7942ea2 "
        "(before: the 0.30/0.10 line and the semi-ellipse); semi_ellipse defined, unused"
    ),
    ertools="the built-in shapes plus user shapes from the config; no option: a user shape is "
    "the user's choice, said in the output",
    option="",
)

RULE_ARC_LENGTH = Rule(
    key="fbm3w.arc-length",
    benchmark="fbm3w",
    title="target parameter",
    rulebook="t(l) with l the normalised length (seed 7.3.1)",
    node_2015=f"{NODE_SOURCE}: each shape evaluated at its own parameter (the sine's is not its "
    "length: 8.36 mm for a robot exactly on it)",
    ertools="the same by default (shape_floor reported); --arc-length compares at equal "
    "fractions of the target's arc length instead, on request only",
    option="",
)

RULE_UNSCOREABLE_RUNS = Rule(
    key="fbm3w.unscoreable-runs",
    benchmark="fbm3w",
    title="runs without enough valid ground truth",
    rulebook="the end effector's path as the mocap measured it (seed 7.3.3); the seed says "
    "nothing of tracking losses or gaps",
    node_2015=(
        f"{NODE_SOURCE}: every pose it received, repeated poses of a lost marker set and gaps "
        "included, made the path; a run was scored from whatever it had: one kept pose gave "
        "`error_sum / N` = 0.0, a start on the reference the world's x axis"
    ),
    ertools=(
        "a run whose path window is less than 90% covered by valid data, or has more than 0.5 s "
        "without it between two valid samples, is unscoreable: no distance_error, the reason "
        "given (docs/uncertainty.md); a path that never moved d_min, or starts on the "
        "reference, is a failure"
    ),
    option="--unscoreable 2015",
)

# The versions of scripts/fbm3w (rows of the version table, ertools.node_versions.NodeVersion).
_F = "scripts/fbm3w"
_DEV = "not restorable: a development version, run in no competition"
_DRAFT = "not restorable: no score computed"
_PRE = (
    "in part: its shapes as user shapes in the config (docs/fbm3w.md) and `--timeout-runs "
    "unscored` (time, no score); not restorable: a timed-out run was repeated under its run "
    "number and spec, which the next manual operation in the log does not show"
)
VERSIONS = (
    NodeVersion(_F, "ef3ed26", "2015-10-30", "development", "FBM1@Work's node copied", _DRAFT),
    NodeVersion(
        _F,
        "1101e55",
        "2015-11-03",
        "development",
        "runs from runs_specifications, D_MIN 0.002; no score yet",
        _DRAFT,
    ),
    NodeVersion(_F, "e2b7475", "2015-11-04", "development", "no score yet", _DRAFT),
    NodeVersion(_F, "0f20ffd", "2015-11-05", "development", "none (notes)", _DRAFT),
    NodeVersion(
        _F,
        "f127618",
        "2015-11-05",
        "development",
        "the path collected from pose2d (D_MIN 0.002) while the goal ran; a RefBox timeout: "
        "its time; no score yet",
        _DRAFT,
    ),
    NodeVersion(_F, "65dfee4", "2015-11-05", "development", "none (the file's mode)", _DRAFT),
    NodeVersion(
        _F,
        "71d270d",
        "2015-11-06",
        "development",
        "an error printed, not scored (in the world frame, the target at the length itself)",
        _DRAFT,
    ),
    NodeVersion(
        _F,
        "5568eef",
        "2015-11-06",
        "development",
        "D_MIN 0.01, one manual operation for all runs; still printed only",
        _DRAFT,
    ),
    NodeVersion(
        _F,
        "3e6dd79",
        "2015-11-08",
        "development",
        "the first score (best_distance_error): Eq. (1) in the run frame at l/L, D_MIN 0.005, "
        "line (0.30 l, 0.10 l), spline a semi-ellipse (0.050, 0.048); a RefBox timeout: its "
        "time, no score, the run repeated",
        _DEV,
    ),
    NodeVersion(
        _F, "f8b4b26", "2015-11-09", "development", "none (not running, its commit says)", _DEV
    ),
    NodeVersion(
        _F,
        "d76de82",
        "2015-11-09",
        "development",
        "the run frame's x axis atan2(start - reference)",
        _DEV,
    ),
    NodeVersion(
        _F,
        "d161ac8",
        "2015-11-09",
        "development",
        "D_MIN 0.00033; a manual operation per run; the start measured in the first run only",
        _DEV,
    ),
    NodeVersion(
        _F,
        "f82940c",
        "2015-11-09",
        "development",
        "the reference measured after each manual operation",
        _DEV,
    ),
    NodeVersion(
        _F,
        "f012c65",
        "2015-11-09",
        "development",
        "the start measured 2 s after the goal was sent",
        _DEV,
    ),
    NodeVersion(
        _F,
        "2320dc4",
        "2015-11-10",
        "development",
        "the start is the first pose of the path",
        _DEV,
    ),
    NodeVersion(
        _F, "9417897", "2015-11-10", "development", "an ENTER awaited before each path", _DEV
    ),
    NodeVersion(
        _F,
        "f7ff352",
        "2015-11-10",
        "development",
        "no ENTER; the paths published for display",
        _DEV,
    ),
    NodeVersion(
        _F,
        "e9620e6",
        "2015-11-10",
        "RoCKIn 2015 Lisbon, before its days 2 and 3 (the next commit says)",
        "none (comments)",
        _PRE,
    ),
    NodeVersion(
        _F,
        "6615fb0",
        "2015-11-22",
        "RoCKIn 2015 Lisbon, competition days 2 and 3 (its commit)",
        "the spline a semi-ellipse of 0.11 x 0.11 (a sine defined, unused)",
        _PRE,
    ),
    NodeVersion(
        _F,
        "7942ea2",
        "2015-11-30",
        'RoCKIn 2015 Lisbon ("changes during rockin 2015")',
        "line (0.15 l, 0.045 l) and spline the sine (Listing 15); a timed-out run timed, "
        "scored, eligible as best, the loop going on",
        "`--2015` (50b173b differs only where a tf lookup failed)",
    ),
    NodeVersion(
        _F,
        "50b173b",
        "2015-11-30",
        "RoCKIn 2015 Lisbon (its final state; unchanged to 89dfa75)",
        "a failed tf lookup (no mocap) retried, no longer ending the node",
        "`--2015`",
    ),
)

# Every rule above, in the catalogue's order (the benchmark's ``rules``).
RULES = (
    RULE_TIMEOUT_RUNS,
    RULE_STOPPED_RUNS,
    RULE_LIVE_CLOCK,
    RULE_RUN_FINDING,
    RULE_POSE_TOPIC,
    RULE_D_MIN,
    RULE_USER_SHAPES,
    RULE_ARC_LENGTH,
    RULE_UNSCOREABLE_RUNS,
)
