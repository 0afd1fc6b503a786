"""The toy's three stages: the poses read (``load``), the runs found (``find_runs``: one, the
whole log), the result (``score_runs``)."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

from ertools.io.model import PoseSource
from ertools.io.reader import read_pose_source
from ertools.streams import PoseStream, Provenance
from tests.helpers.toybench.config import ToyOptions
from tests.helpers.toybench.formula import mean_x, measured
from tests.helpers.toybench.result import ToyResult
from tests.helpers.toybench.rules import RULE_NAN_POSES


def load(logs: Sequence[Path], options: ToyOptions) -> PoseStream:
    """The marker poses of the logs (a missing topic: a ``TopicError`` naming it)."""
    return read_pose_source(list(logs), PoseSource(topic=options.topic))


def find_runs(loaded: PoseStream, options: ToyOptions) -> None:
    """One run: the whole log."""
    return None


def score_runs(loaded: PoseStream, runs: None, options: ToyOptions) -> ToyResult:
    """The count and mean x, with the deviation from the original node when it applies."""
    keep = measured(loaded.xyz)
    unmeasured = len(loaded) - int(keep.sum())
    counted = len(loaded) if options.count_nan else len(loaded) - unmeasured
    deviations = ()
    if unmeasured and not options.count_nan:
        detail = f"{unmeasured} pose(s) without a position not counted"
        deviations = (RULE_NAN_POSES.deviation(detail),)
    return ToyResult(
        count=counted * options.scale,
        mean_x=mean_x(loaded.xyz, keep),
        deviations=deviations,
        provenance=Provenance(
            inputs=(loaded.source,),
            parameters=(("scale", str(options.scale)), ("count_nan", str(options.count_nan))),
        ),
    )
