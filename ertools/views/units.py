"""The units the human-facing pages and figures show, one per kind of number.

Results, ``score.yaml``/``score.json`` and the CSV files keep the seed's SI units (metres,
radians, seconds) or whatever unit their column name says (``gt_spread_mm``). Only what a
person reads converts, and only here: every length in millimetres (2015 errors are a few
millimetres: 0.000639 m reads badly), every angle in degrees, every time in seconds. Each
header and axis label carries its unit: ``distance_error (mm)``.
"""

from __future__ import annotations

import math
import re
from typing import Any

from ertools.frozen_dataclass import frozen_dataclass
from ertools.timeutil import EPOCH_THRESHOLD_S


@frozen_dataclass
class Quantity:
    """A kind of number: the unit shown and the factor from each source unit to it."""

    unit: str
    factors: dict[str, float]  # source unit -> multiply by this to get ``unit``


# The one table of display units, keyed by quantity.
QUANTITIES: dict[str, Quantity] = {
    "length": Quantity("mm", {"m": 1000.0, "cm": 10.0, "mm": 1.0}),
    "angle": Quantity("deg", {"rad": 180.0 / math.pi, "deg": 1.0}),
    "time": Quantity("s", {"s": 1.0, "ms": 1e-3, "ns": 1e-9}),
}

# Decimals shown per quantity, in its display unit (mm, deg, s): what the data resolves. Mocap
# positions are good to ~0.1 mm (0.1-0.3 mm marker noise), so 0.01 mm keeps one guard digit;
# orientations to ~0.05 deg; the loggers stamp to the millisecond.
DECIMALS = {"length": 2, "angle": 2, "time": 3}

# Column or score key -> (quantity, the unit the value is stored in). Keys of every
# benchmark's tables() and headline; a unit suffix in the name (``_m``, ``_rad``) is dropped
# from the header, which states the display unit instead.
_LENGTH_M = (
    "distance_error best_distance_error d_min path_length raw_path_length target_length "
    "shape_floor x y dx dy target_x target_y robot_x robot_y robot_z gt_x gt_y gt_z error "
    "trans_error_m position_error rmse median max position_accuracy position_accuracy_m "
    "distance_error_m epsilon suggested_d_min p50 p90 p95 p99 from_m to_m max_position_error "
    "dinstance_error translation spread_m"  # dinstance: the seed's spelling (Listing 13)
)
_ANGLE_RAD = (
    "target_theta robot_theta orientation_error_rad dtheta_unwrapped_rad orientation_accuracy "
    "orientation_accuracy_rad frame_yaw robot_yaw gt_yaw yaw_error orientation_error "
    "orientation_error_2015"
)
_ANGLE_DEG = "theta_deg gt_theta_deg gt_spread_deg theta_error_deg"
_TIME_S = (
    "execution_time execution_time_s segment_time_s start_s reached_s goal_s t_rel_s "
    "reference_time start_time end_time start end duration t from to offset estimated_offset "
    "offset_uncertainty max_gap segment_time start_segment_time end_segment_time result_s"
)
COLUMNS: dict[str, tuple[str, str]] = {
    **{k: ("length", "m") for k in _LENGTH_M.split()},
    "gt_spread_mm": ("length", "mm"),
    **{k: ("angle", "rad") for k in _ANGLE_RAD.split()},
    **{k: ("angle", "deg") for k in _ANGLE_DEG.split()},
    **{k: ("time", "s") for k in _TIME_S.split()},
    "gt_offset_ms": ("time", "ms"),
    "spread_deg": ("angle", "deg"),
    # ``theta`` is radians in FBM2@Home's poses and degrees in FBM1's (as in 2015): the
    # dotted key of a score says which.
    "robot_pose.theta": ("angle", "rad"),
    "target_pose.theta": ("angle", "rad"),
    "answer.theta": ("angle", "deg"),
    "ground_truth.theta": ("angle", "deg"),
    "error.theta": ("angle", "deg"),
}
# Columns named by pattern: the d_min sweep's ``run_<i>`` (distance_error of run i).
_PATTERNS: tuple[tuple[re.Pattern[str], tuple[str, str]], ...] = (
    (re.compile(r"run_\d+"), ("length", "m")),
)
_SUFFIX = re.compile(r"_(m|mm|cm|rad|deg|s|ms)$")


