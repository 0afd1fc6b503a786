"""How a HOPF score is computed: its inputs (the options of ``ertools score hopf``, the
manifest keys), the options they make (every check in :func:`make_options`), the defaults and
the script versions ``--rules`` reproduces. NumPy-free: the declaration and ``--help`` import it.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any, ClassVar

from ertools.benchmarks.base import Input, resolve_values
from ertools.benchmarks.common.inputs import INTERVAL_INPUTS
from ertools.benchmarks.common.script_inputs import (
    GT_GAPS,
    MAX_GAP,
    SCRIPT_GROUP,
    ScriptOptions,
    result_input,
    script_values,
)
from ertools.errors import UsageError
from ertools.frozen_dataclass import frozen_dataclass
from ertools.rsbb_states import ScriptFrame

NAME = "hopf"
CODE = "HOPF"

#: The frames its script broadcasts (2bb8a41: ``benchmarks_description.yaml``'s tf helper).
SCRIPT_FRAMES: tuple[ScriptFrame, ...] = (
    ScriptFrame("/item", "/positioner_origin", "/table_origin", 3, 1.0),
)
#: The mocap bodies whose pose topics its runs record.
MOCAP_BODIES = ("table_origin", "positioner_origin")
#: The seasons in which a script for it existed.
SCRIPT_SEASONS = ("2017", "2019")

#: The script versions ``--rules`` reproduces (docs/hopf.md, docs/fidelity.md's version table).
SCRIPTS = {
    "2019": "2bb8a41",
    "2017": "00e3106",
    "2017-11": "b5d91f4",
}
SCRIPT_TEXT = {
    "2019": "fbm1_objects_perception.py at rockin-robot-challenge/rsbb 2bb8a41 (2018-19 season)",
    "2017": "fbm1_objects_perception.py at Enri2077/rsbb 00e3106 (December 2017 to May 2018)",
    "2017-11": "fbm1_objects_perception.py at Enri2077/rsbb b5d91f4 (November 2017)",
}
RULE_SETS = ("ertools", *SCRIPTS)

#: The translation term's clip (ertools' rule): 1 m, as the 2015 rulebook's FBM1.
CLIP_TRANSLATION_M = 1.0


@frozen_dataclass
class HopfOptions(ScriptOptions):
    """Everything ``ertools score hopf`` can be told (:class:`ScriptOptions`, then these).

    Attributes:
        items: ``items_with_pose.yaml`` (None: found beside the bag in the RSBB layout).
        config: ``HOPF.yaml`` (None: the result file's ``benchmark_info.params``, or found).
        clip_translation: t clipped at :data:`CLIP_TRANSLATION_M` (False: the script's t).
        single_wrap: theta error wrapped by one step, as the script.
        exact_names: class and instance compared with their blanks, as the script.
        stopped_goals_2019: totals divided by the goals begun, as the script (stale after a
            stop before a goal).
    """

    SCRIPTS: ClassVar[Mapping[str, str]] = SCRIPTS

    items: Path | None = None
    config: Path | None = None
    clip_translation: bool = True
    single_wrap: bool = False
    exact_names: bool = False
    stopped_goals_2019: bool = False


INPUTS = (
    Input(
        "items",
        "path",
        "items_with_pose.yaml, the items the script drew from (default: beside the bag or in "
        "the RSBB layout)",
        metavar="FILE",
    ),
    Input(
        "config",
        "path",
        "HOPF.yaml, the benchmark config (default: beside the bag, the layout, or the result "
        "file's params)",
        metavar="FILE",
    ),
    result_input(CODE),
    MAX_GAP,
    Input(
        "rules",
        "choice",
        "reproduce a script version whole: 2019 (rsbb 2bb8a41, 2018-19), 2017 (Enri2077/rsbb "
        "00e3106, December 2017 to May 2018), 2017-11 (b5d91f4, November 2017); ertools "
        "(default): the options of this group decide",
        choices=RULE_SETS,
        group=SCRIPT_GROUP,
    ),
    Input(
        "clip_translation",
        "choice",
        "the translation term: clipped at 1 m (default) or none (the script: pose scores below 0)",
        choices=("1", "none"),
        group=SCRIPT_GROUP,
    ),
    Input(
        "single_wrap", "flag", "wrap the theta error by one step, as the script", group=SCRIPT_GROUP
    ),
    Input(
        "exact_names",
        "flag",
        "compare class and instance with their surrounding blanks, as the script",
        group=SCRIPT_GROUP,
    ),
    Input(
        "stopped_goals",
        "choice",
        "ertools (default): totals over the goals answered or timed out; 2019: divided by the "
        "goals begun, stale after a stop before a goal",
        choices=("ertools", "2019"),
        group=SCRIPT_GROUP,
    ),
    GT_GAPS,
    *INTERVAL_INPUTS,
)


def make_options(given: Mapping[str, Any]) -> HopfOptions:
    """The values of :data:`INPUTS` by name -> options (declared checks, then these).

    Raises:
        UsageError: a bad value, or options that exclude each other.
    """
    values = resolve_values(INPUTS, given)
    rules = values.get("rules") or "ertools"
    script = rules != "ertools"
    clip = values.get("clip_translation") or "1"
    gaps = values.get("gt_gaps") or "refuse"
    if script and values.get("max_gap") is not None and gaps == "refuse":
        raise UsageError("--max-gap applies to ertools' reading, not to --rules " + rules)
    return HopfOptions(
        items=values.get("items"),
        config=values.get("config"),
        clip_translation=clip != "none" and not script,
        single_wrap=bool(values.get("single_wrap")) or script,
        exact_names=bool(values.get("exact_names")) or script,
        stopped_goals_2019=values.get("stopped_goals") == "2019" or script,
        **script_values(values),
    )
