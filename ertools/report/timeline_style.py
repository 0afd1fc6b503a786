"""Colours and labels shared by the timeline's HTML page and its static figure.

One palette for both, so the page's legend, the PNG's legend and the bars agree. The colours
are Okabe and Ito's colour-blind-safe set ("Color Universal Design", 2008): blue, bluish green,
orange and reddish purple stay distinct under the three common colour-vision deficiencies.
Problems are never shown by colour alone: their bars are hatched and outlined in black and
carry a marker.
"""

from __future__ import annotations

from ertools.benchmarks.common.teams import team_from_log_name
from ertools.timelines.model import KIND_LABELS, BagEntry

KIND_COLORS: dict[str, str] = {
    "gt": "#0072B2",  # blue
    "benchmark": "#009E73",  # bluish green
    "robot": "#E69F00",  # orange
    "other": "#CC79A7",  # reddish purple
}
# Spans of a benchmark or robot log that no GT file covers (vermillion, drawn as a strip
# under the bar: a shape, not only a colour).
UNCOVERED_COLOR = "#D55E00"
PROBLEM_EDGE = "#000000"
MARKER_FILL = "#F0E442"  # yellow, behind a black "!" or number
SESSION_FILL = "#E8ECF2"


def lane_name(bag: BagEntry) -> str:
    """The lane of a bag: its logger, or ``robot <team>`` for a robot log named by the 2015
    rockin_logger (one lane per robot, whatever the benchmark and run)."""
    # rockin_logger named robot logs ${BENCHMARK}_${DATE}_${TEAMNAME}.bag: the date differs
    # from run to run, the team does not, so the team is the robot's lane.
    if bag.kind == "robot":
        team = team_from_log_name(bag.path)
        if team is not None:
            return f"robot {team}"
    return bag.logger


__all__ = [
    "KIND_COLORS",
    "KIND_LABELS",
    "MARKER_FILL",
    "PROBLEM_EDGE",
    "SESSION_FILL",
    "UNCOVERED_COLOR",
    "lane_name",
]
