"""Whether an FBM1 ground truth is a measurement: the validity of the table and board samples
in its window, and the reason when a body was not measured there (issue 28)."""

from __future__ import annotations

import numpy as np

from ertools.benchmarks.common.validity import (
    REASONS,
    SampleMask,
    Validity,
    combine,
    sample_codes,
    summarise,
    unmeasured,
)
from ertools.benchmarks.fbm1.config import Fbm1Options
from ertools.benchmarks.fbm1.gt import GroundTruth
from ertools.streams import PoseStream
from ertools.timeutil import NS_PER_S


def gt_validity(
    origin: PoseStream,
    board: PoseStream,
    gt: GroundTruth,
    options: Fbm1Options,
    masks: tuple[SampleMask, SampleMask] | None,
    t0_ns: int = 0,
    until_ns: int | None = None,
) -> tuple[Validity, str | None]:
    """Both bodies' validity in the ground truth's window (the samples averaged, or those a
    lookup interpolated between: within --max-gap of its moment), and why it is no
    measurement: a body without one valid sample within --max-gap of the moment it stands for
    (the window's end, the goal; or the lookup's moment), all repeated poses of a lost marker
    set or NaN, that moved more than --still while unseen (seen again before ``until_ns``,
    the result, after which the board may be taken away) or was never seen before
    (:func:`~ertools.benchmarks.common.validity.unmeasured`)."""
    max_gap = round(options.gt.max_gap_s * NS_PER_S)
    if masks is None:
        masks = (body_mask(origin), body_mask(board))
    lookup = gt.start_ns == gt.end_ns
    a, b = (gt.start_ns - max_gap, gt.end_ns + max_gap) if lookup else (gt.start_ns, gt.end_ns)
    validity = combine(tuple(summarise(m, a, b, gap_s=options.gt.max_gap_s) for m in masks))
    bodies = ((masks[0], origin, "origin"), (masks[1], board, "ref_board"))
    for mask, stream, name in bodies:
        # the moment the ground truth stands for: the window's end (the goal) or the lookup
        window = (gt.end_ns - max_gap, gt.end_ns + max_gap)
        if unmeasured(mask, stream.xyz, *window, options.gt.still_m, until_ns):
            lo = int(np.searchsorted(mask.t_ns, a))
            hi = int(np.searchsorted(mask.t_ns, b, side="right"))
            what = ", ".join(
                f"{int(np.sum(mask.codes[lo:hi] == c))} {REASONS[c]}"
                for c in np.unique(mask.codes[lo:hi]).tolist()
            )
            return validity, (
                f"no valid {name} pose within {options.gt.max_gap_s:g} s of the ground truth's "
                f"{'moment' if lookup else 'window end'} t={(gt.end_ns - t0_ns) / NS_PER_S:.3f} "
                f"s ({what or 'no sample'} in the window), and it moved while unseen (tracking "
                "lost)"
            )
    return validity, None


def body_mask(stream: PoseStream) -> SampleMask:
    return sample_codes(stream.t_ns, stream.xyz, stream.quat_xyzw)
