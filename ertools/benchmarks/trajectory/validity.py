"""Which of a comparison's robot poses are valid, and when too few are for a score: the
trajectory's validity codes from its association (:mod:`ertools.benchmarks.common.validity`).
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from ertools.benchmarks.common.validity import (
    GAP as V_GAP,
)
from ertools.benchmarks.common.validity import (
    OUTSIDE_WINDOW,
    VALID,
    Validity,
)
from ertools.benchmarks.common.validity import (
    TRACKING_LOST as V_TRACKING_LOST,
)
from ertools.benchmarks.trajectory.association import (
    COMPARED,
    TRACKING_LOST,
    UNCOVERED,
    Matched,
)

# A comparison is unscoreable when fewer than this fraction of the robot poses inside the GT
# have a valid GT pose: the statistics would then describe a part of the run chosen by the
# mocap's losses, not the run. A small number of valid pairs alone is no verdict: each pair is
# a measurement, and few of them widen the confidence interval instead (docs/uncertainty.md).
MIN_VALID_FRACTION = 0.5


def validity_codes(matched: Matched, gt_start_ns: int) -> npt.NDArray[np.int8]:
    """The validity reason of each robot pose from its association status.

    A pose compared across a GT gap (``--gaps compare``) is a ``gap`` and one compared with the
    first GT pose before the GT began (``--before-gt first``) is ``outside_window``: 2015 used
    them, but no GT was measured at their moment.
    """
    s = matched.status
    codes = np.full(s.shape, V_GAP, dtype=np.int8)  # GAP and evo's UNPAIRED
    codes[s == COMPARED] = VALID
    codes[s == TRACKING_LOST] = V_TRACKING_LOST
    codes[(s == UNCOVERED) | ((s == COMPARED) & (matched.t_ns < gt_start_ns))] = OUTSIDE_WINDOW
    codes[(s == COMPARED) & matched.across_gap] = V_GAP
    return codes


def too_few(validity: Validity) -> str | None:
    """Why the valid pairs cannot support the statistics, or None."""
    inside = validity.expected - int(validity.counts[OUTSIDE_WINDOW])
    valid = validity.valid_samples
    if valid < MIN_VALID_FRACTION * inside:
        what = ", ".join(
            f"{v} {k}" for k, v in validity.invalid_samples.items() if k != "outside_window"
        )
        return (
            f"only {valid} of the {inside} robot poses inside the GT have a valid GT pose "
            f"({what}); at least {MIN_VALID_FRACTION:.0%} are needed"
        )
    return None
