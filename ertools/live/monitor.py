"""The 2015 log_monitor (seed 5.2): watch the log being written and warn when it goes wrong.

Every ``interval_s`` the monitor looks at the log folder and warns when

* no file is being written (none unfinished and recently modified);
* several files are being written at once (two recorders on one folder);
* the file being written grew less than ``min_growth_bps`` bytes per second (2015:
  ``log_size_growth = 50 * 1000`` bytes per 2-second check of a ROS 1 bag);
* a pose topic's rate fell below ``drop_fraction`` of the best rate it had, or below
  ``min_rate_hz`` (MCAP files only: the monitor reads the records added since the last check).

A file "is being written" when it is not closed (an MCAP without its closing magic, a ROS 1
``.bag.active``) and was modified within ``stale_s``. The first look only takes a baseline:
rates need two looks, so ``--once`` waits one interval.
"""

from __future__ import annotations

import time
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

from ertools.frozen_dataclass import frozen_dataclass
from ertools.live.tail import McapTail, is_finished

PATTERNS = ("*.mcap", "*.bag.active")


def _mtime(path: Path) -> float:
    try:
        return path.stat().st_mtime
    except OSError:
        return float("-inf")


def _size(path: Path) -> int:
    try:
        return path.stat().st_size
    except OSError:
        return 0


@frozen_dataclass
class MonitorOptions:
    """What counts as healthy (see the module doc)."""

    directory: Path
    interval_s: float = 2.0  # the 2015 script looked every 2 s
    min_growth_bps: float = 2_000.0
    stale_s: float | None = None  # default: 3 intervals, at least 5 s
    drop_fraction: float = 0.5
    min_rate_hz: float | None = None
    rate_topic_suffix: str = "/pose"
    prefix: str = ""  # only files whose name starts with it (two loggers, one folder)

    @property
    def stale_after_s(self) -> float:
        return self.stale_s if self.stale_s is not None else max(3.0 * self.interval_s, 5.0)


@frozen_dataclass
class MonitorCheck:
    """One look at the folder."""

    active: tuple[Path, ...]
    newest: Path | None
    size_bytes: int
    growth_bps: float | None
    rates_hz: dict[str, float]
    warnings: tuple[str, ...]
    window_end_ns: int | None = None  # log time of the newest message (rates end there)

    def status_line(self) -> str:
        if self.newest is None:
            return "no log files"
        parts = [f"{self.newest.name} {self.size_bytes / 1e6:.2f} MB"]
        if self.growth_bps is not None:
            parts[0] += f" +{self.growth_bps / 1e3:.1f} kB/s"
        if self.rates_hz:
            parts.append(", ".join(f"{t} {r:.1f} Hz" for t, r in sorted(self.rates_hz.items())))
        return " | ".join(parts)


@dataclass
class _Followed:
    path: Path
    size: int
    t: float
    tail: McapTail | None
    times: dict[str, deque[int]] = field(default_factory=dict)
    best: dict[str, float] = field(default_factory=dict)
    latest_ns: int | None = None


