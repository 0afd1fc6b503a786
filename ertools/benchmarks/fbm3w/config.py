"""FBM3@Work's inputs (the options of ``ertools score fbm3w``, the manifest keys) and how
they become :class:`Fbm3wOptions`; :func:`options_2015` turns every 2015 behaviour on.

Every value is checked here, once: ``--d-min`` (metres, >= 0, at most 5 cm), ``--d-min-sweep``,
the run windows and the switches that contradict each other. NumPy-free: the command's parser
imports it; the readers of the files named are imported by :func:`make_options`.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import replace
from typing import TYPE_CHECKING, Any

from ertools.benchmarks.base import FormerName, Input, resolve_values, tf_value
from ertools.benchmarks.common.inputs import (
    DEFAULT_C,
    DEFAULT_CONFIDENCE,
    DEFAULT_DRAWS,
    DEFAULT_SEED,
    EXACT_HELP,
    INTERVAL_INPUTS,
    UNSCOREABLE_CHOICES,
    check_confidence,
    unscoreable_input,
)
from ertools.errors import ConfigError, UsageError
from ertools.frozen_dataclass import frozen_dataclass

if TYPE_CHECKING:  # annotations only: the config file's shapes are NumPy
    from ertools.benchmarks.fbm3w.settings import Fbm3wConfig

NAMESPACE = "fbm3w"
DEFAULT_TOPIC = "/fbm3w/robot_at_work/pose2d"
FALLBACK_TOPIC = "/fbm3w/robot_at_work/pose"
DEFAULT_FRAME = "robot_at_work"
RUN_MODES = ("states", "windows", "auto")


Window = tuple[str, float, float, float]


@frozen_dataclass
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

    The values are validated once, where they come in (:func:`make_options`).
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
    from ertools.benchmarks.fbm3w.settings import DEFAULT_D_MIN  # lazy: shapes, 60 ms

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


LEGACY = "2015 behaviour (each difference can be undone)"
SWEEP_MAX = 500  # values of --d-min-sweep: enough for a smooth curve, bounded work

INPUTS = (
    Input(
        "config",
        "path",
        "runs_specifications (Listing 14), optional d_min and shapes (default: the 2015 "
        "values, as configs/fbm3w.yaml)",
        metavar="FILE",
    ),
    Input("d_min", "float", "subsampling threshold (2015: 0.00033)", unit="m", minimum=0.0),
    Input(
        "d_min_sweep",
        "str",
        "also score every run at N values of d_min from START to STOP (metres)",
        metavar="START:STOP:N",
    ),
    Input("runs", "choice", "how to find the runs (see below)", choices=RUN_MODES),
    Input(
        "run",
        "str",
        "an explicit run (repeatable; implies --runs windows)",
        repeat=True,
        metavar="SPEC:REF_T:START_T:END_T",
    ),
    Input("runs_file", "path", "explicit runs from a YAML file", metavar="FILE"),
    Input(
        "topic",
        "str",
        "end-effector pose topic (default /fbm3w/robot_at_work/pose2d, then .../pose)",
        metavar="TOPIC",
    ),
    Input(
        "tf",
        "str",
        "take the poses from /tf PARENT -> CHILD (e.g. world:robot_at_work)",
        metavar="PARENT:CHILD",
        old_flags=("--frame",),
    ),
    Input(
        "time_source",
        "choice",
        "pose time: header stamp (default; a Pose2D has none: its record time) or bag record "
        "time (the 2015 node received the poses live)",
        default="header",
        choices=("header", "record"),
    ),
    Input(
        "arc_length",
        "flag",
        "compare at equal fractions of the target's arc length (not 2015)",
    ),
    Input(
        "timeout_runs",
        "choice",
        "a run the RefBox timed out: listed without distance_error (default), or 2015: "
        "scored on the path it covered and eligible as best run",
        default="unscored",
        choices=("unscored", "2015"),
        group=LEGACY,
    ),
    Input(
        "stopped_runs",
        "choice",
        "a run the RefBox stopped: its time counted in execution_time (default), or 2015: left out",
        default="counted",
        choices=("counted", "2015"),
        group=LEGACY,
    ),
    Input("exact_end_payloads", "flag", EXACT_HELP, group=LEGACY),
    unscoreable_input(LEGACY, FormerName("unscoreable_runs")),
    Input(
        "rules",
        "choice",
        "every behaviour of one node at once: 2015 (scripts/fbm3w 50b173b, RoCKIn 2015 "
        "Lisbon: --timeout-runs 2015 --stopped-runs 2015 --exact-end-payloads --unscoreable "
        "2015, d_min 0.00033 unless --d-min is given, no --arc-length) or ertools (default)",
        choices=("ertools", "2015"),
        group=LEGACY,
    ),
    Input("all_2015", "flag", "= --rules 2015", flag="--2015", group=LEGACY),
    Input(
        "still_speed",
        "float",
        "speed below which the marker set counts as still (default 0.004)",
        unit="m/s",
        positive=True,
    ),
    Input(
        "still_min",
        "float",
        "shortest stationary phase (default 0.5)",
        unit="s",
        positive=True,
    ),
    *INTERVAL_INPUTS,
)


def parse_sweep(text: str) -> tuple[float, ...]:
    """``START:STOP:N`` -> N evenly spaced d_min values (metres).

    Raises:
        UsageError: not three fields, negative or infinite bounds, N outside 1..500.
    """

    parts = text.split(":")
    try:
        if len(parts) != 3:
            raise ValueError
        start, stop, n = float(parts[0]), float(parts[1]), int(parts[2])
    except ValueError:
        raise UsageError(
            f"--d-min-sweep {text!r}: expected START:STOP:N, e.g. 0.0001:0.001:10"
        ) from None
    if not (math.isfinite(start) and math.isfinite(stop)) or min(start, stop) < 0:
        raise UsageError(f"--d-min-sweep {text!r}: START and STOP must be >= 0 metres")
    if not 1 <= n <= SWEEP_MAX:
        raise UsageError(f"--d-min-sweep {text!r}: N must be between 1 and {SWEEP_MAX}")
    if n == 1:
        return (start,)
    step = (stop - start) / (n - 1)
    return tuple(round(start + i * step, 12) for i in range(n))  # no 0.00039999999999999996


def _d_min(value: float, where: str) -> float:
    """A d_min in metres, refused (usage error) when it cannot be one."""

    from ertools.benchmarks.fbm3w.settings import check_d_min  # lazy: shapes, 60 ms

    try:
        return check_d_min(value, where)
    except ConfigError as err:
        raise UsageError(err.message) from None


def make_options(given: Mapping[str, Any]) -> Fbm3wOptions:
    """The values of :data:`INPUTS` -> :class:`Fbm3wOptions` (the config file read).

    Raises:
        UsageError: a value out of range, contradicting switches (exit 2).
        ConfigError: an unreadable config or runs file, a malformed run window (exit 1).
    """

    from ertools.benchmarks.fbm3w.runs import (  # lazy: NumPy, the run windows, 120 ms
        parse_run_spec,
        parse_runs_file,
    )
    from ertools.benchmarks.fbm3w.settings import load_fbm3w_config  # lazy: shapes, 60 ms
    from ertools.configs._yaml import load_yaml  # lazy: PyYAML, 30 ms

    v = resolve_values(INPUTS, given)
    windows = [parse_run_spec(text, i) for i, text in enumerate(v["run"])]
    if v["runs_file"] is not None:
        windows += parse_runs_file(load_yaml(v["runs_file"], "run list"), str(v["runs_file"]))
    if windows and v["runs"] not in (None, "windows"):
        raise UsageError(
            f"--run/--runs-file give explicit windows; they contradict --runs {v['runs']}"
        )
    node = bool(v["all_2015"]) or v["rules"] == "2015"
    if node and v["arc_length"]:
        raise UsageError("--2015 and --arc-length contradict each other (2015 had no arc length)")
    if v["topic"] is not None and v["tf"] is not None:
        raise UsageError("give either --topic or --tf, not both")
    tf = tf_value("--tf", v["tf"])
    d_min = None if v["d_min"] is None else _d_min(v["d_min"], "--d-min")
    sweep = () if v["d_min_sweep"] is None else parse_sweep(v["d_min_sweep"])
    for value in sweep:
        _d_min(value, "--d-min-sweep")
    options = Fbm3wOptions(
        runs=v["runs"],
        windows=tuple(windows),
        d_min=d_min,
        sweep=sweep,
        topic=v["topic"],
        frame=None if tf is None else tf[1],
        tf_parent="world" if tf is None else tf[0],
        time_source=v["time_source"],
        still_speed=v["still_speed"],
        min_still_s=v["still_min"],
        arc_length=v["arc_length"],
        timeout_runs=v["timeout_runs"],
        stopped_runs=v["stopped_runs"],
        exact_end_payloads=v["exact_end_payloads"],
        unscoreable_runs=v["unscoreable"] or UNSCOREABLE_CHOICES[0],
        config=load_fbm3w_config(v["config"]),
        confidence=check_confidence(v["confidence"]),
        draws=v["draws"],
        seed=v["seed"],
    )
    return options_2015(options) if node else options
