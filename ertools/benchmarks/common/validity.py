"""Validity masks: why each ground-truth sample a scorer uses or skips is (not) a measurement.

Every sample gets one int8 reason code (:data:`REASONS`), computed for a whole stream at once
(:func:`sample_codes`), then summarised over a scored window (:func:`summarise`): the fraction
of valid samples, the count of each invalid reason and the invalid spans (where the valid data
stops and starts again, for the tables and, through
:mod:`ertools.benchmarks.common.path_gaps`, the path plots). The benchmarks turn it into a
verdict: :func:`coverage_problem` (FBM3W's path), :func:`valid_near` (FBM2H's reached moments),
:func:`unmeasured` (FBM1's ground-truth moment), the share of valid pairs (the trajectory); a
run whose valid data cannot support a score is ``unscoreable`` with the reason, never scored
from what is left without saying so (docs/uncertainty.md, "Validity masks and unscoreable
runs").

What each reason means in the data (the logs carry no per-frame tracking flag):

- ``tracking_lost``: the pose repeats the previous one exactly (position and orientation) at a
  later stamp: Motive re-sending the last pose of a rigid body it lost
  (:func:`ertools.benchmarks.common.hygiene.identical_poses`).
- ``gap``: frames missing where consecutive samples are more than the gap threshold apart
  (:data:`DEFAULT_GAP_S`, the FBM2H ``--gt-tolerance`` and clock-offset default); counted as the
  frames expected at the stream's median frame period.
- ``outside_window``: the sample lies outside the scored window (not in the fraction's
  denominator).
- ``nan``: a position or orientation that is not finite, or a zero quaternion.
- ``clock_jump``: a different pose at the very stamp of the previous sample: the clock did not
  advance (or stepped back and the stream was sorted), so its time is not the measurement's.
- ``far``: a position no body in an arena can have: kilometres from the stream's other
  samples, or beyond any frame on Earth (:func:`~ertools.benchmarks.common.hygiene.
  impossible_samples`).
- ``jump``: a pose reached and left again faster than any robot moves (a marker set mistaken
  for another for a few frames, a forged pose): a glitch, not a measurement.
- ``occluded``: reserved for a source that flags untracked frames. No log format ertools reads
  carries that flag: ``ertools record`` does not write an untracked frame (a ``gap``), the 2015
  mocap_optitrack re-published the last pose (``tracking_lost``), a NaN pose is ``nan``.
"""

from __future__ import annotations

import math
from collections.abc import Mapping

import numpy as np
import numpy.typing as npt

from ertools.arrays import F64, I64, Bool, IntArr, median
from ertools.benchmarks.common.hygiene import impossible_samples, rows_equal
from ertools.frozen_dataclass import frozen_dataclass

VALID = 0
TRACKING_LOST = 1
GAP = 2
OUTSIDE_WINDOW = 3
NAN = 4
CLOCK_JUMP = 5
OCCLUDED = 6
FAR = 7
JUMP = 8
REASONS: tuple[str, ...] = (
    "valid",
    "tracking_lost",
    "gap",
    "outside_window",
    "nan",
    "clock_jump",
    "occluded",
    "far",
    "jump",
)
#: the codes of samples whose position cannot be used at all (not merely a repeat)
UNUSABLE = (NAN, FAR, JUMP)
CODE: Mapping[str, int] = {name: code for code, name in enumerate(REASONS)}

Codes = npt.NDArray[np.int8]

# A tracking loss whose two ends are closer than this hid no motion: above the 0.3-1.3 mm
# frame-to-frame noise of a still marker set on the 2015 logs, below the 6 mm a robot moving
# at the FBM3 sample's 0.06 m/s covers in the shortest span (0.1 s).
STILL_M = 0.002

# Consecutive samples further apart than this leave a gap. The same 0.1 s as FBM2H's --max-gap
# and the clock-offset search (clocks.py): 12 frames at 120 Hz, far above the frame jitter of
# a recording (a few ms), well below any stretch in which a robot moves a measurable distance
# at benchmark speeds (0.1 s at 0.3 m/s is 3 cm, which a straight chord still follows).
DEFAULT_GAP_S = 0.1


