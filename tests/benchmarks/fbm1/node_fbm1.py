"""The FBM1 nodes of rockin-robot-challenge/benchmark_and_scoring_fbm, replayed over a log.

Four versions, each read at its commit (``git show COMMIT:scripts/fbm1h``) and ported here
statement by statement, over the BmBox replayed from the log (``tests/helpers/bmbox2015.py``); line
numbers are those of the version named:

- ``scripts/fbm1h`` at e373be0 (2015-10-30, the last 2015 change; RoCKIn 2015 Lisbon; its
  scoring is 117a5d0's, e373be0 only waits for ENTER at the end): ``WaitClient()`` (47);
  ``while benchmark.Running() and (runs < BENCHMARK_RUNS)`` (50, ``BENCHMARK_RUNS = 10``);
  ``runs = runs + 1`` (51); ``random.choice(items)`` (54, in the log as the manual operation's
  payload, 58-59); the two ``if not benchmark.Running(): break`` (61-67); the board lookup (70-79,
  visible in these logs); ``SendGoal()`` (82), ``start_time`` (83), ``WaitResult()`` (86),
  ``end_time`` (87); ``if benchmark.Timeout(): execution_time += ...; continue`` (89-92); ``if
  not benchmark.Running(): continue`` (94-96); the class and instance ``==`` (107-114); ``now``,
  the item broadcast stamped ``now``, two ``time.sleep(0.5)`` (117-121), the lookup of /item in
  /origin at ``Time(0)``, i.e. at ``now`` (123-125); the one-step theta wrap (132-133); the
  translation term set to 1 only above ``max_pose_error`` = sqrt(2) m (147); the rotation clip
  (149-150); ``pose_score_sum`` (153); the time (158); every total over ``runs`` (164-166).
- ``scripts/fbm1w`` at 7628309 (2015-07-06, its only version; RoCKIn 2015 Lisbon): the same
  body but ``while benchmark.Running():`` (50, no run cap), ``item_instance =
  benchmark.ManualOperation()`` (55: the RefBox payload when the BmBox left the manual
  operation), ``if not benchmark.Running(): break`` (57), the item of that instance (62).
- ``scripts/fbm1h`` at 40ba68b (2017-01-26, "the Lisbon's 2016 2nd local competition"): the
  ground truth moves before the goal (81-91: ``now``, the item broadcast, one ``sleep(0.5)``,
  the lookup at ``Time(0)``, then ``raw_input`` for the positioner's removal); after the answer
  only the result broadcast and one ``sleep(0.5)`` (132-133); ``class_accuracy`` and
  ``instance_accuracy`` over ``BENCHMARK_RUNS`` (176-177), ``pose_score`` over ``runs``.
- ``scripts/fbm1h`` at 89dfa75 (2017-11-10, "after the Lisbon major tournament 2017"): 40ba68b
  (with 27d9a23's score display, no arithmetic) and ``if pose_err_trans > 1.0 :
  pose_err_trans = 1.0`` (185) instead of the sqrt(2) test.

The moment ``now`` is the stamp of the node's item broadcast on /tf (its own ``now``). Nothing
here imports ertools.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from typing import Any

import yaml

from tests.helpers.bmbox2015 import Blocked, BmBoxReplay, Msg

BENCHMARK_RUNS = 10
# The versions: (script, commit).
VERSIONS = {
    "2015": ("fbm1h", "e373be0"),
    "2015w": ("fbm1w", "7628309"),
    "2016": ("fbm1h", "40ba68b"),
    "2017": ("fbm1h", "89dfa75"),
}

Lookup = Callable[[dict[str, Any], int], tuple[float, float, float]]


def fbm1_node(
    states: dict[str, list[Msg]],
    items: Sequence[dict[str, Any]],
    item_stamps: Sequence[int],
    lookup: Lookup,
    version: str,
) -> dict[str, Any]:
    """``main()`` of the node ``version`` (a key of :data:`VERSIONS`) over the replayed BmBox.

    ``lookup(item, t)``: tf's /item in /origin at ``t`` (x, y, yaw in degrees).
    """
    work = version == "2015w"
    later = version in ("2016", "2017")
    benchmark = BmBoxReplay(states["bmbox"], states["refbox"], states["client"])
    by_id = {i["id"]: i for i in items}
    runs = 0
    class_positives = 0.0
    instance_positives = 0.0
    pose_score_sum = 0.0
    execution_time = 0.0
    max_pose_error = math.sqrt(math.pow(1, 2) + math.pow(1, 2))
    per_run: dict[int, dict[str, Any]] = {}
    goals_before = 0

    def item_stamp_after(t: int) -> int | None:
        return next((s for s in item_stamps if s > t), None)

    try:
        benchmark.WaitClient()
        while benchmark.Running() and (work or runs < BENCHMARK_RUNS):
            runs = runs + 1
            per_run[runs] = {"status": "aborted"}
            goals_before = benchmark.goals
            if work:
                item_instance = benchmark.ManualOperation()
                if not benchmark.Running():
                    break
                item = [x for x in items if x["instance"] == item_instance][0]  # noqa: RUF015
            else:
                benchmark.ManualOperation("Place item ...")
                # random.choice(items) is in the log: the payload the node published with it
                item = by_id.get(int(benchmark.manual_message.split()[2]), {})
                if not benchmark.Running():
                    break
                if not benchmark.Running():
                    break
            gt = None
            if later:
                now = item_stamp_after(benchmark.now)
                benchmark.sleep(0.5)
                gt = None if now is None else lookup(item, now)
            benchmark.SendGoal()
            sent = benchmark.goals > goals_before
            start_time = benchmark.now
            result_yaml = benchmark.WaitResult()
            end_time = benchmark.now
            # The goal is in the log (TRANSMITTING_GOAL) or the benchmark stopped before it.
            per_run[runs] = {"status": "no_answer" if sent else "aborted"}
            if benchmark.Timeout():
                execution_time = execution_time + (end_time - start_time) / 1e9
                continue
            if not benchmark.Running():
                continue
            assert result_yaml is not None
            result = yaml.safe_load(result_yaml)
            c_ok = result["item_class"] == item["class"]
            i_ok = result["item_instance"] == item["instance"]
            if c_ok:
                class_positives = class_positives + 1
            if i_ok:
                instance_positives = instance_positives + 1
            if later:
                benchmark.sleep(0.5)  # the result broadcast, then one sleep
            else:
                now = item_stamp_after(start_time)
                benchmark.sleep(0.5)
                benchmark.sleep(0.5)
                assert now is not None, "the node's item broadcast is in the log"
                gt = lookup(item, now)
            assert gt is not None
            x, y, yaw = gt
            x_err = result["x"] - x
            y_err = result["y"] - y
            w_err = result["theta"] - yaw
            if w_err > 180:
                w_err = w_err - 360
            if w_err < -180:
                w_err = w_err + 360
            pose_err_trans = math.sqrt(math.pow(x_err, 2) + math.pow(y_err, 2))
            if version == "2017":
                if pose_err_trans > 1.0:  # noqa: PLR1730 (the node's own statement)
                    pose_err_trans = 1.0
            elif pose_err_trans > max_pose_error:
                pose_err_trans = 1
            pose_err_rot = abs(w_err) / 180
            if pose_err_rot > 1:  # noqa: PLR1730
                pose_err_rot = 1
            pose_score = 1 - (pose_err_trans / 2) - (pose_err_rot / 2)
            pose_score_sum = pose_score_sum + pose_score
            execution_time = execution_time + (end_time - start_time) / 1e9
            per_run[runs] = {
                "status": "scored",
                "gt": gt,
                "err": (x_err, y_err, w_err),
                "class_ok": c_ok,
                "instance_ok": i_ok,
                "pose_score": pose_score,
                "execution_time": (end_time - start_time) / 1e9,
            }
    except Blocked:
        # The log ended with the node waiting: the score of what it had (bmbox2015); a goal
        # the log shows sent makes its run one without an answer.
        if runs and benchmark.goals > goals_before:
            per_run[runs] = {"status": "no_answer"}
    over = BENCHMARK_RUNS if later else runs
    return {
        "score": {
            "class_accuracy": class_positives / over,
            "instance_accuracy": instance_positives / over,
            "pose_score": pose_score_sum / runs,
            "execution_time": execution_time,
        },
        "runs": per_run,
        "cut": benchmark.cut_at is not None,
    }
