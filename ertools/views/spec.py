"""A figure a benchmark declares: its file stem, title and size, and how its chart is built
for that size (the size decides how far paths are thinned). Drawing it, as SVG or with
matplotlib, is :mod:`ertools.report.figures`' job."""

from __future__ import annotations

from collections.abc import Callable

from ertools.frozen_dataclass import frozen_dataclass
from ertools.views.chart import Chart


@frozen_dataclass
class ChartSpec:
    """One figure: ``build(size)`` makes its :class:`Chart` for a ``size`` in inches."""

    name: str
    title: str
    build: Callable[[tuple[float, float]], Chart]
    size: tuple[float, float] = (7.0, 5.0)