@frozen_dataclass
class SampleMask:
    """The reason code of every sample of a stream.

    Attributes:
        t_ns: (N,) the samples' times.
        codes: (N,) int8 codes, indices into :data:`REASONS`.
    """

    t_ns: I64
    codes: Codes

    @property
    def valid(self) -> Bool:
        ok: Bool = self.codes == VALID
        return ok

    def names(self) -> list[str]:
        """The reason of every sample by name (for tables; not for hour-long streams)."""
        return [REASONS[c] for c in self.codes.tolist()]


def sample_codes(t_ns: I64, xyz: F64, quat_xyzw: F64 | None = None) -> SampleMask:
    """Each sample's reason code, from the stream alone (window and gaps aside).

    Precedence: ``nan`` over ``far`` over ``jump`` over ``clock_jump`` over
    ``tracking_lost``. A sample equal to the
    previous one at the same stamp is a second recording of it (two loggers on one topic) and
    stays valid: it neither adds nor hides a measurement.
    """
    n = len(t_ns)
    codes = np.zeros(n, dtype=np.int8)
    if not n:
        return SampleMask(t_ns, codes)
    rows = xyz if quat_xyzw is None else np.concatenate([xyz, quat_xyzw], axis=1)
    if n > 1:
        same = rows_equal(rows[1:], rows[:-1])
        same_t = t_ns[1:] == t_ns[:-1]
        codes[1:][same & ~same_t] = TRACKING_LOST
        codes[1:][same_t & ~same] = CLOCK_JUMP
    impossible = impossible_samples(t_ns, xyz)
    codes[impossible.jump] = JUMP
    codes[impossible.far] = FAR
    bad = ~np.all(np.isfinite(rows), axis=1)
    if quat_xyzw is not None:
        with np.errstate(over="ignore", invalid="ignore"):
            norm = np.einsum("ij,ij->i", quat_xyzw, quat_xyzw)
        bad |= ~(norm > 1e-18)
    codes[bad] = NAN
    return SampleMask(t_ns, codes)


def measured(mask: SampleMask) -> Bool:
    """Which samples of ``mask``'s stream are measurements at all: not ``far`` or a ``jump``
    (physically impossible: every number is computed without them, the validity counts
    them; docs/uncertainty.md, "Impossible samples")."""
    ok: Bool = ~np.isin(mask.codes, (FAR, JUMP))
    return ok


def last_measured(ok: Bool, i: int) -> int:
    """The last index at or before ``i`` where ``ok`` holds, -1 when none does."""
    if i < 0 or ok[i]:
        return i
    before = np.flatnonzero(ok[: i + 1])
    return int(before[-1]) if before.size else -1


@frozen_dataclass
class InvalidSpan:
    """A stretch of the window without valid data longer than the gap threshold.

    From the last valid sample before it to the first valid one after it (the window's ends
    where there is none).

    Attributes:
        start_ns, end_ns: its ends.
        reason: ``gap`` when no sample arrived in it, else the most frequent invalid reason of
            the samples in it (``tracking_lost``: Motive repeated the last pose).
        samples: the invalid samples in it (0 for a gap).
        before, after: indices in the window (0 = its first sample) of the valid samples at
            its ends, -1 where the span touches the window's edge: the plot's (x, y) ends.
    """

    start_ns: int
    end_ns: int
    reason: str
    samples: int
    before: int
    after: int

    @property
    def duration_s(self) -> float:
        return (self.end_ns - self.start_ns) / 1e9

    def to_dict(self, origin_ns: int) -> dict[str, object]:
        return {
            "reason": self.reason,
            "start_time": round((self.start_ns - origin_ns) / 1e9, 6),
            "end_time": round((self.end_ns - origin_ns) / 1e9, 6),
            "duration": round(self.duration_s, 6),
            "samples": self.samples,
        }


