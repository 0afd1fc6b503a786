"""The report's figure renderer and path thinning: the same pictures as matplotlib's own
``savefig`` of the full data (issue 29: cheaper figures must stay as informative)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest

from ertools.report.figures import DPI, FigureSpec, render
from ertools.views.thinning import thin_path, thin_series

matplotlib = pytest.importorskip("matplotlib")
from matplotlib.figure import Figure  # noqa: E402
from matplotlib.image import imread  # noqa: E402


def _savefig(spec: FigureSpec, path: Path) -> None:
    """What the reports did before issue 29: a new figure, constrained layout, savefig."""
    fig = Figure(figsize=spec.size, layout="constrained")
    ax = fig.add_subplot()
    spec.draw(ax)
    if spec.title:
        ax.set_title(spec.title)
    fig.savefig(path, dpi=DPI)


def _busy(ax: Any) -> None:
    rng = np.random.default_rng(3)
    x = np.linspace(0.0, 10.0, 500)
    ax.plot(x, np.sin(x), label="a line")
    dots = ax.scatter(x[::10], np.cos(x[::10]), c=x[::10], label="coloured dots")
    ax.figure.colorbar(dots, ax=ax, label="colour (mm)")
    right = ax.twinx()
    right.bar(np.arange(5), rng.uniform(1, 3, 5), alpha=0.3, color="tab:orange")
    right.set_ylabel("bars")
    ax.set_xlabel("x (s)")
    ax.set_ylabel("y (mm)")
    ax.legend(loc="best", fontsize="small")
    ax.grid(True, lw=0.3)


def _plain(ax: Any) -> None:
    ax.bar([0, 1, 2], [3.0, 1.0, 2.0], color="tab:green")
    ax.set_xticks([0, 1, 2])
    ax.set_ylabel("distance_error (mm)")


def _pixels(path: Path) -> np.ndarray:
    return np.asarray(imread(path))


@pytest.mark.slow
def test_render_draws_what_savefig_draws(tmp_path: Path) -> None:
    # Two specs of the same size one after the other: the second is drawn on the canvas the
    # first used, and nothing of the first (its colorbar, its twin axes) may remain.
    busy = FigureSpec("busy", "A busy figure", _busy, (8.0, 5.5))
    plain = FigureSpec("plain", "A plain figure", _plain, (8.0, 5.5))
    for spec in (busy, plain, busy):
        render(spec, tmp_path / f"new_{spec.name}.png")
        _savefig(spec, tmp_path / f"old_{spec.name}.png")
        new = _pixels(tmp_path / f"new_{spec.name}.png")
        old = _pixels(tmp_path / f"old_{spec.name}.png")
        assert new.shape == old.shape == (605, 880, 4)
        assert np.array_equal(new, old), spec.name
    assert (tmp_path / "new_busy.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_render_writes_vector_formats_through_matplotlib(tmp_path: Path) -> None:
    render(FigureSpec("plain", "", _plain, (4.0, 3.0)), tmp_path / "plain.svg")
    text = (tmp_path / "plain.svg").read_text(encoding="utf-8")
    assert text.lstrip().startswith("<?xml") and "<svg" in text


def _hour(rng: np.random.Generator) -> np.ndarray:
    """An hour at 120 Hz (432,000 poses, metres): standing with 0.2 mm noise for 40 minutes,
    then driving three 1 m circles, with a tracking loss (NaN) in between."""
    n_stand, n_move = 288_000, 144_000
    stand = np.array([0.5, -0.2]) + rng.normal(0.0, 0.0002, (n_stand, 2))
    a = np.linspace(0.0, 6 * np.pi, n_move)
    move = np.c_[0.5 + np.cos(a) - 1.0, -0.2 + np.sin(a)] + rng.normal(0.0, 0.0002, (n_move, 2))
    xy = np.r_[stand, move]
    xy[300_000:300_120] = np.nan
    return xy


@pytest.mark.slow
def test_thin_path_keeps_what_the_figure_shows(tmp_path: Path) -> None:
    xy = _hour(np.random.default_rng(7))
    size = (7.0, 6.0)
    kept = thin_path(xy, size)
    # what is dropped: points that stay in the cell of the one before them (cells of half a
    # pixel: 1.3 mm here). Driving at 0.13 mm per sample the robot stays ~10 samples in a
    # cell; the 0.2 mm noise makes it flip between neighbouring cells at their borders, and
    # those flips are kept (they are what the full line draws too): ~40 % of the hour stays.
    assert len(kept) < 0.6 * len(xy)
    assert len(thin_path(xy[288_000:], size)) < len(xy[288_000:]) / 2.5
    # the first and last points and the extremes of each axis stay
    for got in (xy[0], xy[-1]):
        assert (kept == got).all(axis=1).any()
    for column in (0, 1):
        for pick in (np.nanargmin, np.nanargmax):
            assert (kept == xy[pick(xy[:, column])]).all(axis=1).any()
    # the break stays a break: the NaN rows and the points at both of its ends
    assert np.isnan(kept).any()
    for edge in (xy[299_999], xy[300_120]):
        assert (kept == edge).all(axis=1).any()

    def draw(points: np.ndarray) -> Any:
        return lambda ax: (ax.plot(points[:, 0], points[:, 1], lw=1.0), ax.set_aspect("equal"))

    render(FigureSpec("full", "", draw(xy), size), tmp_path / "full.png")
    render(FigureSpec("thin", "", draw(kept), size), tmp_path / "thin.png")
    full, thin = _pixels(tmp_path / "full.png"), _pixels(tmp_path / "thin.png")
    differ = np.abs(full[..., :3] - thin[..., :3]).max(axis=2) > 0.25
    # the same picture: antialiased edges may move by a shade where the line is rebuilt
    # from fewer vertices (half a cell = a quarter pixel), no pixel may appear or vanish
    assert differ.sum() < 0.002 * differ.size, differ.sum()


def test_thin_path_passes_short_and_constant_paths() -> None:
    two = np.array([[0.0, 0.0], [1.0, 1.0]])
    assert np.array_equal(thin_path(two, (4.0, 3.0)), two)
    still = np.zeros((1000, 3))
    assert np.array_equal(thin_path(still, (4.0, 3.0)), still[[0, -1]])


def test_thin_series_keeps_every_column_extreme() -> None:
    # 100,000 samples over a 2-inch axis (220 px columns): ~455 samples per column
    t = np.arange(100_000, dtype=float)
    y = np.sin(t / 5000.0)
    y[12_345] = 40.0  # a spike
    y[77_777] = -40.0
    y[50_000:50_010] = np.nan
    keep = thin_series(t, y, 2.0)
    assert np.all(np.diff(keep) > 0)  # in time order, no repeats
    assert len(keep) <= 4 * 220 + 30
    for must in (0, 99_999, 12_345, 77_777, 49_999, 50_010, *range(50_000, 50_010)):
        assert must in keep
    # per column of 100,000 / 220 samples: the kept ones hold its lowest and highest value
    column = np.minimum((t / t[-1] * 220).astype(int), 219)
    finite = np.isfinite(y)
    for c in range(220):
        mine = (column == c) & finite
        kept = np.zeros_like(mine)
        kept[keep] = True
        assert y[mine & kept].max() == y[mine].max()
        assert y[mine & kept].min() == y[mine].min()
    short = thin_series(t[:100], y[:100], 2.0)
    assert np.array_equal(short, np.arange(100))
