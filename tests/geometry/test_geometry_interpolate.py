"""interpolate_poses over whole streams against a plain reading, query by query: the samples
around each query found by walking the stamps, positions interpolated in Python, orientations
by scipy's Slerp; repeated stamps, exact hits, queries before, after and between.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation, Slerp

from ertools.geometry import interpolate_poses
from ertools.streams import PoseStream

BIG = np.iinfo(np.int64).max


@st.composite
def stream_and_queries(draw: st.DrawFn) -> tuple[PoseStream, np.ndarray]:
    n = draw(st.integers(1, 12))
    steps = draw(st.lists(st.sampled_from([0, 1, 7, 8, 8, 300]), min_size=n - 1, max_size=n - 1))
    t = np.cumsum([1000, *steps]).astype(np.int64)
    xyz = np.array(draw(st.lists(st.tuples(*[st.integers(-64, 64)] * 3), min_size=n, max_size=n)))
    # Orientations one after the other never pi apart (two shortest arcs: no one answer).
    yaw = np.cumsum(draw(st.lists(st.floats(-1.5, 1.5), min_size=n, max_size=n)))
    tilt = draw(st.lists(st.floats(-0.3, 0.3), min_size=n, max_size=n))
    quat = Rotation.from_euler("zx", np.column_stack([yaw, tilt])).as_quat()
    scale = draw(st.lists(st.sampled_from([1.0, 1.0, 0.5, 2.0]), min_size=n, max_size=n))
    stream = PoseStream(t, xyz / 16.0, quat * np.array(scale)[:, None], "world", "body")
    near = st.integers(int(t[0]) - 20, int(t[-1]) + 20)
    hits = st.sampled_from(t.tolist())
    q = draw(st.lists(st.one_of(near, hits), min_size=1, max_size=30))
    return stream, np.array(q, dtype=np.int64)


@pytest.mark.slow
@settings(max_examples=200, deadline=None)
@given(stream_and_queries())
def test_linear_interpolation_matches_a_plain_one(case: tuple[PoseStream, np.ndarray]) -> None:
    stream, queries = case
    got = interpolate_poses(stream, queries, "linear")
    t, n = stream.t_ns.tolist(), len(stream)
    rows = stream.xyz.tolist()
    unit = stream.quat_xyzw / np.linalg.norm(stream.quat_xyzw, axis=1)[:, None]
    for k, q in enumerate(queries.tolist()):
        lo = max([i for i in range(n) if t[i] <= q], default=-1)
        hi = min([i for i in range(n) if t[i] >= q], default=n)
        assert (int(got.lo[k]), int(got.hi[k])) == (lo, hi)
        inside = lo >= 0 and hi < n
        assert bool(got.inside[k]) == inside
        assert int(got.gap_ns[k]) == (t[hi] - t[lo] if inside else BIG)
        if lo < 0 or hi >= n:  # outside: the end sample
            a, b, w = (hi, hi, 0.0) if lo < 0 else (lo, lo, 0.0)
        else:
            a, b = lo, hi
            w = (q - t[lo]) / (t[hi] - t[lo]) if t[hi] > t[lo] else 0.0
        # the same three operations per coordinate: equal to the bit
        expected = [rows[a][c] + w * (rows[b][c] - rows[a][c]) for c in range(3)]
        assert got.xyz[k].tolist() == expected
        want = Slerp([0.0, 1.0], Rotation.from_quat(unit[[a, b]]))([w]).as_quat()[0]
        have = got.quat_xyzw[k]
        # scipy and numpy's trigonometry differ by a few ulps of the angles
        assert min(np.abs(have - want).max(), np.abs(have + want).max()) < 1e-9