@frozen_dataclass
class Validity:
    """Validity of the samples in one scored window (a run, a segment, an item, a trajectory).

    Attributes:
        window: (start_ns, end_ns), both inclusive.
        samples: samples inside the window.
        counts: (len(REASONS),) per reason: samples inside the window, and for ``gap`` the
            frames missing in the gaps (at the median frame period); ``outside_window`` only
            where a scorer counts skipped samples outside its window (the trajectory's robot
            poses that no GT covers).
        spans: the invalid stretches longer than the gap threshold, in time order.
        period_ns: the median frame period used to count missing frames.
        expected: the fraction's denominator: the window's samples, the frames missing in its
            gaps and the skipped samples outside it (default: the sum of ``counts``).
    """

    window: tuple[int, int]
    samples: int
    counts: I64
    spans: tuple[InvalidSpan, ...]
    period_ns: int
    expected: int = -1

    def __post_init__(self) -> None:
        if self.expected < 0:
            object.__setattr__(self, "expected", int(self.counts.sum()))

    @property
    def valid_samples(self) -> int:
        return int(self.counts[VALID])

    @property
    def valid_fraction(self) -> float:
        """Valid samples over the window's samples and missing frames (0.0 when empty)."""
        return self.valid_samples / self.expected if self.expected else 0.0

    @property
    def invalid_samples(self) -> dict[str, int]:
        """``{reason: count}`` of the nonzero invalid reasons, in :data:`REASONS` order."""
        return {REASONS[c]: int(v) for c, v in enumerate(self.counts.tolist()) if c and v}

    def longest(self, inner: bool = False) -> InvalidSpan | None:
        """The longest invalid span; ``inner``: only those between two valid samples."""
        spans = [s for s in self.spans if not inner or (s.before >= 0 and s.after >= 0)]
        return max(spans, key=lambda s: s.end_ns - s.start_ns, default=None)

    def fields(self) -> dict[str, object]:
        """The result keys: ``valid_fraction`` (6 decimals) and ``invalid_samples``."""
        return {
            "valid_fraction": round(self.valid_fraction, 6),
            "invalid_samples": self.invalid_samples,
        }

    def text(self, label: str, origin_ns: int) -> str:
        """``run 2 97.3% valid (12 tracking_lost, 1 gap 0.41 s at 13.20 s)``."""
        parts = [f"{v} {k}" for k, v in self.invalid_samples.items() if k != "gap"]
        gaps = [s for s in self.spans if s.reason == "gap"]
        if gaps:
            g = max(gaps, key=lambda s: s.end_ns - s.start_ns)
            longest = "" if len(gaps) == 1 else " longest"
            parts.append(
                f"{len(gaps)} gap{'s' if len(gaps) > 1 else ''}{longest} {g.duration_s:.2f} s "
                f"at {(g.start_ns - origin_ns) / 1e9:.2f} s"
            )
        detail = f" ({', '.join(parts)})" if parts else ""
        return f"{label} {self.valid_fraction:.1%} valid{detail}"


def from_codes(codes: Codes, t_ns: I64, *, gap_s: float = DEFAULT_GAP_S, nan: int = 0) -> Validity:
    """The validity of samples whose codes a scorer assigned itself (the trajectory's robot
    poses, by their association), over their own span; ``nan``: samples dropped before as not
    finite, counted as such."""
    counts = np.bincount(codes.astype(np.intp), minlength=len(REASONS)).astype(np.int64)
    counts[NAN] += nan
    if not len(t_ns):
        return Validity((0, 0), 0, counts, (), 0)
    a, b = int(t_ns[0]), int(t_ns[-1])
    period = median_period_ns(t_ns)
    # a 10 Hz robot log's own period is the gap threshold: a span needs two periods
    spans = _spans(t_ns, codes, a, b, max(round(gap_s * 1e9), 2 * period))
    return Validity((a, b), len(t_ns) + nan, counts, spans, period)


def combine(parts: tuple[Validity, ...]) -> Validity:
    """Several streams' validity over one window as one (FBM1's table and board bodies): the
    counts and denominators summed, the spans of all in time order (their ``before``/``after``
    indices stay those of their own stream)."""
    counts = np.sum([p.counts for p in parts], axis=0).astype(np.int64)
    return Validity(
        (min(p.window[0] for p in parts), max(p.window[1] for p in parts)),
        sum(p.samples for p in parts),
        counts,
        tuple(sorted((s for p in parts for s in p.spans), key=lambda s: s.start_ns)),
        parts[0].period_ns,
        sum(p.expected for p in parts),
    )


def has_valid(mask: SampleMask, start_ns: int, end_ns: int) -> bool:
    """Whether a valid sample lies in [start_ns, end_ns]."""
    lo = int(np.searchsorted(mask.t_ns, start_ns, side="left"))
    hi = int(np.searchsorted(mask.t_ns, end_ns, side="right"))
    return bool(np.any(mask.codes[lo:hi] == VALID))