def quantity_of(name: str) -> tuple[str, str] | None:
    """(quantity, stored unit) of a column or key, or None for counts, ratios and text.

    A dotted key (``runs_details.0.distance_error``) is looked up by its last two parts
    (``robot_pose.theta``), then its last part.
    """
    bracket = _BRACKET.fullmatch(name)
    if bracket is not None:  # the RSBB's keys state their unit: position_accuracy[m]
        return _BRACKET_UNITS[bracket.group(2)]
    last_two = ".".join(name.rsplit(".", 2)[-2:])
    if last_two in COLUMNS:
        return COLUMNS[last_two]
    key = name.rsplit(".", 1)[-1]
    if key in COLUMNS:
        return COLUMNS[key]
    for pattern, spec in _PATTERNS:
        if pattern.fullmatch(key):
            return spec
    # a score's interval (``distance_error_interval``, CSV ``distance_error_m_low``): its unit
    bound = _BOUND.fullmatch(name)
    if bound is not None:
        return quantity_of(bound.group(1))
    return None


_BOUND = re.compile(r"(.+)_(interval|low|high)")
_BRACKET = re.compile(r"(.+?) ?\[(m|rad|s)\]")
_BRACKET_UNITS = {"m": ("length", "m"), "rad": ("angle", "rad"), "s": ("time", "s")}


def without_unit(name: str) -> str:
    """A key without the unit its name states (``position_accuracy[m]`` ->
    ``position_accuracy``): the page shows the value in its display unit instead."""
    bracket = _BRACKET.fullmatch(name)
    return bracket.group(1) if bracket is not None else name


def is_number(value: Any) -> bool:
    return isinstance(value, int | float) and not isinstance(value, bool)


def is_epoch(name: str, values: list[Any]) -> bool:
    """A time column of instants: every number in it is epoch seconds (after 2001)."""

    if quantity_of(name) != ("time", "s"):
        return False
    numbers = [v for v in values if is_number(v) and not math.isnan(v)]
    return bool(numbers) and all(v > EPOCH_THRESHOLD_S for v in numbers)


def factor(quantity: str, stored: str) -> float:
    """What a value stored in ``stored`` units is multiplied by to show it."""
    return QUANTITIES[quantity].factors[stored]


def fixed(value: float, quantity: str) -> str:
    """``value`` (in the display unit of ``quantity``) at :data:`DECIMALS`; a value smaller
    than the last decimal but not zero (a clock offset's uncertainty of 0.2 ms) keeps two
    significant digits rather than reading as 0."""
    text = f"{value:.{DECIMALS[quantity]}f}"
    if value != 0 and float(text) == 0:
        return f"{value:.2g}"
    return text


def unit(quantity: str) -> str:
    return QUANTITIES[quantity].unit


def label(text: str, quantity: str) -> str:
    """An axis label or header with its unit: ``label("distance error", "length")``."""
    return f"{text} ({unit(quantity)})"


def header(name: str) -> str:
    """A column's header with its display unit; names of unitless columns unchanged."""
    spec = quantity_of(name)
    if spec is None:
        return name
    return label(_SUFFIX.sub("", name) if _SUFFIX.search(name) else name, spec[0])


def display(name: str, value: Any) -> Any:
    """``value`` of column ``name`` in its display unit (numbers only; others unchanged)."""
    spec = quantity_of(name)
    if spec is None or not is_number(value):
        return value
    return float(value) * factor(*spec)
