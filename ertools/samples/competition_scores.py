"""The expected score of a simulated execution, as fields of ``ertools score ... --format json``.

A field is the dotted path of a value in that JSON (``details.segments_details.0.dinstance_error``);
its value comes from the scenario's ``expected`` (computed from the noiseless truth by the
scenario module, never by ``ertools.benchmarks``) and its tolerance from the scenario's
tolerances: the measurement noise between the truth and what the GT logger recorded.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
import numpy.typing as npt

from ertools.benchmarks.trajectory.sample import expected_scores
from ertools.geometry import yaw_from_quat
from ertools.simulator.mocap import MocapPublished
from ertools.simulator.simulated import SimulatedRun

Fields = dict[str, Any]
MAX_GAP_NS = 100_000_000  # the trajectory scorer's default --max-gap


def _tol(abs_: float, why: str) -> dict[str, Any]:
    return {"abs": float(abs_), "why": why}


def expected_score(sim: SimulatedRun) -> tuple[Fields, dict[str, dict[str, Any]]]:
    """``({field: value}, {field: {abs, why}})`` for one execution."""
    if sim.benchmark == "fbm1h":
        return _fbm1h(sim.expected, sim.tolerance)
    if sim.benchmark == "fbm2h":
        return _fbm2h(sim.expected, sim.tolerance)
    if sim.benchmark == "fbm3w":
        return _fbm3w(sim.expected, sim.tolerance)
    raise ValueError(f"no expected score for {sim.benchmark!r}")


def _why(tolerance: Mapping[str, Any], key: str) -> tuple[float, str]:
    entry = tolerance[key]
    return float(entry["abs"]), str(entry["why"])


def _fbm1h(exp: Mapping[str, Any], tolerance: Mapping[str, Any]) -> tuple[Fields, dict[str, Any]]:
    score: Fields = {}
    tol: dict[str, Any] = {}
    exact = _tol(0, "counts are exact")
    pose = _tol(*_why(tolerance, "pose_score"))
    timing = _tol(*_why(tolerance, "execution_time"))
    totals = exp["totals"]
    for key, t in (
        ("class_accuracy", exact),
        ("instance_accuracy", exact),
        ("pose_score", pose),
        ("execution_time", timing),
    ):
        score[key], tol[key] = totals[key], t
    for run in exp["runs"]:
        k = f"runs.{run['run']}"
        score[f"{k}.status"], tol[f"{k}.status"] = run["status"], exact
        for key in ("class_correct", "instance_correct"):
            score[f"{k}.{key}"], tol[f"{k}.{key}"] = bool(run[key]), exact
        score[f"{k}.pose_score"], tol[f"{k}.pose_score"] = run["pose_score"], pose
        score[f"{k}.execution_time"], tol[f"{k}.execution_time"] = run["execution_time"], timing
    return score, tol


def _fbm2h(exp: Mapping[str, Any], tolerance: Mapping[str, Any]) -> tuple[Fields, dict[str, Any]]:
    dist = _tol(*_why(tolerance, "distance_error"))
    orient = _tol(*_why(tolerance, "orientation_error"))
    timing = _tol(*_why(tolerance, "segment_time"))
    score: Fields = {
        "position_accuracy": exp["position_accuracy"],
        "orientation_accuracy": exp["orientation_accuracy"],
        "execution_time": exp["execution_time"],
        "timeout_segments": exp["timeout_segments"],
    }
    tol: dict[str, Any] = {
        # a mean of errors each within the per-segment tolerance stays within it
        "position_accuracy": dist,
        "orientation_accuracy": orient,
        "execution_time": timing,
        "timeout_segments": _tol(0, "counts are exact"),
    }
    for k, seg in enumerate(exp["segments"]):
        path = f"details.segments_details.{k}"
        for key, value, t in (
            ("dinstance_error", seg["distance_error"], dist),
            ("orientation_error", seg["orientation_error"], orient),
            ("segment_time", seg["segment_time"], timing),
        ):
            score[f"{path}.{key}"], tol[f"{path}.{key}"] = value, t
    return score, tol


def _fbm3w(exp: Mapping[str, Any], tolerance: Mapping[str, Any]) -> tuple[Fields, dict[str, Any]]:
    dist = _tol(*_why(tolerance, "distance_error"))
    timing = _tol(*_why(tolerance, "execution_time"))
    errors = sorted(
        float(r["distance_error"])
        for r in exp["runs_details"].values()
        if r["distance_error"] is not None
    )
    if len(errors) > 1 and errors[1] - errors[0] <= 2 * dist["abs"]:
        raise ValueError(f"best run ambiguous within the tolerance: {errors[:2]}")
    score: Fields = {
        "best_run": exp["best_run"],
        "best_distance_error": exp["best_distance_error"],
        "execution_time": exp["execution_time"],
    }
    tol: dict[str, Any] = {
        "best_run": _tol(0, "the best run's margin over the next exceeds twice the tolerance"),
        "best_distance_error": dist,
        "execution_time": timing,
    }
    for k, run in exp["runs_details"].items():
        path = f"runs_details.{k}"
        score[f"{path}.distance_error"] = run["distance_error"]
        tol[f"{path}.distance_error"] = (
            dist if run["distance_error"] is not None else _tol(0, "a timed-out run has none")
        )
        score[f"{path}.execution_time"], tol[f"{path}.execution_time"] = (
            run["execution_time"],
            timing,
        )
    return score, tol


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
