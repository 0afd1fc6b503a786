"""How an FBM2@Home score is computed (the options, as data) and its defaults.

:func:`ertools.benchmarks.fbm2h.declare.make_options` builds :class:`Fbm2hOptions` from the
declared inputs.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from ertools.benchmarks.common.uncertainty import (
    DEFAULT_CONFIDENCE,
    DEFAULT_DRAWS,
    DEFAULT_SEED,
)
from ertools.benchmarks.fbm2h.segments import StopParams
from ertools.configs.transform import (
    MarkerTransform,
)

NAMESPACE = "fbm2h"  # of the state topics
DEFAULT_TOPIC = "/fbm2h/robot_at_home/pose"
# The 2015 node looked the marker set up in tf (scripts/fbm2h): world -> robot_at_home.
TF_2015 = ("world", "robot_at_home")
DEFAULT_MAX_GAP_S = 0.1


# The nodes ``--rules`` reproduces: rockin-robot-challenge/benchmark_and_scoring_fbm
# scripts/fbm2h, read at each commit (the version table of docs/fidelity.md). One file (blob
# 9abe295) served the three competitions: the names say which one a score reproduces.
NODES = {
    "2015": "scripts/fbm2h at 50b173b (RoCKIn 2015 Lisbon; 0e7a367's arithmetic)",
    "2016": "scripts/fbm2h at 40ba68b (the Lisbon 2016 second local competition; = 50b173b)",
    "2017": "scripts/fbm2h at 89dfa75 (the Lisbon 2017 major tournament; = 50b173b)",
}
RULE_SETS = ("ertools", *NODES)


@dataclass(frozen=True)
class Fbm2hOptions:
    """Everything ``ertools score fbm2h`` can be told.

    Attributes:
        goal: Listing 10 goal list file; None = the goal payload in the state topics.
        transform: Listing 11 file; None with ``team``+``transforms_dir`` = DIR/transform-TEAM.yaml;
            None otherwise = identity (said in the warnings).
        team: picks the transform with ``transforms_dir``; alone it changes nothing here (the
            CLI keeps it as the result's team, see :mod:`ertools.benchmarks.common.teams`).
        topic / tf_frame: where the marker set's poses are (PoseStamped/Pose2D topic, or a /tf
            child frame of ``world``).
        time_source: ``header`` (mocap stamp) or ``record`` (bag time).
        reached: ``states``, ``timing``, ``auto`` or None (states when present).
        timing: the timing file for ``reached == "timing"``.
        max_gap_s: a reached moment needs a GT sample this close.
        hits: the referee's count of hits.
        orientation_2015: compute orientation errors as 2015 did (unwrapped).
        unscored_2015: accuracies as 2015 computed them when segments are not scored: the
            sums over the scored segments divided by N (the waypoints), the segment the RefBox
            timed out counted in execution_time (``--unscored-segments 2015``).
        segment_clock: with ``reached`` states, ``client`` (a segment ends at the Client's
            COMPLETED_GOAL) or ``bmbox`` (the 2015 node's clock: BmBox messages at both ends,
            ``--segment-clock bmbox``); see :func:`ertools.benchmarks.fbm2h.segments.from_states`.
        unscoreable_2015: a reached moment whose only ground truth within ``max_gap_s`` is
            invalid (repeated poses of a lost marker set) is scored from it as 2015 did, with a
            warning (``--unscoreable 2015``); by default the segment has no GT.
        pose_2015: with no ``topic``/``tf_frame``, read the marker set from /tf
            ``world -> robot_at_home`` first, the 2015 node's source (``--2015``).
        exact_end_payloads: RefBox END payloads read as the 2015 BmBox did (only
            ``reason: timeout`` / ``reason: stop``; :func:`ertools.states.end_reason`).
        namespace: the benchmark namespace of the state topics.
        stops: thresholds for ``auto``.
        confidence, draws, seed: the score intervals (level, Monte Carlo draws, 0 for none;
            seed), :mod:`ertools.benchmarks.fbm2h.intervals`.
        marker_transform: a transform already in hand (``ertools audit``: the one the live
            score says the node used); None = from ``transform``/``team``, else identity.
        rules: the node every 2015 behaviour reproduces (``2015``, ``2016``, ``2017``: keys
            of :data:`NODES`), or ``ertools`` (the single options decide).
    """

    goal: Path | None = None
    transform: Path | None = None
    team: str | None = None
    transforms_dir: Path | None = None
    topic: str | None = None
    tf_frame: str | None = None
    tf_parent: str = "world"
    time_source: str = "header"
    reached: str | None = None
    timing: Path | None = None
    max_gap_s: float = DEFAULT_MAX_GAP_S
    hits: int | None = None
    orientation_2015: bool = False
    unscored_2015: bool = False
    segment_clock: str = "client"
    pose_2015: bool = False
    exact_end_payloads: bool = False
    namespace: str = NAMESPACE
    unscoreable_2015: bool = False
    stops: StopParams = field(default_factory=StopParams)
    marker_transform: MarkerTransform | None = None
    confidence: float = DEFAULT_CONFIDENCE
    draws: int = DEFAULT_DRAWS
    seed: int = DEFAULT_SEED
    rules: str = "ertools"
