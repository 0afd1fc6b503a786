"""``scripts/fbm3w`` at 50b173b (2015-11-30), the FBM3@Work node of RoCKIn 2015, replayed.

rockin-robot-challenge/benchmark_and_scoring_fbm, read at the commit (``git show
50b173b:scripts/fbm3w``); line numbers are that file's. The BmBox is ``tests/helpers/bmbox2015.py``.
This is ``main()`` (165-322) statement by statement, with the functions it calls:

- ``BENCHMARK_RUNS = 5`` (17), ``D_MIN = 0.00033`` (20); the targets ``line_path`` (28-30:
  ``(0.15*l, 0.045*l)``) and ``spline_path = sine`` (36-42: ``(0.15*l,
  0.075*sin(12.5*pi*0.15*l))``), chosen by the run's spec (195-199);
- ``while benchmark.Running() and current_run < BENCHMARK_RUNS`` (192);
  ``ManualOperation()`` (206), then ``acquire_reference_position()`` (208: tf
  ``world -> robot_at_work`` at ``Time(0)``, the latest pose received then), then ``if not
  benchmark.Running(): break`` (210);
- ``SendGoal`` (216), ``start_time = time.time()`` (223), ``start_collecting_robot_path()``
  (224: subscribe to pose2d, ``robot_path = []``), ``WaitResult()`` (227), ``end_time`` (230),
  ``end_collecting_robot_path()`` (231): the path is the pose2d messages received in between,
  kept by ``mocap_callback`` (155-162: the first one, then each one at least ``D_MIN`` from
  the last kept one);
- ``if benchmark.Timeout(): print`` only (234-237, the time and ``continue`` commented out by
  7942ea2: a timed-out run is scored and timed); ``if not benchmark.Running(): continue``
  (239-241: no time, no score, ``current_run`` unchanged, and the loop head ends the loop);
- ``execution_time += end_time - start_time`` (245);
- the accuracy (254-298): the start is ``robot_path[0]`` (126), the run frame's x axis
  ``atan2(start.y - ref.y, start.x - ref.x)`` (133-134) with its origin at the start (75),
  each pose moved into it through tf (``translate_robot_pose``, 68-87: the inverse rotation of
  its offset from the start); ``L`` the sum of the distances between consecutive kept poses
  (276-277, in the world), ``l`` their running sum, ``error_sum`` the distances of poses 1..N-1
  in the frame to the target at ``l / L`` (280-288); ``distance_error = error_sum / N`` (295),
  N the kept poses, the start included (a path of one pose scores 0.0; an empty one raises
  ``IndexError`` at line 126 and the node dies);
- the best run: the first with the smallest ``distance_error`` (301-303).

The node's clock and poses come from the log: ``time.time()`` after a call is the record time
of the BmBox message that ended it (``tests/helpers/bmbox2015.py``); tf at ``Time(0)`` and the
messages the subscription received are the pose2d messages by record time. Nothing here
imports ertools.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

from tests.helpers.bmbox2015 import Blocked, BmBoxReplay, Msg

BENCHMARK_RUNS = 5
D_MIN = 0.00033
SPECS = ("line", "spline", "line", "spline", "line")  # config/fbm3w.yaml at 50b173b


def line_path(ll: float) -> tuple[float, float]:
    ll = float(ll)
    return 0.15 * ll, 0.045 * ll


def sine(ll: float) -> tuple[float, float]:
    ll = float(ll)
    return 0.15 * ll, 0.075 * math.sin(12.5 * math.pi * 0.15 * ll)


TARGETS = {"line": line_path, "spline": sine}

Pose = tuple[float, float]


def d(p1: Pose, p2: Pose) -> float:
    return math.sqrt((p1[0] - p2[0]) ** 2 + (p1[1] - p2[1]) ** 2)


def collect(t: Sequence[int], xy: Sequence[Pose], start: int, end: int) -> list[Pose]:
    """``robot_path`` between the subscription and its end: ``mocap_callback`` per message."""
    robot_path: list[Pose] = []
    for tt, pose in zip(t, xy, strict=True):
        if not start <= tt <= end:
            continue
        if len(robot_path) > 0:
            if d(robot_path[-1], pose) >= D_MIN:
                robot_path.append(pose)
        else:
            robot_path.append(pose)
    return robot_path


def latest(t: Sequence[int], xy: Sequence[Pose], at: int) -> Pose:
    """``acquire_robot_position()``: tf's latest pose at ``Time(0)`` when asked."""
    before = [p for tt, p in zip(t, xy, strict=True) if tt <= at]
    return before[-1]


def accuracy(robot_path: list[Pose], reference: Pose, spec: str) -> float:
    """Lines 254-295: the run's ``distance_error``."""
    target_path = TARGETS[spec]
    start = robot_path[0]  # acquire_starting_position_from_path (IndexError when empty)
    yaw = math.atan2(start[1] - reference[1], start[0] - reference[0])  # update_robot_frame
    c, s = math.cos(yaw), math.sin(yaw)

    def translate_robot_pose(p: Pose) -> Pose:
        dx, dy = p[0] - start[0], p[1] - start[1]
        return c * dx + s * dy, -s * dx + c * dy

    ll = 0.0
    error_sum = 0.0
    n = len(robot_path)
    total = 0.0
    for i in range(1, n):
        total = total + d(robot_path[i - 1], robot_path[i])
    for i in range(1, n):
        robot_in_frame_pose = translate_robot_pose(robot_path[i])
        ll = ll + d(robot_path[i - 1], robot_path[i])
        error_sum = error_sum + d(robot_in_frame_pose, target_path(ll / total))
    return error_sum / n


def fbm3w_node(
    bmbox: list[Msg], refbox: list[Msg], t: Sequence[int], xy: Sequence[Pose]
) -> dict[str, Any]:
    """``main()`` of scripts/fbm3w at 50b173b over the replayed BmBox (see the module doc)."""
    benchmark = BmBoxReplay(bmbox, refbox, [])
    current_run = 0
    best_run = None
    best_distance_error: float | None = None
    execution_time = 0.0
    runs_details: dict[int, dict[str, Any]] = {}
    try:
        benchmark.WaitClient()
        while benchmark.Running() and current_run < BENCHMARK_RUNS:
            runs_details[current_run] = {}
            spec = SPECS[current_run]
            runs_details[current_run]["spec"] = spec
            benchmark.ManualOperation()
            robot_reference_position = latest(t, xy, benchmark.now)
            if not benchmark.Running():
                break
            benchmark.SendGoal("start path following")
            start_time = benchmark.now
            benchmark.WaitResult()
            end_time = benchmark.now
            robot_path = collect(t, xy, start_time, end_time)
            if benchmark.Timeout():
                runs_details[current_run]["timeout"] = True  # print "TIMEOUT" only
            if not benchmark.Running():
                continue
            execution_time = execution_time + (end_time - start_time) / 1e9
            runs_details[current_run]["execution_time"] = (end_time - start_time) / 1e9
            distance_error = accuracy(robot_path, robot_reference_position, spec)
            runs_details[current_run]["distance_error"] = distance_error
            if best_run is None or distance_error < best_distance_error:  # type: ignore[operator]
                best_run = current_run
                best_distance_error = distance_error
            current_run = current_run + 1
    except Blocked:
        pass  # the log ended with the node waiting: the score of what it had (bmbox2015)
    return {
        "best_distance_error": best_distance_error,
        "best_run": best_run,
        "execution_time": execution_time,
        "runs_details": runs_details,
        "cut": benchmark.cut_at is not None,
    }