def unmeasured(
    mask: SampleMask,
    xyz: F64,
    start_ns: int,
    end_ns: int,
    still_m: float,
    until_ns: int | None = None,
) -> bool:
    """Whether a still body's pose in [start_ns, end_ns] was not measured: no valid sample
    there, and either none before it or the first valid sample after it more than ``still_m``
    from the last one before it (the body moved while unseen). A body frozen to the end of
    the log, or (``until_ns``) seen again only after the body may have been moved on purpose
    (the run's end), shows no move: its repeated pose stands."""
    if has_valid(mask, start_ns, end_ns):
        return False
    ok = np.flatnonzero(mask.codes == VALID)
    k = int(np.searchsorted(mask.t_ns[ok], start_ns))
    if k == 0:
        return True
    if k == len(ok) or (until_ns is not None and mask.t_ns[ok[k]] > until_ns):
        return False
    before, after = xyz[ok[k - 1]], xyz[ok[k]]
    return bool(np.linalg.norm(after - before) > still_m)


def median_period_ns(t_ns: I64) -> int:
    """The median positive interval of ``t_ns`` (0 when there is none)."""
    dt = np.diff(t_ns)
    dt = dt[dt > 0]
    return int(median(dt)) if dt.size else 0


def summarise(
    mask: SampleMask,
    start_ns: int,
    end_ns: int,
    *,
    gap_s: float = DEFAULT_GAP_S,
    period_ns: int | None = None,
    outside: int = 0,
) -> Validity:
    """The validity of the samples of ``mask`` in [start_ns, end_ns].

    Args:
        mask: the whole stream's codes (:func:`sample_codes`).
        start_ns, end_ns: the scored window, both inclusive.
        gap_s: stretches without a valid sample longer than this are spans; intervals between
            received samples longer than it count their missing frames as ``gap``.
        period_ns: the frame period; default: the stream's median interval.
        outside: samples the scorer skipped as outside its window, counted as such.
    """
    t = mask.t_ns
    lo = int(np.searchsorted(t, start_ns, side="left"))
    hi = int(np.searchsorted(t, end_ns, side="right"))
    tw, cw = t[lo:hi], mask.codes[lo:hi]
    period = median_period_ns(t) if period_ns is None else period_ns
    gap_ns = round(gap_s * 1e9)
    counts = np.bincount(cw.astype(np.intp), minlength=len(REASONS)).astype(np.int64)
    # Missing frames: every interval (window edges included) longer than the gap threshold.
    edges = np.concatenate([[start_ns], tw, [end_ns]]).astype(np.int64)
    dt = np.diff(edges)
    # an empty window misses every frame it should hold, however short it is
    long = dt > gap_ns if tw.size else np.ones(1, dtype=bool)
    if period > 0 and long.any():
        # an interval at the window's edge has one received end, an inner one two
        inner = np.ones(dt.size, dtype=np.int64)
        inner[0] = inner[-1] = 0
        if dt.size == 1:
            inner[:] = -1
        missing = np.rint(dt[long] / period).astype(np.int64) - inner[long]
        counts[GAP] = int(np.maximum(missing, 0).sum())
    counts[OUTSIDE_WINDOW] = outside
    return Validity(
        (start_ns, end_ns), hi - lo, counts, _spans(tw, cw, start_ns, end_ns, gap_ns), period
    )


def _spans(
    t: I64, codes: Codes, start_ns: int, end_ns: int, gap_ns: int
) -> tuple[InvalidSpan, ...]:
    """The stretches between consecutive valid samples (or window edges) longer than gap_ns."""
    ok: IntArr = np.flatnonzero(codes == VALID)
    ends = np.concatenate([[start_ns], t[ok], [end_ns]]).astype(np.int64)
    idx = np.concatenate([[-1], ok, [-1]])
    long = np.flatnonzero(np.diff(ends) > gap_ns)
    if not long.size:
        return ()
    # the samples of stretch k lie between its two valid samples (or the window's edges)
    first = np.concatenate([[0], ok + 1])
    last = np.concatenate([ok, [len(t)]])
    out = []
    for k in long.tolist():  # a handful of spans, not a loop over samples
        inside = codes[first[k] : last[k]]
        bad = inside[inside != VALID]
        # the most frequent invalid reason inside, or a gap where nothing arrived
        top = int(np.bincount(bad.astype(np.intp)).argmax()) if bad.size else GAP
        reason = REASONS[top]
        out.append(
            InvalidSpan(
                int(ends[k]), int(ends[k + 1]), reason, int(bad.size), int(idx[k]), int(idx[k + 1])
            )
        )
    return tuple(out)


