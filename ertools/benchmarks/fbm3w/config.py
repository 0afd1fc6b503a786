"""How an FBM3@Work score is computed (the options, as data) and its pose-source defaults.

:func:`ertools.benchmarks.fbm3w.declare.make_options` builds :class:`Fbm3wOptions` from the
declared inputs; :func:`options_2015` turns every 2015 behaviour on.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

from ertools.benchmarks.common.epsilon import (
    DEFAULT_C,
)
from ertools.benchmarks.common.inputs import DEFAULT_CONFIDENCE, DEFAULT_DRAWS, DEFAULT_SEED
from ertools.configs.fbm3w import DEFAULT_D_MIN, Fbm3wConfig
from ertools.errors import ConfigError

NAMESPACE = "fbm3w"
DEFAULT_TOPIC = "/fbm3w/robot_at_work/pose2d"
FALLBACK_TOPIC = "/fbm3w/robot_at_work/pose"
DEFAULT_FRAME = "robot_at_work"
RUN_MODES = ("states", "windows", "auto")


Window = tuple[str, float, float, float]


@dataclass(frozen=True)
class Fbm3wOptions:
    """How to score (the CLI's options, as data).

    Attributes:
        runs: ``states``, ``windows``, ``auto``, or None (windows when given, else states when
            the BmBox topic exists, else auto).
        windows: explicit runs (spec, reference, start, end) in seconds (bag-relative or epoch).
        d_min: overrides the config's d_min.
        sweep: d_min values to score every run with (``--d-min-sweep``).
        topic, frame: the pose source (default: the pose2d topic, then pose, then tf frame).
        tf_parent: the parent of ``frame`` in /tf (``world``, the mocap frame).
        time_source: ``record`` (default: the 2015 node received poses live) or ``header``.
        still_speed, min_still_s: stationary detection (auto runs and the noise estimate).
        noise_c: factor of the suggested d_min (c * epsilon).
        arc_length: compare at equal fractions of the target's arc length instead of the
            shape's own parameter (2015); removes the floor of shapes such as ``sine``.
        timeout_runs: ``unscored`` (default: a run the RefBox timed out is listed without a
            distance_error) or ``2015`` (scored on the path it covered and eligible as best
            run, as the 2015 node did).
        stopped_runs: ``counted`` (default: a run the RefBox stopped counts in
            execution_time) or ``2015`` (its time left out, as the 2015 node did).
        exact_end_payloads: RefBox END payloads read as the 2015 BmBox did (only
            ``reason: timeout`` / ``reason: stop``; :func:`ertools.states.end_reason`).
        unscoreable_runs: ``null`` (default: a run whose valid ground truth cannot support a
            score is ``unscoreable`` with no distance_error) or ``2015`` (scored from what it
            has, as the 2015 node did, with a deviation saying how much of its path was valid).
        config: runs_specifications, d_min and shapes (None: the 2015 values,
            ``configs/fbm3w.yaml``); ``d_min`` above overrides its d_min.
        confidence, draws, seed: the score intervals (level, Monte Carlo draws, 0 for none;
            seed of the draws), :mod:`ertools.benchmarks.fbm3w.intervals`.

    The values are validated once, where they come in
    (:func:`ertools.benchmarks.fbm3w.declare.make_options`).
    """

    runs: str | None = None
    windows: tuple[Window, ...] = ()
    d_min: float | None = None
    sweep: tuple[float, ...] = ()
    topic: str | None = None
    frame: str | None = None
    tf_parent: str = "world"
    time_source: str = "record"
    still_speed: float | None = None
    min_still_s: float | None = None
    noise_c: float = DEFAULT_C
    arc_length: bool = False
    timeout_runs: str = "unscored"
    stopped_runs: str = "counted"
    exact_end_payloads: bool = False
    config: Fbm3wConfig | None = None
    unscoreable_runs: str = "null"
    confidence: float = DEFAULT_CONFIDENCE
    draws: int = DEFAULT_DRAWS
    seed: int = DEFAULT_SEED


TIMEOUT_RUNS = ("unscored", "2015")
STOPPED_RUNS = ("counted", "2015")


def options_2015(options: Fbm3wOptions) -> Fbm3wOptions:
    """``options`` with every FBM3W 2015 behaviour on (``--2015``).

    Timed-out runs scored and eligible, stopped runs' time left out, RefBox END payloads read
    as the BmBox compared them, the shapes at their own parameter, and the script's hard-coded
    D_MIN unless ``--d-min`` says otherwise.

    Raises:
        ConfigError: ``--arc-length`` asked for as well (it is not 2015).
    """
    if options.arc_length:
        raise ConfigError("--2015 and --arc-length contradict each other (2015 had no arc length)")
    return replace(
        options,
        timeout_runs="2015",
        stopped_runs="2015",
        exact_end_payloads=True,
        unscoreable_runs="2015",
        d_min=DEFAULT_D_MIN if options.d_min is None else options.d_min,
    )
