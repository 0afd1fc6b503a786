"""The inputs several benchmarks declare alike, written once: the intervals' options, the
choice of scoring an unscoreable run as 2015 did, the 2015 reading of RefBox END payloads.

NumPy-free, like every ``declare`` and ``config`` module that lists them: the command line
builds a benchmark's parser from these declarations without loading the scorers.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import replace
from typing import Any

from ertools.benchmarks.base import FormerName, Input
from ertools.errors import UsageError
from ertools.frozen_dataclass import frozen_dataclass

DEFAULT_CONFIDENCE = 0.95
DEFAULT_DRAWS = 400
DEFAULT_SEED = 0
# The most draws an interval takes: 100,000 already take minutes on a sample log (the FBM3W
# sample: 10 s at 4,000 draws, 90 s at 40,000), and a typo of 10**9 would run for days and
# hold gigabytes of draws, so more is refused with this number.
MAX_DRAWS = 100_000
# numpy seeds any non-negative integer; results and reports carry the seed as an int64
MAX_SEED = 2**63 - 1
# The seed's D_MIN = c * epsilon (7.3.2): the c of the suggested d_min (``ertools noise``) and
# of FBM3@Work's default noise when a log has no still phase.
DEFAULT_C = 3.0
# The 2015 mocap_noise_statistics tool's D_INTERVAL: the bin of the noise histogram, metres.
DEFAULT_BIN = 0.00015

#: The options every ``score`` command takes for its intervals (declared once, listed by each
#: benchmark's declaration).
INTERVAL_INPUTS = (
    Input(
        "confidence",
        "float",
        "confidence level of the score intervals (default 0.95)",
        default=DEFAULT_CONFIDENCE,
        minimum=0.0,
        positive=True,
        below=1.0,
        metavar="LEVEL",
        group="intervals",
    ),
    Input(
        "draws",
        "int",
        f"Monte Carlo draws per interval source (default {DEFAULT_DRAWS}, at most {MAX_DRAWS}; "
        "0: no intervals)",
        default=DEFAULT_DRAWS,
        minimum=0,
        maximum=MAX_DRAWS,
        metavar="N",
        group="intervals",
    ),
    Input(
        "seed",
        "int",
        f"seed of the Monte Carlo draws (default {DEFAULT_SEED}): same seed, same intervals",
        default=DEFAULT_SEED,
        minimum=0,
        maximum=MAX_SEED,
        metavar="N",
        group="intervals",
    ),
)


def check_confidence(confidence: float) -> float:
    """``confidence`` if it is a level strictly between 0 and 1, else a usage error."""
    if not (math.isfinite(confidence) and 0.0 < confidence < 1.0):
        raise UsageError(f"--confidence {confidence}: give a level between 0 and 1, e.g. 0.95")
    return confidence


@frozen_dataclass
class IntervalSettings:
    """``--confidence``, ``--draws`` and ``--seed`` as one value (draws 0: no intervals)."""

    draws: int = DEFAULT_DRAWS
    seed: int = DEFAULT_SEED
    confidence: float = DEFAULT_CONFIDENCE

    @property
    def enabled(self) -> bool:
        return self.draws > 0

    @staticmethod
    def from_values(values: Mapping[str, Any]) -> IntervalSettings:
        """From resolved input values (:data:`INTERVAL_INPUTS`); a level outside (0, 1) is a
        usage error."""
        confidence = values.get("confidence")
        draws = values.get("draws")
        seed = values.get("seed")
        return IntervalSettings(
            DEFAULT_DRAWS if draws is None else int(draws),
            DEFAULT_SEED if seed is None else int(seed),
            check_confidence(DEFAULT_CONFIDENCE if confidence is None else float(confidence)),
        )


#: ``unscoreable``'s values: ``null`` (default: the verdict ``unscoreable``, no score, the
#: reason given) or ``2015`` (scored from what is left, as the 2015 nodes did, with a warning).
UNSCOREABLE_CHOICES = ("null", "2015")
SCORE_AS_2015 = "2015"

#: "Score unscoreable runs as 2015 did": one option, one meaning, one help text in every
#: benchmark (``--unscoreable 2015``, manifest key and keyword ``unscoreable``); each benchmark
#: lists it with its help group and its own former names (:func:`unscoreable_input`).
UNSCOREABLE = Input(
    "unscoreable",
    "choice",
    "a run (FBM2H: a segment; trajectory: the comparison) whose valid ground truth cannot "
    "support a score (docs/uncertainty.md): unscoreable, null scores and the reason (null, "
    "default), or 2015: scored from what is left, as the 2015 nodes did, with a warning",
    choices=UNSCOREABLE_CHOICES,
)


def unscoreable_input(group: str, *former: FormerName) -> Input:
    """:data:`UNSCOREABLE` in a benchmark's help ``group``, with the benchmark's former
    spellings of it (``--unscoreable-runs 2015``, ``--score-unscoreable``)."""
    return replace(UNSCOREABLE, group=group, former=former)


# The option every FBM benchmark has (``--2015`` / ``--rules 2015`` set it), and its help.
EXACT_FLAG = "--exact-end-payloads"
EXACT_HELP = (
    "RefBox END payloads read as the 2015 BmBox compared them: only 'reason: timeout' and "
    "'reason: stop' (the manual's bare timeout / halt then mean neither)"
)