class Monitor:
    """Stateful checker: call :meth:`check` every interval."""

    def __init__(self, options: MonitorOptions) -> None:
        self.options = options
        self._followed: _Followed | None = None

    def _files(self) -> list[Path]:
        """Log files, oldest first; one removed or renamed meanwhile (a split) is left out."""
        d = self.options.directory
        stamped = []
        for path in {p for pattern in PATTERNS for p in d.glob(self.options.prefix + pattern)}:
            try:
                stamped.append((path.stat().st_mtime, path.name, path))
            except OSError:
                continue
        return [p for _, _, p in sorted(stamped)]

    def _is_active(self, path: Path, wall: float) -> bool:
        try:
            recent = wall - path.stat().st_mtime <= self.options.stale_after_s
        except OSError:
            return False
        if path.name.endswith(".bag.active"):
            return recent
        return recent and not is_finished(path)

    def check(self, now: float | None = None, wall: float | None = None) -> MonitorCheck:
        """Look once. ``now`` (monotonic s) and ``wall`` (epoch s) are for tests."""
        now = time.monotonic() if now is None else now
        wall = time.time() if wall is None else wall
        opts = self.options
        warnings: list[str] = []
        if not opts.directory.is_dir():
            return MonitorCheck((), None, 0, None, {}, (f"{opts.directory} is not a folder",))
        files = self._files()
        active = [p for p in files if self._is_active(p, wall)]
        if len(active) > 1:
            names = ", ".join(p.name for p in active)
            warnings.append(f"several files are being written at once: {names}")
        if not active:
            if files:
                newest = files[-1]
                age = wall - _mtime(newest)
                closed = "closed" if is_finished(newest) else "unfinished"
                warnings.append(
                    f"no log file is being written in {opts.directory} (newest: {newest.name}, "
                    f"{closed}, last modified {age:.0f} s ago)"
                )
            else:
                warnings.append(f"no log file in {opts.directory}")
            self._followed = None
            newest_path = files[-1] if files else None
            size = _size(newest_path) if newest_path else 0
            return MonitorCheck(tuple(active), newest_path, size, None, {}, tuple(warnings))

        path = active[-1]
        size = _size(path)
        f = self._followed
        growth: float | None = None
        rates: dict[str, float] = {}
        if f is None or f.path != path:
            tail = McapTail(path) if path.suffix == ".mcap" else None
            f = self._followed = _Followed(path, size, now, tail)
            if tail is not None:
                self._update_rates(f, rates)  # baseline: read what is there
                rates = {}
        else:
            dt = now - f.t
            if dt > 0:
                growth = (size - f.size) / dt
                if growth < opts.min_growth_bps:
                    warnings.append(
                        f"{path.name} grew {growth:.0f} B/s over the last {dt:.1f} s, expected "
                        f">= {opts.min_growth_bps:.0f} B/s"
                    )
            f.size, f.t = size, now
            if f.tail is not None:
                self._update_rates(f, rates)
                warnings += self._rate_warnings(f, rates)
        end = f.latest_ns if rates else None
        return MonitorCheck(tuple(active), path, size, growth, rates, tuple(warnings), end)

    def _update_rates(self, f: _Followed, rates: dict[str, float]) -> None:
        """Per pose topic: messages in the last interval of log time, divided by it.

        Log time, not arrival: the recorder writes a chunk every flush, so counting messages per
        check would jitter by a chunk; the window ends at the newest message of any topic, so
        a body that stopped while others go on shows 0.
        """
        assert f.tail is not None
        window_ns = int(self.options.interval_s * 1e9)
        suffix = self.options.rate_topic_suffix
        for m in f.tail.poll(window_ns=window_ns):
            if m.topic.endswith(suffix):
                f.times.setdefault(m.topic, deque()).append(m.log_time_ns)
        if f.tail.corrupt:
            return
        latest = max((d[-1] for d in f.times.values() if d), default=None)
        if latest is None:
            return
        f.latest_ns = latest
        for topic, d in f.times.items():
            while d and d[0] <= latest - window_ns:
                d.popleft()
            rates[topic] = len(d) / self.options.interval_s

    def _rate_warnings(self, f: _Followed, rates: dict[str, float]) -> list[str]:
        out = []
        opts = self.options
        if f.tail is not None and f.tail.corrupt:
            out.append(f"{f.path.name}: {f.tail.corrupt}")
        for topic, rate in sorted(rates.items()):
            best = f.best.get(topic, 0.0)
            if best > 0 and rate < opts.drop_fraction * best:
                out.append(f"{topic} rate dropped to {rate:.1f} Hz (was {best:.1f} Hz)")
            elif opts.min_rate_hz is not None and rate < opts.min_rate_hz:
                out.append(f"{topic} rate {rate:.1f} Hz is below {opts.min_rate_hz:g} Hz")
            f.best[topic] = max(best, rate)
        return out


def watch(
    options: MonitorOptions,
    *,
    duration_s: float | None = None,
    once: bool = False,
    status: Callable[[str], None],
    warn: Callable[[str], None],
    sleep: Callable[[float], None] = time.sleep,
) -> int:
    """Check every interval until ``duration_s`` (forever when None); returns warnings seen.

    ``once``: a baseline look, one interval, one reported look.
    """
    monitor = Monitor(options)
    monitor.check()  # baseline
    start = time.monotonic()
    count = 0
    while True:
        sleep(options.interval_s)
        result = monitor.check()
        status(result.status_line())
        for w in result.warnings:
            warn(w)
        count += len(result.warnings)
        if once or (duration_s is not None and time.monotonic() - start >= duration_s):
            return count
