"""Where HOPF (FBM1@Home 2017-19) scoring differs from the RSBB script, each difference a
:class:`~ertools.fidelity.Rule`, and the script's versions (docs/hopf.md).

The ``node_2015`` field of a Rule holds what the *script* did: here the 2019 script
(``rockin-robot-challenge/rsbb`` at 2bb8a41), whose behaviour ``--rules 2019`` restores.
"""

from __future__ import annotations

from ertools.fidelity import Rule
from ertools.node_versions import NodeVersion

SCRIPT = "fbm1_objects_perception.py (rsbb 2bb8a41)"
SCRIPT_FILE = "rsbb_bmbox/scripts/benchmark_scripts/fbm1_objects_perception.py"

RULE_TRANSLATION_CLIP = Rule(
    key="hopf.translation-clip",
    benchmark="hopf",
    title="translation term clip",
    rulebook="pose score 1 - t/2 - r/2 with both terms in [0, 1] (the 2015 FBM1 listing)",
    node_2015=(
        f"{SCRIPT} l. 275-276: t = the distance in metres, unclipped (the clip is commented "
        "out): an answer more than 2 m off scores below 0"
    ),
    ertools="t = min(distance, 1 m), so a pose score stays in [0, 1] (as fbm1.translation-clip)",
    option="--clip-translation none",
    season="2019",
)

RULE_THETA_WRAP = Rule(
    key="hopf.theta-wrap",
    benchmark="hopf",
    title="theta error wrap",
    rulebook="the error of the 2D pose, theta in radians",
    node_2015=(
        f"{SCRIPT} l. 269-270: one step (minus 2 pi above pi, plus 2 pi below -pi): between "
        "3 pi and 5 pi off, r stays 1 after the clip"
    ),
    ertools="the error wrapped fully to [-pi, pi)",
    option="--single-wrap",
    season="2019",
)

RULE_NAMES = Rule(
    key="hopf.names",
    benchmark="hopf",
    title="class and instance comparison",
    rulebook="the robot answers the item's class and instance",
    node_2015=f"{SCRIPT} l. 256, 261: `==` on the strings, surrounding blanks count",
    ertools="compared without surrounding blanks (as fbm1.names)",
    option="--exact-names",
    season="2019",
)

RULE_STOPPED_GOAL = Rule(
    key="hopf.stopped-goal",
    benchmark="hopf",
    title="goals a referee stop cut short",
    rulebook="accuracies over the items presented",
    node_2015=(
        f"{SCRIPT} l. 85, 311-314: the totals are divided by i, the goals begun: a goal "
        "interrupted by the stop counts as a failure; a stop before the goal returns before the "
        "totals, which keep the previous goal's values (divided by i - 1) beside an empty goal"
    ),
    ertools=(
        "totals over the goals whose outcome is known (answered or timed out); a goal the stop "
        "interrupted is listed and not counted"
    ),
    option="--stopped-goals 2019",
    season="2019",
)

RULE_ANSWER_FIELDS = Rule(
    key="hopf.answer-fields",
    benchmark="hopf",
    title="an answer without x, y, theta, class or instance",
    rulebook="the robot answers the item's class, instance and pose",
    node_2015=(
        f"{SCRIPT} l. 247-250: a missing key or a value that is no number raises: the script "
        "dies and the result file keeps its last save (that goal's timeout, completed and "
        "segment_time, the previous totals); no later goal is scored"
    ),
    ertools=(
        "the part the missing or unreadable field belongs to is scored as wrong (a pose 0, a "
        "class or instance incorrect), the field named; the run goes on"
    ),
    option="--rules 2019",
    season="2019",
)

RULE_GT_GAPS = Rule(
    key="hopf.gt-gaps",
    benchmark="hopf",
    title="ground truth across a tracking gap",
    rulebook="the item's pose measured by the mocap",
    node_2015=(
        f"{SCRIPT} l. 128 (Pose2D_from_tf_concatenation): tf interpolates the table and the "
        "positioner between the samples around the lookup's moment, however far apart"
    ),
    ertools=(
        "no ground truth from samples more than --max-gap apart around the moment: the goal is "
        "unscoreable, left out of the totals, the reason given"
    ),
    option="--gt-gaps interpolate",
    season="2019",
)

# The versions of the script (rows of the version table, ertools.node_versions.NodeVersion).
VERSIONS = (
    NodeVersion(
        SCRIPT_FILE,
        "b5d91f4",
        "2017-11-07",
        "development (Enri2077/rsbb, before the December 2017 event)",
        "HOPF first written for the RSBB: items from HOPF.yaml, the ground truth looked up "
        "until it succeeds (a failure only when stopped, which ends the goals), the answer's "
        "class and instance recorded as the truth's, a first_manual_operation key; t unclipped, "
        "one-step wrap, totals over the goals begun",
        "`--rules 2017-11`",
    ),
    NodeVersion(
        SCRIPT_FILE,
        "00e3106",
        "2017-12-15",
        "ERL @Home 2017-18 (an event in Portugal, week of 14 December 2017; unchanged to "
        "3d9b21f, 2018-05-02)",
        "items from items_with_pose.yaml; 3 lookup attempts, then the referee moves the "
        "positioner; goal_<i> created first; manual_operation_N fields",
        "`--rules 2017`",
    ),
    NodeVersion(
        SCRIPT_FILE,
        "2bb8a41",
        "2019-04-08",
        "ERL @Home 2018-19",
        "the manual_operation_N fields dropped; the live score with a SCORE SUMMARY",
        "`--rules 2019`",
    ),
)

# what the registry carries (declare passes it as ``rules=``), in definition order
RULES = (
    RULE_TRANSLATION_CLIP,
    RULE_THETA_WRAP,
    RULE_NAMES,
    RULE_STOPPED_GOAL,
    RULE_ANSWER_FIELDS,
    RULE_GT_GAPS,
)
