"""Where ertools' reading of HPFF differs from the RSBB script (season 2019), each a
:class:`~ertools.fidelity.Rule`, and the script's one version (docs/hpff.md)."""

from __future__ import annotations

from ertools.fidelity import Rule
from ertools.node_versions import NodeVersion

SCRIPT = "fbm5_person_following.py (rockin-robot-challenge/rsbb 2bb8a41)"
FILE = "rsbb_bmbox/scripts/benchmark_scripts/fbm5_person_following.py"

RULE_SAMPLING = Rule(
    key="hpff.sampling",
    benchmark="hpff",
    title="when the robot and the person are sampled",
    rulebook="the following distance measured throughout the run (ERL @Home rulebook, FBM5)",
    node_2015=(
        f"{SCRIPT} l. 98-148: every 0.5 s two tf lookups of one 0.2 s attempt each (relative, "
        "then absolute), at the moments the script reached them; a lookup fails when the data "
        "at its moment came more than 0.2 s late"
    ),
    ertools=(
        "samples on a 2 Hz grid from 8 s after the robot's start to the goal's end, both "
        "bodies interpolated from the mocap; a sample counts where both were tracked within "
        "--max-gap"
    ),
    option="--sampling script",
    season="2019",
)

RULE_PLANE = Rule(
    key="hpff.distance-plane",
    benchmark="hpff",
    title="the following distance's plane",
    rulebook="the distance between the robot and the person",
    node_2015=(
        f"{SCRIPT} l. 110-112: `sqrt(x^2 + y^2)` of the robot's position in the cap's frame "
        "(`actor_markerset`): a tilted cap tilts the plane"
    ),
    ertools="the horizontal distance in the testbed frame between the robot's odometric centre "
    "and the cap",
    option="--distance-plane actor",
    season="2019",
)

RULE_DURATION = Rule(
    key="hpff.duration-clock",
    benchmark="hpff",
    title="the run's duration",
    rulebook="the robot follows the person for the goal's duration",
    node_2015=(
        f"{SCRIPT} l. 90, 151-153: from after `request_goal` (the robot's start) to the end "
        "of the sampling loop (up to 0.5 s after the goal ended), within goal_timeout +- 15 s"
    ),
    ertools="from the RefBox's goal EXECUTING_GOAL to its READY (the goal's end), the same "
    "+- 15 s rule",
    option="--duration-clock script",
    season="2019",
)

RULE_STOPPED = Rule(
    key="hpff.stopped-runs",
    benchmark="hpff",
    title="a run stopped by the referee",
    rulebook="the benchmark ends at the goal's timeout, the global timeout or the referee's stop",
    node_2015=f"{SCRIPT} l. 141-148: a stop returns from the script: the score is `{{}}`",
    ertools="the samples until the stop scored, the run said stopped (and failed by the "
    "duration rule)",
    option="--rules 2019",
    season="2019",
)

RULE_RELIABILITY = Rule(
    key="hpff.reliability",
    benchmark="hpff",
    title="the reliability figure",
    rulebook="(the script's own figure of merit of the mocap)",
    node_2015=f"{SCRIPT} l. 168-169: failed relative lookups over all lookups",
    ertools="grid samples without valid mocap for either body over all grid samples (follows "
    "hpff.sampling)",
    option="--sampling script",
    season="2019",
)

VERSIONS = (
    NodeVersion(
        FILE,
        "2bb8a41",
        "2019-04-08",
        "ERL @Home 2018-19 (its only version)",
        "first version: 2 Hz samples after an 8 s settling sleep; deviation from 2.0 m, "
        "distance covered within 0.15-3.5 m, reliability text; a run fails outside "
        "goal_timeout +- 15 s; every run ends with the script's abort",
        "`--rules 2019`",
    ),
)

# what the registry carries (declare passes it as ``rules=``), in definition order
RULES = (RULE_SAMPLING, RULE_PLANE, RULE_DURATION, RULE_STOPPED, RULE_RELIABILITY)
