"""The inputs of a benchmark that re-scores an ERL 2017-19 RSBB script's run alike: the run's
result file to compare with, and how the ground truth is looked up across a tracking gap
(ertools refuses it; the script's tf interpolated).

NumPy-free: the benchmarks' ``config`` modules list them for the command line's parser.
"""

from __future__ import annotations

from ertools.benchmarks.base import Input

#: The help section of the options that undo ertools' readings of a script one by one.
SCRIPT_GROUP = "the RSBB script's behaviour (each difference can be undone)"

#: The mocap runs at 100-120 Hz, so 0.1 s is several lost frames (ertools' rule).
DEFAULT_MAX_GAP_S = 0.1

RESULT = Input(
    "result",
    "path",
    "the run's result file result_run_<n>_<date>.yaml, compared with the recomputed score "
    "(default: beside the bag or in the RSBB layout)",
    metavar="FILE",
)

MAX_GAP = Input(
    "max_gap",
    "float",
    f"no ground truth across a tracking gap wider than this (default {DEFAULT_MAX_GAP_S} s)",
    unit="s",
    positive=True,
)

GT_GAPS = Input(
    "gt_gaps",
    "choice",
    "refuse (default): no ground truth across a gap wider than --max-gap; interpolate: as tf did",
    choices=("refuse", "interpolate"),
    group=SCRIPT_GROUP,
)
