"""Progress of long work: a reporter interface, a one-line bar for terminals, and its scope.

The library prints nothing by itself. Long loops report to a :class:`Reporter` they are
handed (``progress=`` arguments) or, for the reads deep inside a benchmark's scoring, the one
the caller made current with :func:`reporting`; without one they report nothing. Reads report
bytes once per group of chunks (never per message), scoring reports runs.

Only the command line makes a :class:`Bar`: one line on stderr, drawn only when stderr is a
terminal and the work has lasted ``delay_s``, so short commands print nothing. It is ertools'
own rather than tqdm's or rich's: both are new dependencies, and import costs, for one line
of output (docs/io.md).
"""

from __future__ import annotations

import io
import os
import sys
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from contextvars import ContextVar
from typing import Protocol, TextIO


class Reporter(Protocol):
    """Receives the progress of long work (all calls on the thread doing the work)."""

    def task(self, label: str, total: int, unit: str) -> None:
        """A new stretch of work: ``total`` ``unit`` (``"B"`` bytes, ``"runs"``) to do."""

    def advance(self, n: int) -> None:
        """``n`` more units of the current task done."""


_CURRENT: ContextVar[Reporter | None] = ContextVar("ertools_progress", default=None)


def current() -> Reporter | None:
    """The reporter made current by :func:`reporting` in this context, if any."""
    return _CURRENT.get()


@contextmanager
def reporting(reporter: Reporter | None) -> Iterator[Reporter | None]:
    """Make ``reporter`` the one deep reads report to, inside the ``with`` block only."""
    token = _CURRENT.set(reporter)
    try:
        yield reporter
    finally:
        _CURRENT.reset(token)


def _amount(n: float, unit: str) -> str:
    if unit != "B":
        return f"{n:.0f}"
    for prefix in ("", "k", "M", "G"):
        if abs(n) < 1000 or prefix == "G":
            return f"{n:.0f} {prefix}B" if prefix == "" else f"{n:.1f} {prefix}B"
        n /= 1000
    return f"{n:.1f} GB"  # pragma: no cover (the loop returns)


# The bar appears only for work lasting longer than this: a command done sooner prints nothing.
DELAY_S = 0.75
# Counted work says how long is left once it has gone on this long (a pace from one or two
# items says little)
ETA_AFTER_S = 5.0


def _duration(seconds: float) -> str:
    """``40 s``, ``3 min``, ``1 h 05 min``: as precise as an estimate deserves."""
    if seconds < 60:
        return f"{max(round(seconds), 1)} s"
    minutes = round(seconds / 60)
    if minutes < 60:
        return f"{minutes} min"
    return f"{minutes // 60} h {minutes % 60:02d} min"


