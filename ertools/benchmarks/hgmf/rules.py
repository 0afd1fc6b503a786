"""Where ertools' HGMF reading differs from the 2019 script, each difference a
:class:`~ertools.fidelity.Rule` (docs/hgmf.md, "Deviations"), and the script's one version.
"""

from __future__ import annotations

from ertools.fidelity import Rule
from ertools.node_versions import NodeVersion

SCRIPT = "rsbb_bmbox/scripts/benchmark_scripts/fbm6_grasping_manipulation.py"
SOURCE = f"{SCRIPT} (rockin-robot-challenge/rsbb 2bb8a41, ERL 2019)"

RULE_RESTARTED_GOALS = Rule(
    key="hgmf.restarted-goals",
    benchmark="hgmf",
    title="a goal restarted after its final lookup failed",
    rulebook="the average distance of the objects placed, and the objects grasped (ERL "
    "Consumer 2019 rulebook, FBM6)",
    node_2015=(
        f"{SOURCE}: `goals_completed_sum += 1` and, if grasped, `objects_grasped_sum += 1` "
        "(l. 206-209) before the final pose lookup; when it fails the goal is run again "
        "(`continue`, l. 216-221) and both counts stay: the average is divided by goals that "
        "were never measured and `Objects grasped` can exceed the objects"
    ),
    ertools=(
        "only the goals whose final position was measured count in the divisor and the "
        "grasps; the restarted attempt is listed, not scored"
    ),
    option="--restarted-goals 2019",
    season="2019",
)

RULE_GRASP_SAMPLING = Rule(
    key="hgmf.grasp-sampling",
    benchmark="hgmf",
    title="when a grasp is checked",
    rulebook="the object was grasped: lifted from the table (ERL 2019 rulebook, FBM6)",
    node_2015=(
        f"{SOURCE}: a 10 Hz `rospy.Timer` (l. 176, 261-274) looks the object up at tf's latest "
        "common time of the table and the object, moments the log does not record, and "
        "counts a grasp when z > z_ref + 0.03 m at one of them"
    ),
    ertools=(
        "every mocap sample of the object from the goal's start to its end, the table "
        "interpolated at its stamp, against the same z_ref + 0.03 m: a lift between two "
        "ticks is seen, and the decision does not rest on inferred moments"
    ),
    option="--grasp-sampling timer",
    season="2019",
)

RULE_GT_GAPS = Rule(
    key="hgmf.gt-gaps",
    benchmark="hgmf",
    title="the object's position across a tracking gap",
    rulebook="the object's position measured by the motion capture (ERL 2019 rulebook, FBM6)",
    node_2015=(
        f"{SOURCE}: tf interpolates between the samples around the lookup's `now` however far "
        "apart they are (tf keeps 10 s), so a position inside a tracking gap is made up"
    ),
    ertools=(
        "a lookup whose samples around its moment are more than --max-gap apart (default "
        "0.1 s) gives no position: its goal is not scored (the reference height: its goal is "
        "not scored either), and the result says which"
    ),
    option="--gt-gaps interpolate",
    season="2019",
)

VERSIONS = (
    NodeVersion(
        SCRIPT,
        "2bb8a41",
        "2019-04-08",
        "ERL @Home 2018-19 (its only version)",
        "a new script: a grasp when the object rises 3 cm over its height before the goal "
        "at a 10 Hz check; the distance of the object to the target in the table's plane, "
        "averaged over the goals completed",
        "`--rules 2019`",
    ),
)

# what the registry carries (declare passes it as ``rules=``), in definition order
RULES = (RULE_RESTARTED_GOALS, RULE_GRASP_SAMPLING, RULE_GT_GAPS)
