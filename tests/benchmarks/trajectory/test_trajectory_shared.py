"""What the association keeps for the intervals (issue 39: computed once, not twice) is what
the intervals would compute themselves: the scores, intervals and JSON with it and without
it are the same, bit for bit, whether every pose is compared or not."""

from __future__ import annotations

import json
import math
from dataclasses import replace
from typing import Any

import numpy as np
import pytest

from ertools.benchmarks.trajectory import comparison
from ertools.benchmarks.trajectory.association import COMPARED, Matched, associate
from ertools.benchmarks.trajectory.comparison import score_streams
from ertools.benchmarks.trajectory.config import TrajectoryConfig
from ertools.benchmarks.trajectory.terms import PoseTerms
from ertools.geometry import quat_from_yaw, wrap_angle
from ertools.streams import PoseStream

T0 = 1_448_000_000 * 10**9
W = 2 * math.pi / 25  # one lap of the ellipse in 25 s


def _gt(seconds: float, gap: tuple[float, float] | None = None) -> PoseStream:
    """120 Hz on an ellipse with mocap noise, without the samples of ``gap`` (seconds)."""
    rng = np.random.default_rng(3)
    k = np.arange(round(seconds * 120))
    s = k / 120.0
    if gap is not None:
        keep = (s < gap[0]) | (s > gap[1])
        k, s = k[keep], s[keep]
    t = T0 + np.round(k * 1e9 / 120).astype(np.int64)
    xyz = np.column_stack([1.6 * np.cos(W * s), np.sin(W * s), 0.4 + 0 * s])
    xyz += rng.normal(0.0, 3e-4, xyz.shape)
    yaw = np.arctan2(np.cos(W * s), -1.6 * np.sin(W * s)) + rng.normal(0.0, 1e-3, len(s))
    return PoseStream(t, xyz, quat_from_yaw(yaw), "world", "b", "gt")


def _robot(n: int) -> PoseStream:
    rng = np.random.default_rng(4)
    s = 1.0 + np.arange(n) * 0.1 + rng.uniform(0, 0.002, n)
    t = T0 + np.round(s * 1e9).astype(np.int64)
    xyz = np.column_stack([1.6 * np.cos(W * s), np.sin(W * s), 0.4 + 0 * s])
    xyz += rng.normal(0.0, 0.02, xyz.shape)
    # yaw errors up to 3 rad: some differences wrap
    yaw = np.arctan2(np.cos(W * s), -1.6 * np.sin(W * s)) + rng.normal(0.0, 1.0, n)
    return PoseStream(t, xyz, quat_from_yaw(yaw), "world", "r", "r")


def _plain(*args: Any, **kwargs: Any) -> Matched:
    """The association without what it keeps for the intervals."""
    return replace(associate(*args, **kwargs), gt_lo=None, yaw_diff=None)


@pytest.mark.parametrize("gap", [None, (20.0, 20.5)])
@pytest.mark.parametrize("association", ["linear", "hold"])
def test_kept_arrays_change_nothing(
    monkeypatch: pytest.MonkeyPatch, gap: tuple[float, float] | None, association: str
) -> None:
    gt, robot = _gt(40.0, gap), _robot(380)
    config = TrajectoryConfig(association=association)  # type: ignore[arg-type]
    kept = score_streams(robot, gt, config)
    monkeypatch.setattr(comparison, "associate", _plain)
    plain = score_streams(robot, gt, config)
    assert plain.matched.gt_lo is None and kept.matched.gt_lo is not None
    compared = kept.matched.status == COMPARED
    assert compared.all() == (gap is None)
    assert kept.intervals and json.dumps(kept.to_dict()) == json.dumps(plain.to_dict())


def test_kept_arrays_are_the_search_and_the_signed_yaw() -> None:
    gt, robot = _gt(40.0, (20.0, 20.5)), _robot(380)
    m = associate(robot, gt, "linear", 100_000_000)
    ok = m.status == COMPARED
    assert not ok.all()
    assert m.gt_lo is not None and m.yaw_diff is not None
    np.testing.assert_array_equal(m.gt_lo, np.searchsorted(gt.t_ns, robot.t_ns, "right") - 1)
    # the signed difference of the two yaws, wrapped: as the intervals took it
    want = wrap_angle(robot.yaw[ok] - m.gt_yaw[ok])
    np.testing.assert_array_equal(m.yaw_diff[ok], want)
    np.testing.assert_array_equal(np.abs(m.yaw_diff[ok]), m.yaw_error[ok])
    assert np.abs(want).max() > 2.0  # some near +-pi


def test_distances_are_the_norms_of_the_errors() -> None:
    gt, robot = _gt(40.0), _robot(380)
    m = associate(robot, gt, "linear", 100_000_000)
    error = robot.xyz - m.gt_xyz
    zeros = np.zeros(len(robot))
    terms = PoseTerms(error, zeros, zeros, zeros, zeros, error, zeros, zeros, None)
    # computed from the errors, bit for bit numpy's norm and the association's distance
    np.testing.assert_array_equal(terms.norms(), np.linalg.norm(error, axis=1))
    np.testing.assert_array_equal(terms.norms(), m.position_error)
    given = replace(terms, distance=m.position_error)
    assert given.norms() is m.position_error
    np.testing.assert_array_equal(given.take(np.arange(5)).norms(), m.position_error[:5])