def lost_spans(validity: Validity, xy: F64 | None, still_m: float) -> tuple[InvalidSpan, ...]:
    """The spans of ``validity`` in which the tracked point may have moved unmeasured.

    A stretch of invalid samples (tracking lost) whose two valid ends are within ``still_m`` of
    each other in ``xy`` (the window's samples) hid no motion: the marker set was where it
    had been (a still robot recorded without noise repeats its pose too). One that touches the
    window's edge shows no move either (its repeated pose is the last one measured). A gap
    (nothing received) is always lost.
    """

    def at(i: int) -> tuple[float, float] | None:
        return None if xy is None or i < 0 else (float(xy[i, 0]), float(xy[i, 1]))

    return tuple(
        s for s in validity.spans if xy is None or span_lost(s, at(s.before), at(s.after), still_m)
    )


def span_lost(
    span: InvalidSpan,
    start_xy: tuple[float, float] | None,
    end_xy: tuple[float, float] | None,
    still_m: float = STILL_M,
) -> bool:
    """Whether the tracked point may have moved unmeasured in ``span`` (see
    :func:`lost_spans`), from the (x, y) of its two ends (None at the window's edge)."""
    if span.reason == "gap":
        return True
    if start_xy is not None and end_xy is not None:
        return math.hypot(end_xy[0] - start_xy[0], end_xy[1] - start_xy[1]) > still_m
    return span.samples == 0


def coverage(validity: Validity, spans: tuple[InvalidSpan, ...] | None = None) -> float:
    """The fraction of the window's duration outside ``spans`` (default: all its spans)."""
    a, b = validity.window
    if b <= a:
        return 1.0 if validity.valid_samples else 0.0
    lost = sum(s.end_ns - s.start_ns for s in (validity.spans if spans is None else spans))
    return max(0.0, 1.0 - lost / (b - a))


def coverage_problem(
    validity: Validity,
    min_fraction: float,
    max_inner_gap_s: float | None = None,
    lost: tuple[InvalidSpan, ...] | None = None,
) -> str | None:
    """Why ``validity`` cannot support a path score, or None.

    Less than ``min_fraction`` of the window's duration covered by valid data (outside the
    ``lost`` spans, default all spans), or (``max_inner_gap_s``) a lost span longer than that
    between two valid samples, which the path would cross as a chord.
    """
    spans = validity.spans if lost is None else lost
    covered = coverage(validity, spans)
    if covered < min_fraction:
        what = ", ".join(f"{v} {k}" for k, v in validity.invalid_samples.items())
        return (
            f"valid data covers only {covered:.1%} of the window ({what or 'no samples'}); at "
            f"least {min_fraction:.0%} is needed"
        )
    if max_inner_gap_s is not None:
        inner = [s for s in spans if s.before >= 0 and s.after >= 0]
        span = max(inner, key=lambda s: s.end_ns - s.start_ns, default=None)
        if span is not None and span.duration_s > max_inner_gap_s:
            return (
                f"{span.duration_s:.2f} s without valid data in the middle of the path "
                f"({span.reason}, from {(span.start_ns - validity.window[0]) / 1e9:.2f} s into "
                f"the window); at most {max_inner_gap_s:g} s can be crossed"
            )
    return None


def valid_near(mask: SampleMask, at_ns: I64, tolerance_ns: int) -> Bool:
    """(K,) whether a valid sample lies within ``tolerance_ns`` of each moment of ``at_ns``."""
    ok = mask.t_ns[mask.codes == VALID]
    at = np.asarray(at_ns, dtype=np.int64)
    if not ok.size:
        return np.zeros(at.shape, dtype=bool)
    i = np.clip(np.searchsorted(ok, at), 1, ok.size - 1) if ok.size > 1 else np.zeros_like(at)
    near = np.abs(ok[i] - at)
    if ok.size > 1:
        near = np.minimum(near, np.abs(ok[i - 1] - at))
    out: Bool = near <= tolerance_ns
    return out


def cell(invalid: Mapping[str, int]) -> str:
    """``invalid_samples`` in one CSV/HTML cell: ``tracking_lost=12 gap=49`` ("" when none)."""
    return " ".join(f"{k}={v}" for k, v in invalid.items())
