"""Figures as data: a benchmark says what to draw, this module decides where it goes.

Drawing functions take a matplotlib ``Axes``; nothing here selects a backend or uses pyplot,
so importing ertools never changes matplotlib's global state.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from importlib import import_module
from pathlib import Path
from typing import Any

from ertools import atomic
from ertools.benchmarks import registry

# Results that are not a registered benchmark's -> ``module:function`` giving their figures
# (a benchmark names its own: :attr:`ertools.benchmarks.base.Benchmark.figures`).
OTHER_FIGURES: dict[str, str] = {"noise": "ertools.report.plots_noise:figure_specs"}


@dataclass(frozen=True)
class FigureSpec:
    """One figure: a file stem, a title, a size and a function drawing on one Axes."""

    name: str
    title: str
    draw: Callable[[Any], None]
    size: tuple[float, float] = (7.0, 5.0)


def figure_specs(result: Any) -> list[FigureSpec]:
    """The figures of a result, from the function its benchmark declares."""
    name = str(result.name)
    target = registry.get(name).figures if name in registry.names() else OTHER_FIGURES.get(name)
    if not target:
        return []
    module_name, _, function = target.partition(":")
    specs: list[FigureSpec] = getattr(import_module(module_name), function)(result)
    return specs


def save_figures(specs: Sequence[FigureSpec], outdir: Path, fmt: str = "png") -> list[Path]:
    """Draw every spec into its own file in ``outdir``; returns the paths written."""
    # lazy: matplotlib only when a figure is drawn (~0.3 s to import)
    from matplotlib.figure import Figure

    outdir.mkdir(parents=True, exist_ok=True)
    written: list[Path] = []
    for spec in specs:
        fig = Figure(figsize=spec.size, layout="constrained")
        ax = fig.add_subplot()
        spec.draw(ax)
        if spec.title:
            ax.set_title(spec.title)
        path = outdir / f"{spec.name}.{fmt}"
        with atomic.replacing(path) as tmp:
            fig.savefig(tmp, dpi=110, format=fmt)
        written.append(path)
    return written


def save_one_file(specs: Sequence[Any], path: Path) -> Path:
    """Every spec as one panel of one figure, stacked top to bottom, in ``path`` (its suffix
    picks the format)."""
    from matplotlib.figure import Figure  # lazy: matplotlib only when a figure is drawn

    width = max((s.size[0] for s in specs), default=6.0)
    height = sum(s.size[1] for s in specs) or 4.0
    fig = Figure(figsize=(width, height), layout="constrained")
    axes = fig.subplots(max(len(specs), 1), 1, squeeze=False)[:, 0]
    for spec, ax in zip(specs, axes, strict=False):
        spec.draw(ax)
        if spec.title:
            ax.set_title(spec.title)
    if not specs:
        axes[0].text(0.5, 0.5, "no figure for this result", ha="center", va="center")
        axes[0].set_axis_off()
    path.parent.mkdir(parents=True, exist_ok=True)
    with atomic.replacing(path) as tmp:
        fig.savefig(tmp, dpi=110)
    return path
