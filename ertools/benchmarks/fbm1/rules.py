"""Where FBM1@Home and FBM1@Work scoring differs from the 2015 node, each difference a
:class:`~ertools.fidelity.Rule` (the catalogue of :mod:`ertools.fidelity`: what the rulebook
says, what the node did, what ertools does and why, the option restoring 2015).
"""

from __future__ import annotations

from ertools.fidelity import Rule
from ertools.node_versions import NodeVersion

NODE_SOURCE = "scripts/fbm1h (e373be0), scripts/fbm1w (7628309): RoCKIn 2015"

RULE_GT_MOMENT = Rule(
    key="fbm1.ground-truth",
    benchmark="fbm1",
    title="ground-truth moment",
    rulebook="BMmanager combines the table, board and item transforms (seed 7.1); no moment",
    node_2015=(
        f"{NODE_SOURCE}: one tf lookup, `lookupTransform('/origin', '/item', "
        "rospy.Time(0))`, at the stamp of the item transform broadcast once when the result had "
        "arrived (the 2016 and 2017 @Home nodes, 40ba68b and 89dfa75: when the placement was "
        "confirmed, `--gt placed`)"
    ),
    ertools=(
        "mean over the stationary window before the goal, spread reported: one sample carries "
        "the mocap noise, and the board may be touched while the robot looks"
    ),
    option="--gt result",
)

RULE_TRANS_CLIP = Rule(
    key="fbm1.translation-clip",
    benchmark="fbm1",
    title="translation term clip",
    rulebook="pose score 1 - t/2 - r/2 with both terms in [0, 1] (score listing, seed 7.1)",
    node_2015=(
        f"{NODE_SOURCE}: `if pose_err_trans > max_pose_error : pose_err_trans = 1` with "
        "max_pose_error = sqrt(2) m: errors of 1..1.41 m stay unclipped (score down to -0.21); "
        "so the 2016 node (40ba68b); the 2017 node (89dfa75) clipped at 1 m as ertools does"
    ),
    ertools="t = min(error, 1 m), so a pose score stays in [0, 1]",
    option="--clip-above-diagonal",
)

RULE_THETA_WRAP = Rule(
    key="fbm1.theta-wrap",
    benchmark="fbm1",
    title="theta error wrap",
    rulebook="the error of the 2D pose; theta in [-180, 180] deg",
    node_2015=(
        f"{NODE_SOURCE}: `if w_err > 180: w_err = w_err - 360` and `if w_err < -180: w_err = "
        "w_err + 360`: one step, answers beyond +-540 deg keep r = 1"
    ),
    ertools="wrapped fully to [-180, 180)",
    option="--single-wrap",
)

RULE_NAMES = Rule(
    key="fbm1.names",
    benchmark="fbm1",
    title="class and instance comparison",
    rulebook="object class and instance names [string] (seed 7.1)",
    node_2015=(
        f"{NODE_SOURCE}: `result['item_class'] == item['class']`, exact: the 2015 fbm1w.yaml "
        'class `"Bearing Boxes "` (trailing blank) matched no answer'
    ),
    ertools="compared without surrounding blanks",
    option="--exact-names",
)

RULE_ABORTED = Rule(
    key="fbm1.aborted-runs",
    benchmark="fbm1",
    title="run stopped before its goal",
    rulebook="repeated until time runs out or 10 objects have been processed (seed 7.1)",
    node_2015=(
        f"{NODE_SOURCE}: `runs = runs + 1` before the manual operation, then `break` when the "
        "benchmark stopped: the run counts in every divisor with no positive and pose score 0"
    ),
    ertools=(
        "totals over the runs whose goal was sent (a run never asked is not a failed one); a "
        "log that ends before a run's goal is that run stopped there"
    ),
    option="--count-aborted",
)

RULE_POSE_SOURCE = Rule(
    key="fbm1.pose-source",
    benchmark="fbm1",
    title="table and board pose source",
    rulebook="the table (origin) and reference board marker sets from the mocap (seed 7.1)",
    node_2015=(
        f'{NODE_SOURCE}: `listener.lookupTransform("/origin", "/item", rospy.Time(0))` '
        "(fbm1h at e373be0, line 125): the /tf frames origin and ref_board, never the pose "
        "topics"
    ),
    ertools=(
        "the pose topics /<ns>/origin/pose and /<ns>/ref_board/pose (the same mocap samples, "
        "header-stamped), else the /tf frames; the one-lookup ground truths (--gt result, "
        "placed, goal, and so --rules 2015) take /tf first"
    ),
    option="--origin-tf world:origin --ref-board-tf world:ref_board",
)

