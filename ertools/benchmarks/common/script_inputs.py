"""The inputs of a benchmark that re-scores an ERL 2017-19 RSBB script from its run bag: the
side files (the script's config, the team's transform, the run's result file and the team,
each found in the RSBB's folder layout when not given:
:func:`ertools.rsbb.sidefiles.find_side_files`), and the refusal of a rule option that would
undo what ``--rules`` reproduces.

NumPy-free: the benchmarks' ``config`` modules list them for the command line's parser.
"""

from __future__ import annotations

from collections.abc import Mapping

from ertools.benchmarks.base import Input
from ertools.errors import UsageError

#: The help section of the options that undo ertools' readings of a 2019 script one by one.
SCRIPT_GROUP = "the 2019 script (differences can be undone one by one)"

TRANSFORM = Input(
    "transform",
    "path",
    "transform-<team>.yaml (markerset_to_robot_transform); default: found beside the "
    "bag or in rsbb_etc/transforms/",
    metavar="FILE",
    per_team=True,
)


def config_input(code: str, contents: str) -> Input:
    """``--config``: the script's ``<CODE>.yaml``, holding ``contents`` (its keys, in words)."""
    return Input(
        "config",
        "path",
        f"{code}.yaml ({contents}); default: found beside the bag or in the RSBB layout, else "
        "the result file's benchmark_info.params",
        metavar="FILE",
    )


def result_input(code: str) -> Input:
    """``--result``: the run's result file, which the recomputed score is compared with."""
    return Input(
        "result",
        "path",
        "the run's result_run_<n>_<date>.yaml, compared with the recomputed score; default: "
        f"found beside the bag or in results/{code}/<team>/",
        metavar="FILE",
    )


def team_input(code: str) -> Input:
    """``--team``: whose transform and result file to look for."""
    return Input(
        "team",
        "str",
        f"the team (default: rsbb_logs/{code}/<team>/ of the bag, else the result file's)",
        metavar="NAME",
        per_team=True,
    )


def refuse_undoing(rules: str, undone: Mapping[str, bool]) -> None:
    """Refuse the rule options (by their flag) that would undo what ``--rules RULES``
    reproduces.

    Raises:
        UsageError: one or more of them is True.
    """
    clash = [flag for flag, undoes in undone.items() if undoes]
    if clash:
        raise UsageError(
            f"--rules {rules} reproduces the script: {', '.join(clash)} would undo it; "
            "give one or the other"
        )
