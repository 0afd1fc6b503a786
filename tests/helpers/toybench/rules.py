"""Where the toy differs from its original node, each difference a :class:`ertools.fidelity.Rule`.

The toy's "original node" is invented for the example; a real benchmark cites the node's file
and lines (``ertools/benchmarks/fbm3w/rules.py``).
"""

from __future__ import annotations

from ertools.fidelity import Rule

RULE_NAN_POSES = Rule(
    key="toy.nan-poses",
    benchmark="toy",
    title="poses without a position",
    rulebook="the toy rulebook counts the poses the mocap system measured",
    node_2015="the original toy node counted every message, NaN positions included",
    ertools="a pose whose position is NaN was not measured: it is not counted",
    option="--count-nan",
)

RULES = (RULE_NAN_POSES,)