RULE_UNSCOREABLE = Rule(
    key="fbm1.unscoreable",
    benchmark="fbm1",
    title="ground truth without a valid mocap sample",
    rulebook="BMmanager combines the table, board and item transforms (seed 7.1); nothing on "
    "tracking losses",
    node_2015=(
        f"{NODE_SOURCE}: the tf lookup gave the last pose Motive had re-sent, measured or not"
    ),
    ertools=(
        "a run with no valid sample of the table or the board (not a repeated pose of a lost "
        "marker set, not NaN) within --max-gap of the ground truth's window is unscoreable: "
        "left out of the totals like a failed run, the reason given (docs/uncertainty.md)"
    ),
    option="--unscoreable 2015",
)

RULE_ACQUIRE_WINDOW = Rule(
    key="fbm1.acquire-items",
    benchmark="fbm1",
    title="item transform acquisition",
    rulebook="the transform from the board to each item is acquired with the mocap (seed 7.1.4)",
    node_2015=(
        "scripts/acquire_items (2015): one tf lookup of ref_board -> origin when the operator "
        "pressed ENTER"
    ),
    ertools=(
        "the mean over the item's still window, spread written beside it; no option: the "
        "moments ENTER was pressed are not in the log"
    ),
    option="",
)

# Every rule above, in the catalogue's order (ertools.benchmarks.fbm1.declare: the benchmark's
# ``rules``).
RULES = (
    RULE_GT_MOMENT,
    RULE_TRANS_CLIP,
    RULE_THETA_WRAP,
    RULE_NAMES,
    RULE_ABORTED,
    RULE_POSE_SOURCE,
    RULE_UNSCOREABLE,
    RULE_ACQUIRE_WINDOW,
)

# The versions of the FBM1 nodes (rows of the version table, ertools.node_versions.NodeVersion).
_H = "scripts/fbm1h"
VERSIONS = (
    NodeVersion(
        _H,
        "5fdbdc2",
        "2015-04-03",
        'RoCKIn Camp 2015 ("release used at rockin camp 2015")',
        "the 2015 scoring: totals over runs played + aborted, one tf lookup when the result "
        "arrived, translation set to 1 only above sqrt(2) m, one-step theta wrap, exact names",
        "`--rules 2015` (the same arithmetic; its BmBox waited on a RefBox END during a manual "
        "operation)",
    ),
    NodeVersion(_H, "8eb3450", "2015-06-23", "development", "none (imports)", "`--rules 2015`"),
    NodeVersion(_H, "117a5d0", "2015-10-26", "development", "none (a log level)", "`--rules 2015`"),
    NodeVersion(
        _H,
        "e373be0",
        "2015-10-30",
        "RoCKIn 2015 Lisbon",
        "none (waits for ENTER at the end)",
        "`--rules 2015` (`--2015`)",
    ),
    NodeVersion(
        _H,
        "40ba68b",
        "2017-01-26",
        "Lisbon 2016 second local competition",
        "the ground truth looked up when the placement was confirmed, before the goal (then "
        "ENTER once the positioner is removed); class and instance accuracies over "
        "BENCHMARK_RUNS = 10",
        "`--rules 2016` (`--2016`)",
    ),
    NodeVersion(
        _H,
        "27d9a23",
        "2017-05-04",
        "the Peccioli competition, May 2017 (its commit)",
        "none (a partial score published for display)",
        "`--rules 2016` (the same arithmetic)",
    ),
    NodeVersion(
        _H,
        "89dfa75",
        "2017-11-10",
        "Lisbon 2017 major tournament",
        "the translation term clipped at 1 m (`if pose_err_trans > 1.0`), not above sqrt(2) m",
        "`--rules 2017` (`--2017`)",
    ),
    NodeVersion(
        "scripts/fbm1w",
        "7628309",
        "2015-07-06",
        "RoCKIn 2015 Lisbon (its only version)",
        "FBM1@Home's arithmetic without a run cap (`while benchmark.Running()`), the item the "
        "RefBox names (ManualOperation()'s payload)",
        "`--rules 2015` (`--2015`)",
    ),
)
