"""The expected score of a simulated execution, as fields of ``ertools score ... --format json``.

A field is the dotted path of a value in that JSON (``details.segments_details.0.dinstance_error``);
its value comes from the scenario's ``expected`` (computed from the noiseless truth by the
scenario module, never by ``ertools.benchmarks``) and its tolerance from the scenario's
tolerances: the measurement noise between the truth and what the GT logger recorded.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
import numpy.typing as npt

from ertools.benchmarks import registry
from ertools.benchmarks.trajectory.sample import expected_scores
from ertools.geometry import yaw_from_quat
from ertools.simulator.mocap import MocapPublished
from ertools.simulator.simulated import SimulatedRun

Fields = dict[str, Any]
MAX_GAP_NS = 100_000_000  # the trajectory scorer's default --max-gap


def _tol(abs_: float, why: str) -> dict[str, Any]:
    return {"abs": float(abs_), "why": why}


def expected_score(sim: SimulatedRun) -> tuple[Fields, dict[str, dict[str, Any]]]:
    """``({field: value}, {field: {abs, why}})`` for one execution: its benchmark's sample
    module's ``competition_score`` (reached through the registry)."""
    sample = registry.package_module(sim.benchmark, "sample")
    if sample is None or not hasattr(sample, "competition_score"):
        raise ValueError(f"no expected score for {sim.benchmark!r}")
    found: tuple[Fields, dict[str, dict[str, Any]]] = sample.competition_score(
        sim.expected, sim.tolerance
    )
    return found


def expected_trajectory(
    poses: tuple[npt.NDArray[np.int64], npt.NDArray[np.float64], npt.NDArray[np.float64]],
    header_offset_ns: int,
    gt: Sequence[MocapPublished],
    windows: Sequence[tuple[int, int]],
) -> tuple[Fields, dict[str, dict[str, Any]]]:
    """What ``ertools score trajectory ROBOT GT... --offset <-header_offset>`` must report for a
    robot log: the plain per-pose loop of the ``robotlog`` scenario
    (:func:`ertools.benchmarks.trajectory.sample.expected_scores`, linear association, 0.1 s max
    gap) over the GT messages the GT files hold (every pub's messages recorded inside ``windows``,
    the files' [start, end) record-time windows: other teams' runs in the same hour included)."""
    t, xyz, quat = poses
    parts = [
        (p, np.any([(p.t_record_ns >= a) & (p.t_record_ns < b) for a, b in windows], axis=0))
        for p in gt
    ]
    gt_t = np.concatenate([p.t_header_ns[m] for p, m in parts])
    order = np.argsort(gt_t, kind="stable")
    gt_xyz = np.concatenate([p.xyz[m] for p, m in parts])[order]
    gt_q = np.concatenate([p.quat_xyzw[m] for p, m in parts])[order]
    stamps = t + header_offset_ns
    found = expected_scores(
        stamps.tolist(),
        xyz.tolist(),
        yaw_from_quat(quat).tolist(),
        gt_t[order].tolist(),
        gt_xyz.tolist(),
        gt_q.tolist(),
        "linear",
        -header_offset_ns,
        MAX_GAP_NS,
    )
    exact = _tol(0, "counts are exact")
    same = _tol(1e-9, "the same arrays as the bags; only summation order and SLERP form differ")
    return found, {k: exact if isinstance(v, int) else same for k, v in found.items()}
