"""Where HPPF (FBM4@Home 2019) scoring differs from the RSBB script, each difference a
:class:`~ertools.fidelity.Rule`, and the script's version (docs/hppf.md).

The ``node_2015`` field of a Rule holds what the *script* did: here the 2019 script
(``rockin-robot-challenge/rsbb`` at 2bb8a41), whose behaviour ``--rules 2019`` restores.
"""

from __future__ import annotations

from ertools.fidelity import Rule
from ertools.node_versions import NodeVersion

SCRIPT = "fbm4_people_perception.py (rsbb 2bb8a41)"
SCRIPT_FILE = "rsbb_bmbox/scripts/benchmark_scripts/fbm4_people_perception.py"

RULE_ANSWER_FIELDS = Rule(
    key="hppf.answer-fields",
    benchmark="hppf",
    title="an answer without x, y, theta or person_name",
    rulebook="the robot answers the person's name and position",
    node_2015=(
        f"{SCRIPT} l. 186-190: `theta` is required though no score uses it; a missing key, a "
        "value the `%.2f` refuses or a name that is no text raises: the script dies and the "
        "result file keeps its last save (that goal's segment time, the previous totals)"
    ),
    ertools=(
        "only x, y and person_name are needed; a goal whose answer lacks one (or has no number "
        "for x or y) is detected and not recognised, without position error, the field named; "
        "the run goes on"
    ),
    option="--rules 2019",
    season="2019",
)

RULE_NAMES = Rule(
    key="hppf.names",
    benchmark="hppf",
    title="name comparison",
    rulebook="the robot recognises the person by name",
    node_2015=f"{SCRIPT} l. 190: `lower()` on both names, surrounding blanks count",
    ertools="lower-cased and compared without surrounding blanks",
    option="--exact-names",
    season="2019",
)

RULE_GT_GAPS = Rule(
    key="hppf.gt-gaps",
    benchmark="hppf",
    title="ground truth across a tracking gap",
    rulebook="the person's position measured by the mocap (the cap's marker set)",
    node_2015=(
        f"{SCRIPT} l. 172 (Pose2D_from_tf_concatenation): tf interpolates the cap between the "
        "samples around the lookup's moment, however far apart"
    ),
    ertools=(
        "no ground truth from samples more than --max-gap apart around the moment: the goal "
        "has no position error and is left out of the Distance error, the reason given; its "
        "name still counts"
    ),
    option="--gt-gaps interpolate",
    season="2019",
)

VERSIONS = (
    NodeVersion(
        SCRIPT_FILE,
        "2bb8a41",
        "2019-04-08",
        "ERL @Home 2018-19 (its only version)",
        "HPPF written: one goal per person of HPPF.yaml, names compared lower-cased, Distance "
        "error = sum / detected, the percentage over all the people, a goal without ground "
        "truth after its answer restarted",
        "`--rules 2019`",
    ),
)

# what the registry carries (declare passes it as ``rules=``), in definition order
RULES = (RULE_ANSWER_FIELDS, RULE_NAMES, RULE_GT_GAPS)
