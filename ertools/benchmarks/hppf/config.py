"""How an HPPF score is computed: its inputs (the options of ``ertools score hppf``, the
manifest keys), the options they make (every check in :func:`make_options`), the defaults and
the script version ``--rules 2019`` reproduces. NumPy-free: the declaration imports it.
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

NAME = "hppf"
CODE = "HPPF"

#: The frames its script broadcasts (2bb8a41: ``benchmarks_description.yaml``'s tf helper).
SCRIPT_FRAMES: tuple[ScriptFrame, ...] = (
    ScriptFrame("/person", "/actor_markerset", "/testbed_origin", 3, 1.0),
)
#: The mocap bodies whose pose topics its runs record.
MOCAP_BODIES = ("actor_markerset",)
#: The seasons in which a script for it existed.
SCRIPT_SEASONS = ("2019",)

SCRIPTS = {"2019": "2bb8a41"}
SCRIPT_TEXT = {
    "2019": "fbm4_people_perception.py at rockin-robot-challenge/rsbb 2bb8a41 (2018-19 season)",
}
RULE_SETS = ("ertools", *SCRIPTS)


@frozen_dataclass
class HppfOptions(ScriptOptions):
    """Everything ``ertools score hppf`` can be told (:class:`ScriptOptions`, then these).

    Attributes:
        config: ``HPPF.yaml`` (None: found, else the first live score's copy).
        exact_names: names compared lower-cased with their blanks, as the script.
        script_answers: an incomplete answer kills the script, as it did (``--rules 2019``).
    """

    SCRIPTS: ClassVar[Mapping[str, str]] = SCRIPTS

    config: Path | None = None
    exact_names: bool = False
    script_answers: bool = False


INPUTS = (
    Input(
        "config",
        "path",
        "HPPF.yaml, its people (default: beside the bag, the layout, or the run's first live "
        "score)",
        metavar="FILE",
    ),
    result_input(CODE),
    MAX_GAP,
    Input(
        "rules",
        "choice",
        "reproduce the script whole: 2019 (rsbb 2bb8a41, 2018-19); ertools (default): the "
        "options of this group decide",
        choices=RULE_SETS,
        group=SCRIPT_GROUP,
    ),
    Input(
        "exact_names",
        "flag",
        "compare the names lower-cased with their surrounding blanks, as the script",
        group=SCRIPT_GROUP,
    ),
    GT_GAPS,
    *INTERVAL_INPUTS,
)


def make_options(given: Mapping[str, Any]) -> HppfOptions:
    """The values of :data:`INPUTS` by name -> options (declared checks, then these).

    Raises:
        UsageError: a bad value, or options that exclude each other.
    """
    values = resolve_values(INPUTS, given)
    rules = values.get("rules") or "ertools"
    script = rules != "ertools"
    if script and values.get("max_gap") is not None:
        raise UsageError("--max-gap applies to ertools' reading, not to --rules " + rules)
    return HppfOptions(
        config=values.get("config"),
        exact_names=bool(values.get("exact_names")) or script,
        script_answers=script,
        **script_values(values),
    )
