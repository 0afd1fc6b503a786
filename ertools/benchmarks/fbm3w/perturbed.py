"""FBM3@Work's runs re-scored with perturbed positions, every Monte Carlo draw at once
(issues 28 and 39): the 2015 d_min subsampling and Eq. (1) vectorised over the draws of all
the runs side by side. What the draws perturb and why: :mod:`~ertools.benchmarks.fbm3w.
intervals` and docs/uncertainty.md ("How the FBM3@Work draws are computed"). No IO here.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
import numpy.typing as npt

from ertools.arrays import F64, Bool, IntArr
from ertools.benchmarks.fbm3w.shapes import Shape
from ertools.frozen_dataclass import frozen_dataclass

# Draws x samples of one batch: bounds the memory of a long run (~8 bytes x a few arrays).
BATCH_ELEMENTS = 2_000_000
# Draws x samples of the runs whose d_min rule runs in one pass (padded to the longest): a
# competition's four runs of ~600 samples x 400 draws in one pass, float32 positions and
# steps, ~13 MB.
GROUP_ELEMENTS = 1_200_000
TABLE = 4097  # targets the draws interpolate (target_table)
BLOCK = 64  # samples of Eq. (1) computed at a time (_eq1): 64 x 400 draws, 200 kB an array


@frozen_dataclass(eq=False)
class RunSamples:
    """What one scored run's Eq. (1) depends on.

    Attributes:
        xy: (N, 2) the measured positions of the path window (world).
        source: (N,) index of the measurement each sample carries (a repeated pose carries
            the one it repeats).
        reference_xy: (2,) the measured reference position.
        shape: the target.
        center_xy, center_reference_xy: the smoothed path and reference the draws perturb
            (None: the measured ones).
    """

    xy: F64
    source: IntArr
    reference_xy: F64
    shape: Shape
    center_xy: F64 | None = None
    center_reference_xy: F64 | None = None


def perturbed_errors(
    run: RunSamples, sigmas: F64, d_mins: F64, rng: np.random.Generator, noisy: bool
) -> F64:
    """(D,) distance errors of one run with its positions perturbed by ``sigmas`` (D,) (when
    ``noisy``) and subsampled with ``d_mins`` (D,); NaN where a draw cannot be scored."""
    return perturbed_runs([run], sigmas, d_mins, rng, noisy)[:, 0]


def perturbed_runs(
    runs: Sequence[RunSamples],
    sigmas: F64,
    d_mins: F64,
    rng: np.random.Generator,
    noisy: bool,
    *,
    budget: int = BATCH_ELEMENTS,
    fourfold: bool = True,
) -> F64:
    """(D, R) distance errors of every run in every draw (column ``r``: ``runs[r]``).

    The runs' draws go side by side in groups (run by run, each run's draws in batches of
    at most ``budget`` samples, as many as fit in :data:`GROUP_ELEMENTS` padded samples);
    the d_min rule is one pass over the samples of a group. Each piece's noise is drawn
    from ``rng`` in turn (when ``noisy``: :func:`_noise`, each drawn noise used four ways
    unless not ``fourfold``), each draw's scaled by its sigma (a draw of sigma 0 takes no
    random numbers); a repeated pose takes the noise of the sample it repeats. The
    positions are complex64 x + iy (one array for both coordinates: one subtraction per
    step of the d_min rule), relative to each run's first (smoothed) sample: float32 parts
    resolve a run's metres to 0.1 um, against noise of 50 um and d_min of 330 um; lengths
    add up in float64.
    """
    d = sigmas.size
    out = np.empty((d, len(runs)))
    tables: dict[Shape, npt.NDArray[np.float32]] = {}  # runs of one shape share its table
    pieces = [
        (col, lo, min(d, lo + batch))
        for col, run in enumerate(runs)
        for batch in [max(1, budget // max(len(run.xy), 1))]
        for lo in range(0, d, batch)
    ]
    scratch = _Scratch(
        max((min(len(runs[c].xy), BLOCK) * (hi - lo) for c, lo, hi in pieces), default=0)
    )
    for group in _groups(pieces, [len(r.xy) for r in runs], min(budget, GROUP_ELEMENTS)):
        # every piece's draws side by side, samples down the rows (shorter runs padded with
        # NaN, never kept): the positions are drawn straight into this array
        lengths = [len(runs[col].xy) for col, _, _ in group]
        edges = np.cumsum([0, *(hi - lo for _, lo, hi in group)])
        width, longest = int(edges[-1]), max(lengths)
        zt = np.empty((longest, width), dtype=np.complex64)
        views = [
            (zt[:m, a:b], slice(a, b), m)
            for a, b, m in zip(edges[:-1], edges[1:], lengths, strict=True)
        ]
        refs = []
        for (col, lo, hi), (z, cols, m) in zip(group, views, strict=True):
            scale = sigmas[lo:hi].astype(np.float32)
            if not noisy:
                scale[:] = 0.0
            ref_noise = _noise(rng, z, scale, runs[col].source, fourfold)
            refs.append(_positions(runs[col], z, ref_noise))
            zt[m:, cols] = np.nan  # padding: never kept
        kept, cum = _subsample(zt, np.concatenate([d_mins[lo:hi] for _, lo, hi in group]))
        for (col, lo, hi), (z, cols, m), ref in zip(group, views, refs, strict=True):
            shape = runs[col].shape
            table = tables.get(shape)
            if table is None:
                table = tables[shape] = target_table(shape)
            out[lo:hi, col] = _eq1(z, kept[:m, cols], cum[:m, cols], ref, table, scratch)
    return out


def target_table(shape: Shape) -> npt.NDArray[np.float32]:
    """(4, TABLE) the target's x and y at TABLE evenly spaced l in [0, 1], and each row's
    step to the next in x and y (0 after the last), which the draws interpolate linearly
    (:func:`_eq1`): for the 2015 shapes within 2e-8 m of the curve (the sine's y'' = 2.6 m,
    times (1 / 4096)^2 / 8); a shape given by points is exact but within 1 / 4096 of l
    around its corners."""
    xy = shape(np.linspace(0.0, 1.0, TABLE)).T.astype(np.float32)
    return np.concatenate([xy, np.diff(xy, axis=1, append=xy[:, -1:])])


def _groups(
    pieces: list[tuple[int, int, int]], lengths: list[int], budget: int
) -> list[list[tuple[int, int, int]]]:
    """Consecutive (run, lo, hi) pieces grouped while the group's draws x its longest run
    stay within ``budget`` (a piece alone may exceed it only with a single draw)."""
    groups: list[list[tuple[int, int, int]]] = []
    width = longest = 0
    for piece in pieces:
        col, lo, hi = piece
        w, n = width + hi - lo, max(longest, lengths[col])
        if groups and w * n <= budget:
            groups[-1].append(piece)
            width, longest = w, n
        else:
            groups.append([piece])
            width, longest = hi - lo, lengths[col]
    return groups


def origin_of(run: RunSamples) -> F64:
    """The point the draws' positions are relative to: the run's first (smoothed) sample."""
    xy = run.xy if run.center_xy is None else run.center_xy
    return np.asarray(xy[0], dtype=np.float64)


# The four uses of one standard normal noise x + iy (docs/uncertainty.md, "How the FBM3@Work
# draws are computed"): z, -z, iz = -y + ix and -iz = y - ix, each as (the source of the new
# x and its sign, the source of the new y and its sign), 0: x, 1: y.
FOURFOLD = (
    ((0, 1.0), (1, 1.0)),
    ((0, -1.0), (1, -1.0)),
    ((1, -1.0), (0, 1.0)),
    ((1, 1.0), (0, -1.0)),
)


def _noise(
    rng: np.random.Generator,
    out: npt.NDArray[np.complex64],
    scale: npt.NDArray[np.float32],
    source: IntArr,
    fourfold: bool,
) -> npt.NDArray[np.complex64]:
    """Noise of one piece's draws written into ``out`` (m, w), x + iy of m samples in w
    draws, each draw's scaled by its ``scale`` (w,); returns the (w,) noise of the
    reference.

    Only the draws of nonzero scale take random numbers (the others 0): with ``fourfold``
    the first ceil(c / 4) of those c draws take standard normal noise z = x + iy (float32,
    drawn as the samples' x (m, ceil(c / 4)), their y, then the reference's x and y), the
    next as many -z, then iz, then -iz; otherwise each its own. A standard normal x + iy is
    unchanged in distribution by a turn of the plane (its density depends on |z| only), so
    each draw is exactly the model's, for a quarter of the random numbers. A repeated sample
    (``source``) repeats the noise of the sample it carries.
    """
    m, w = out.shape
    ref = np.zeros(w, dtype=np.complex64)
    quiet = scale == 0
    out[:, quiet] = 0.0
    drawn_cols = np.flatnonzero(~quiet)
    if drawn_cols.size == 0:
        return ref
    uses = FOURFOLD if fourfold else FOURFOLD[:1]
    per = -(-drawn_cols.size // len(uses))
    drawn = rng.standard_normal((2, m, per), dtype=np.float32)
    drawn_ref = rng.standard_normal((2, per), dtype=np.float32)
    if np.any(source != np.arange(m)):
        drawn = drawn[:, source]
    for k, axes in enumerate(uses):
        cols = drawn_cols[k * per : (k + 1) * per]
        if cols.size == 0:
            break
        sl = slice(int(cols[0]), int(cols[-1]) + 1)
        together = sl.stop - sl.start == cols.size  # side by side: written in place
        target = out[:, sl] if together else np.empty((m, cols.size), np.complex64)
        for part, (axis, sign) in zip((target.real, target.imag), axes, strict=True):
            np.multiply(drawn[axis, :, : cols.size], scale[cols] * np.float32(sign), out=part)
        if not together:
            out[:, cols] = target
        ref.real[cols] = drawn_ref[axes[0][0], : cols.size] * scale[cols] * axes[0][1]
        ref.imag[cols] = drawn_ref[axes[1][0], : cols.size] * scale[cols] * axes[1][1]
    return ref


def _positions(
    run: RunSamples, z: npt.NDArray[np.complex64], ref_noise: npt.NDArray[np.complex64]
) -> npt.NDArray[np.complex128]:
    """One run's sample positions put into ``z`` (N, D), which holds their noise, as x + iy
    relative to :func:`origin_of`; the (D,) positions of its reference, whose noise is
    ``ref_noise``."""
    origin = origin_of(run)
    xy = (run.xy if run.center_xy is None else run.center_xy) - origin
    ref = (
        run.reference_xy if run.center_reference_xy is None else run.center_reference_xy
    ) - origin
    z += (xy[:, 0] + 1j * xy[:, 1]).astype(np.complex64)[:, None]
    return np.asarray(complex(ref[0], ref[1]) + ref_noise.astype(np.complex128))


def _subsample(zt: npt.NDArray[np.complex64], d_mins: F64) -> tuple[Bool, npt.NDArray[np.float32]]:
    """(N, W) kept flags of the 2015 d_min rule for the W draws side by side in the columns
    of ``zt`` (N, W), each with its d_min, and the (N, W) length of the kept polyline up to
    each sample (summed in float64 row by row, sequentially as the 2015 loop did; stored in
    float32, 6e-8 relative): one pass over the samples, each step vectorised over every
    draw (the rule is sequential within a draw). NaN is never kept."""
    n, w = zt.shape
    d_min = d_mins.astype(np.float32)
    kept = np.zeros((n, w), dtype=bool)
    kept[0] = True
    cum = np.zeros((n, w), dtype=np.float32)
    length = np.zeros(w)
    last = zt[0].copy()
    dz = np.empty(w, dtype=np.complex64)
    parts = dz.view(np.float32)  # x, y, x, y...
    dist = np.empty(w, dtype=np.float32)
    for j in range(1, n):
        # 2015: sqrt(dx**2 + dy**2) >= D_MIN against the last kept point, in place; in
        # real arithmetic (IEEE: the same bits on every CPU, unlike NumPy's complex abs)
        np.subtract(zt[j], last, out=dz)
        np.multiply(parts, parts, out=parts)
        np.add(parts[0::2], parts[1::2], out=dist)
        np.sqrt(dist, out=dist)
        k = np.greater_equal(dist, d_min, out=kept[j])
        np.copyto(last, zt[j], where=k)
        np.add(length, dist, out=length, where=k)  # a kept sample's step adds to the polyline
        cum[j] = length
    return kept, cum


class _Scratch:
    """Work arrays of :func:`_eq1`, allocated once for every piece of a call: fresh
    arrays of megabytes cost more in page faults than the arithmetic on them."""

    def __init__(self, size: int) -> None:
        self.arrays: tuple[npt.NDArray[Any], ...] = (
            *(np.empty(size, dtype=np.float32) for _ in range(8)),
            np.empty(size, dtype=np.intp),
        )

    def shaped(self, m: int, w: int) -> tuple[Any, ...]:
        n = m * w
        return tuple(a[:n].reshape(m, w) for a in self.arrays)


def _eq1(
    z: npt.NDArray[np.complex64],
    kept: Bool,
    cum: npt.NDArray[np.float32],
    ref: npt.NDArray[np.complex128],
    table: npt.NDArray[np.float32],
    scratch: _Scratch | None = None,
) -> F64:
    """Eq. (1) of every draw (column) from its kept flags and polyline lengths (as
    :func:`~.path.score_path`), the target at l/L interpolated in ``table``
    (:func:`target_table`); the errors are computed at every sample and summed where kept
    (whole arrays: faster than gathering the kept points), :data:`BLOCK` samples at a time
    in ``scratch``'s arrays (kept in the CPU's cache from one operation to the next)."""
    m, w = z.shape
    work = scratch if scratch is not None else _Scratch(min(m, BLOCK) * w)
    total = cum[m - 1]
    # l / L in table rows: cum <= total, so the row is at most the last (its step is 0)
    scale = np.zeros_like(total)
    np.divide(np.float32(TABLE - 1), total, out=scale, where=total > 0)
    # the run frame: origin at the start, x along reference -> start: turned by -yaw
    start = z[0]
    axis = start.astype(np.complex128) - ref
    norm = np.sqrt(axis.real**2 + axis.imag**2)
    with np.errstate(invalid="ignore", divide="ignore"):
        c, s = (axis.real / norm).astype(np.float32), (axis.imag / norm).astype(np.float32)
    sums = np.zeros(w)
    # real arithmetic on x and y, each in its own contiguous array (an operation on the
    # complex arrays' strided parts costs several times one on contiguous ones): NumPy's
    # complex multiply and abs differ in the last bit between CPUs (AVX2 or not), its float
    # add, multiply and sqrt do not
    zx, zy = z.real, z.imag
    # a sample no draw keeps adds 0 to every sum (a robot standing still): left out, the
    # rest of its block summed in the same order, to the same bits
    active = np.flatnonzero(np.any(kept, axis=1))
    for lo in range(0, m, BLOCK):
        hi = min(m, lo + BLOCK)
        a, b = np.searchsorted(active, (lo, hi))
        if a == b:
            continue
        rows: slice | IntArr = slice(lo, hi) if b - a == hi - lo else active[a:b]
        at, row, tx, ty, sx, sy, mx, my, index = work.shaped(int(b - a), w)
        np.multiply(cum[rows], scale, out=at)
        np.floor(at, out=row)
        at -= row
        np.copyto(index, row, casting="unsafe")
        # the target at l/L: its row plus the fraction of the step to the next
        for plane, into in zip(table, (tx, ty, sx, sy), strict=True):
            np.take(plane, index, out=into, mode="clip")
        sx *= at
        tx += sx
        sy *= at
        ty += sy
        np.subtract(zx[rows], start.real, out=mx)
        np.subtract(zy[rows], start.imag, out=my)
        # run frame x = c mx + s my - tx, y = c my - s mx - ty
        np.multiply(mx, c, out=at)
        np.multiply(my, s, out=row)
        at += row
        at -= tx
        np.multiply(my, c, out=row)
        np.multiply(mx, s, out=sx)
        row -= sx
        row -= ty
        np.multiply(at, at, out=at)
        np.multiply(row, row, out=row)
        err = np.add(at, row, out=sy)
        np.sqrt(err, out=err)
        err *= kept[rows]
        if lo == 0:
            err[0] = 0.0  # 2015 started its sum at the second kept point (row 0: the start)
        sums += err.sum(axis=0, dtype=np.float64)
    count = np.count_nonzero(kept, axis=0)
    out = sums / np.maximum(count, 1)
    bad = (count < 2) | ~(total > 0) | (axis == 0)
    return np.asarray(np.where(bad, np.nan, out), dtype=np.float64)
