"""The rules of the 2015 trajectory script where ertools' default differs (docs/fidelity.md):
each :class:`~ertools.fidelity.Rule` names the option that restores the 2015 behaviour.
"""

from __future__ import annotations

from ertools.fidelity import Rule

# The rules of the 2015 script where ertools' default differs (docs/fidelity.md). The 2015
# script is rockin_trajectory_benchmark.py of rockin_offline_trajectory_benchmark (seed
# footnote 15); the seed says only that it compares the GT with the trajectory the robot logged.
_SEED = (
    "seed footnote 15: rockin_offline_trajectory_benchmark compares the GT with the trajectory "
    "logged by the robot; section 4: NTP time makes the association 'straightforward'; no rule "
    "given"
)
RULE_ASSOCIATION = Rule(
    key="trajectory.association",
    benchmark="trajectory",
    title="GT pose at a robot time",
    rulebook=_SEED,
    node_2015=(
        "the GT pose before the first GT pose at or after the robot stamp, not interpolated "
        "(rockin_trajectory_benchmark.py: interpolate() 'not used', returns mocap_pose_1)"
    ),
    ertools=(
        "linear between the GT poses around the robot time (SLERP for orientation): holding "
        "adds up to one GT period of motion (8 ms at 120 Hz, 4 mm at 0.5 m/s) to the error"
    ),
    option="--association hold",
)
RULE_TIES = Rule(
    key="trajectory.ties",
    benchmark="trajectory",
    title="robot pose stamped exactly at a GT sample",
    rulebook=_SEED,
    node_2015=(
        "seek_mocap_pose_at stops at the first pair with p2.t >= t and uses p1: on a tie, the "
        "GT pose before the robot's (rockin_trajectory_benchmark.py)"
    ),
    ertools="with --association hold, the GT sample at the robot time: the GT pose at that time",
    option="--ties before",
)
RULE_GAPS = Rule(
    key="trajectory.gaps",
    benchmark="trajectory",
    title="robot poses in GT gaps",
    rulebook=_SEED,
    node_2015=(
        "compared with the pose held across the gap, only warned: 'consecutive mocap poses very "
        "distant in time, used to calculate the error (result may be invalid)' when t2 - t1 > "
        "0.1 s (rockin_trajectory_benchmark.py)"
    ),
    ertools=(
        "not compared, counted as gaps (--max-gap, default 0.1 s): the held pose may be "
        "seconds old and the error then measures the gap, not the robot"
    ),
    option="--gaps compare",
)
RULE_BEFORE_GT = Rule(
    key="trajectory.before-gt",
    benchmark="trajectory",
    title="robot poses before the first GT pose",
    rulebook=_SEED,
    node_2015=(
        "compared with the first GT pose after printing '[ERROR] ... This should never "
        "happen' (rockin_trajectory_benchmark.py, seek_mocap_pose_at)"
    ),
    ertools=(
        "uncovered, not scored: the covered part is scored and the uncovered span is a "
        "failure naming it (GT files missing or clocks apart; exit 1), or only said with "
        "--allow-partial"
    ),
    option="--before-gt first",
)
RULE_YAW_WRAP = Rule(
    key="trajectory.yaw-wrap",
    benchmark="trajectory",
    title="orientation error across +-pi",
    rulebook=_SEED,
    node_2015=(
        "atan2(sum sin|dyaw|, sum cos|dyaw|) with dyaw = r_theta - m_theta not wrapped, yaws "
        "from tf euler_from_quaternion (rockin_trajectory_benchmark.py, Error.update)"
    ),
    ertools=(
        "dyaw wrapped to [-pi, pi] in orientation_error (a pose crossing +-pi otherwise counts "
        "a ~2pi difference); every run also reports 2015's value as orientation_error_2015, so "
        "no option is needed"
    ),
    option="",
)
RULE_GT_OVERLAP = Rule(
    key="trajectory.gt-overlap",
    benchmark="trajectory",
    title="GT files overlapping in time",
    rulebook=_SEED,
    node_2015=(
        "chained the GT files sorted by start time (`sorted(mocap_bags_list, key=... "
        "['start'])`, `itertools.chain`) and scanned the chain forward, never back, warning "
        "'poses out of order: result may be invalid' (rockin_trajectory_benchmark.py, "
        "DualIterator and seek_mocap_pose_at): a robot pose is paired with the first pose "
        "of the chain at or after its time and the one read before it, out of order or not"
    ),
    ertools=(
        "poses merged in time order, a message recorded twice used once: the GT pose at the "
        "robot's time whatever file holds it (2015's pair there can be a pose of the other file "
        "from before a pose it already passed)"
    ),
    option="--gt-order chain",
)
RULE_INVALID_POSES = Rule(
    key="trajectory.invalid-poses",
    benchmark="trajectory",
    title="NaN poses, zero quaternions and impossible positions",
    rulebook=_SEED,
    node_2015=(
        "used as they were: a NaN made the score NaN, a zero quaternion gave tf's identity, a "
        "yaw of 0, a pose kilometres away its distance (rockin_trajectory_benchmark.py, "
        "Error.update)"
    ),
    ertools=(
        "ignored and counted in a warning; no option: a NaN score is no score, a zero "
        "quaternion is a node publishing 'no pose', and a position kilometres from the others "
        "(or a GT pose reached and left faster than any robot) is no measurement "
        "(docs/uncertainty.md, 'Impossible samples')"
    ),
    option="",
)
RULE_ROBOT_STAMPS = Rule(
    key="trajectory.robot-stamps",
    benchmark="trajectory",
    title="robot stamps that go back in time",
    rulebook=_SEED,
    node_2015=(
        "its GT scan only moves forward: a robot pose stamped before the previous one was "
        "compared with the GT pose of the previous one (rockin_trajectory_benchmark.py)"
    ),
    ertools=(
        "an error naming the message; no option: the 2015 pairing there is not the GT at the "
        "robot's time (--robot-time-source record scores by the robot bag's record times instead)"
    ),
    option="",
)

RULE_UNSCOREABLE = Rule(
    key="trajectory.unscoreable",
    benchmark="trajectory",
    title="too few valid pairs",
    rulebook=_SEED,
    node_2015="rockin_trajectory_benchmark.py: averaged whatever pairs it had, one or a thousand",
    ertools=(
        "fewer than half of the robot poses inside the GT with a valid GT pose (the others in "
        "GT gaps, while tracking was lost, NaN) is unscoreable: null statistics, the reason "
        "given (docs/uncertainty.md); evo's pairing (--t-max-diff) is left as evo has it"
    ),
    option="--unscoreable 2015",
)

# Every rule above, in the catalogue's order (the benchmark's ``rules``).
RULES = (
    RULE_ASSOCIATION,
    RULE_TIES,
    RULE_GAPS,
    RULE_BEFORE_GT,
    RULE_YAW_WRAP,
    RULE_GT_OVERLAP,
    RULE_INVALID_POSES,
    RULE_ROBOT_STAMPS,
    RULE_UNSCOREABLE,
)