class Bar:
    """``ertools: reading run.bag [#####-----] 1.2/2.4 GB  85.0 MB/s`` on a terminal's stderr.

    Nothing is written unless the stream is a terminal and ``delay_s`` has passed since the
    bar was made; redraws are at most every ``interval_s``. :meth:`clear` removes the line (a
    note printed meanwhile starts on a clean line; the bar comes back at its next redraw) and
    :meth:`close` removes it for good.
    """

    WIDTH = 24
    NARROW = 10  # the bar's width on a terminal too narrow for the whole line

    def __init__(
        self,
        stream: TextIO | None = None,
        *,
        delay_s: float | None = None,
        interval_s: float = 0.1,
        clock: Callable[[], float] = time.monotonic,
        columns: int | None = None,
    ) -> None:
        self.stream = stream if stream is not None else sys.stderr
        self.columns = columns
        self.enabled = self.stream.isatty()
        self.clock = clock
        self.start = clock()
        self.delay_s = DELAY_S if delay_s is None else delay_s
        self.interval_s = interval_s
        self.label = ""
        self.unit = "B"
        self.total = 0
        self.done = 0
        self.task_start = self.start
        self.paced_from: tuple[float, int] | None = None  # (time, count) the pace runs from
        self.drawn_at = -1.0e18
        self.shown = False
        self.closed = False

    def task(self, label: str, total: int, unit: str) -> None:
        """A new stretch of work; counted work announced again unfinished, with the same total
        (a new label: ``rescoring (2 not scored)``), is the same stretch: its pace goes on."""
        again = unit == self.unit != "B" and max(total, 0) == self.total > self.done
        self.label, self.total, self.unit, self.done = label, max(total, 0), unit, 0
        if not again:
            self.task_start = self.clock()
            self.paced_from = None
        self._maybe_draw(force=True)

    def advance(self, n: int) -> None:
        self.done += n
        if self.paced_from is None:  # the first count: what was done before (cached) is not pace
            self.paced_from = (self.clock(), self.done)
        # counts of runs or bags are few and each slow: every one is shown
        self._maybe_draw(force=self.done >= self.total or self.unit != "B")

    def __call__(self, done: int) -> None:
        """Set the count (for loops that know how far they are, not how much they did)."""
        self.advance(done - self.done)

    def _maybe_draw(self, force: bool) -> None:
        if not self.enabled or self.closed:
            return
        now = self.clock()
        if now - self.start < self.delay_s or (not force and now - self.drawn_at < self.interval_s):
            return
        self.drawn_at = now
        self.shown = True
        self.stream.write("\r" + self.line(now, self._columns()) + "\x1b[K")
        self.stream.flush()

    def line(self, now: float, columns: int = 1000) -> str:
        """The text of the bar at time ``now``, fitted to ``columns``: on a narrow terminal
        the rate goes first, then the bar narrows, then the label loses its middle."""
        amounts = f"{_amount(self.done, self.unit)}/{_amount(self.total, self.unit)}"
        if self.unit != "B":
            amounts += f" {self.unit}"
        elapsed = now - self.task_start
        rate = ""
        if self.unit == "B" and elapsed > 0.2:
            rate = f"  {_amount(self.done / elapsed, 'B')}/s"
        elif self.paced_from is not None and self.done < self.total:
            # counted work (executions of a season, runs): what is left at the pace so far
            since, before = self.paced_from
            if self.done > before and now - since > ETA_AFTER_S:
                left = (now - since) / (self.done - before) * (self.total - self.done)
                rate = f"  ~{_duration(left)} left"
        head = f"ertools: {self.label}"
        for width, tail in ((self.WIDTH, rate), (self.WIDTH, ""), (self.NARROW, "")):
            filled = min(width, width * self.done // max(self.total, 1))
            text = f"{head} [{'#' * filled}{'-' * (width - filled)}] {amounts}{tail}"
            if len(text) < columns:
                break
        return fit(text, columns)

    def _columns(self) -> int:
        """The terminal's width (asked at each redraw: a window may be resized)."""
        if self.columns is not None:
            return self.columns
        try:
            width = os.get_terminal_size(self.stream.fileno()).columns
        except (AttributeError, ValueError, OSError, io.UnsupportedOperation):
            width = 0
        if width <= 0:  # not a real terminal (a test's stand-in) or one that gives no size
            width = int(os.environ.get("COLUMNS", "") or 80)
        return width

    def clear(self) -> None:
        """Remove the line, if drawn, so that other text starts at the left margin."""
        if self.shown:
            self.stream.write("\r\x1b[K")
            self.stream.flush()
            self.shown = False
            self.drawn_at = -1.0e18

    def close(self) -> None:
        self.clear()
        self.closed = True


def fit(text: str, columns: int) -> str:
    """``text`` cut to ``columns - 1`` characters: the middle of the label (between
    ``ertools: `` and `` [``) goes first, else the end.

    A line as wide as the terminal or wider wraps, and ``\r`` then returns to the start of
    its last row only: every redraw would leave a row behind.
    """
    room = max(columns - 1, 10)
    if len(text) <= room:
        return text
    head, sep, tail = text.partition(" [")
    prefix = "ertools: " if head.startswith("ertools: ") else ""
    label = head[len(prefix) :]
    keep = room - len(prefix) - len(sep) - len(tail) - 3
    if not sep or keep < 8:
        return text[:room]
    half = keep // 2
    return prefix + label[:half] + "..." + label[len(label) - (keep - half) :] + sep + tail


def clear_current() -> None:
    """Clear the current bar's line (before a note on stderr)."""
    bar = _CURRENT.get()
    if isinstance(bar, Bar):
        bar.clear()
