"""Foxglove content of a ``score trajectory`` result.

Topics (all in the mocap frame ``world``, times on the GT clock):

- ``/trajectory/gt``: ``foxglove.PoseInFrame`` per pose of the result's GT path (the GT in
  the robot log's span, decimated to about 5000 poses for the figures);
- ``/trajectory/robot``: ``foxglove.PoseInFrame`` per robot pose, at its stamp plus the
  offset applied;
- ``/trajectory/gt_path``, ``/trajectory/robot_path``: one ``foxglove.PosesInFrame`` each,
  the whole path, at the first time;
- ``/trajectory/pairs``: one ``foxglove.SceneUpdate`` with a line from each compared robot
  pose to the GT pose it was compared with;
- ``/trajectory/errors``: JSON per compared robot pose: position and yaw error (plot these);
- ``/ertools/log``: ``foxglove.Log``: the score, warnings, deviations, failures.

Streams longer than the limit keep every k-th message (``every``); the error stream then no
longer averages to the score exactly, so a Log line says so.
"""

from __future__ import annotations

import numpy as np

from ertools.benchmarks.trajectory.association import COMPARED, STATUS_NAMES
from ertools.benchmarks.trajectory.result import TrajectoryResult
from ertools.views.foxglove import (
    INFO,
    RED,
    WARNING,
    WORLD,
    Collected,
    JsonSchema,
    Scene,
    every,
    log,
    pose_path,
    pose_stream,
    result_notes,
)

ERROR_SCHEMA = JsonSchema(
    "ertools.TrajectoryError",
    (
        ("index", "integer"),
        ("position_error", "number"),
        ("yaw_error", "number"),
        ("dx", "number"),
        ("dy", "number"),
        ("dz", "number"),
        ("status", "string"),
    ),
)


def content(out: Collected, r: TrajectoryResult, *, limit: int) -> None:
    m = r.matched
    frame = r.gt_path.frame_id or r.robot.frame_id or WORLD
    gt = r.gt_path
    t0 = int(min(gt.t_ns[0], m.t_ns[0])) if len(gt) and len(m.t_ns) else 0

    gi = every(len(gt), limit)
    pose_stream(out, "/trajectory/gt", gt.t_ns[gi], gt.xyz[gi], gt.quat_xyzw[gi], frame)
    ri = every(len(m.t_ns), limit)
    pose_stream(out, "/trajectory/robot", m.t_ns[ri], r.robot.xyz[ri], r.robot.quat_xyzw[ri], frame)
    pose_path(out, "/trajectory/gt_path", t0, gt.xyz[gi], gt.quat_xyzw[gi], frame)
    pose_path(out, "/trajectory/robot_path", t0, r.robot.xyz[ri], r.robot.quat_xyzw[ri], frame)

    ok = np.flatnonzero(m.status == COMPARED)
    ci = ok[every(len(ok), limit)]
    scene = Scene(t0, frame)
    pairs = np.empty((2 * len(ci), 3))
    pairs[0::2] = r.robot.xyz[ci]
    pairs[1::2] = m.gt_xyz[ci]
    e = scene.entity("pairs")
    if len(ci):
        Scene.line(e, pairs.tolist(), RED, pairs=True, thickness=1.5)
    scene.add_to(out, "/trajectory/pairs")

    d = r.robot.xyz[ci] - m.gt_xyz[ci]
    for i, t, pe, ye, dd in zip(
        ci.tolist(),
        m.t_ns[ci].tolist(),
        m.position_error[ci].tolist(),
        m.yaw_error[ci].tolist(),
        d.tolist(),
        strict=True,
    ):
        out.json(
            "/trajectory/errors",
            t,
            ERROR_SCHEMA,
            {
                "index": i,
                "position_error": pe,
                "yaw_error": ye,
                "dx": dd[0],
                "dy": dd[1],
                "dz": dd[2],
                "status": STATUS_NAMES[COMPARED],
            },
        )
    if r.metrics is not None:
        log(
            out,
            t0,
            INFO,
            f"trajectory: position_error {r.metrics.position_error:.6f} m, orientation_error "
            f"{r.metrics.orientation_error:.6f} rad over {r.compared} compared pose(s) "
            f"({r.gaps} in GT gaps, {r.tracking_lost} tracking lost, {r.uncovered} uncovered)",
            r.name,
        )
    if len(ci) < len(ok) or len(ri) < len(m.t_ns):
        log(
            out,
            t0,
            WARNING,
            f"streams decimated to at most {limit} messages: /trajectory/errors holds {len(ci)} "
            f"of {len(ok)} compared poses, so its mean is not the score exactly",
            r.name,
        )
    result_notes(out, r, r.name)
