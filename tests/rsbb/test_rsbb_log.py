"""ertools.rsbb.log: a simulated run's bag read back into the events the scenario had."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from ertools.benchmarks.hnf.config import SCRIPT_FRAMES as HNF_FRAMES
from ertools.errors import TopicError
from ertools.io.messages import read_messages
from ertools.io.reader import topics
from ertools.rsbb.log import (
    EndKind,
    GoalOutcome,
    read_refbox_states,
    read_referee_items,
    read_rsbb_run,
    read_script_broadcasts,
)
from ertools.rsbb_states import BMBOX_STATE_TOPIC, REFBOX_STATE_TOPIC, RefBoxState
from ertools.simulator.rsbb import write_rsbb_run
from ertools.simulator.rsbb_scenario import live_score_text, result_object
from ertools.simulator.writer import BagWriter
from tests.helpers.rsbb_replay.scenarios import MS, at, hnf_scenario

pytestmark = pytest.mark.slow  # each writes and reads a run bag (~0.5-1 s)


def test_goals_manual_operations_and_the_end(tmp_path: Path) -> None:
    paths = write_rsbb_run(tmp_path, hnf_scenario())
    run = read_rsbb_run(paths.bag)
    assert run.t_start_ns == at(2.0)
    assert (run.end_kind, run.t_end_ns) == (EndKind.END, at(55.0))
    g = run.goals
    assert [x.outcome for x in g] == [
        GoalOutcome.RESULT,
        GoalOutcome.TIMEOUT,
        GoalOutcome.TIMEOUT,
        GoalOutcome.RESULT,
    ]
    assert (g[0].t_request_ns, g[0].t_start_ns, g[0].t_end_ns) == (at(3.0), at(4.0), at(10.0))
    assert g[0].result == "{}" and g[3].result == "reached: 3"
    assert g[1].result is None
    assert g[2].t_start_ns is None  # timed out while the robot prepared
    assert [x.request for x in g] == [
        "[1.0, 0.0, 0.0]\n",
        "[2.0, 0.0, 0.0]\n",
        "[3.0, 0.0, 0.0]\n",
        "[3.0, 0.0, 0.0]\n",
    ]
    (mo,) = run.manual_operations
    assert (mo.t_request_ns, mo.t_done_ns, mo.request, mo.answer) == (
        at(27.0),
        at(29.0),
        "try again or skip?",
        "s",
    )
    # two /timeout messages, just before each timed-out goal's READY
    assert run.timeouts_ns.tolist() == [at(21.0) - 2 * MS, at(30.5) - 2 * MS]


def test_a_referee_stop_interrupts_the_goal_and_the_manual_operation(tmp_path: Path) -> None:
    sc = hnf_scenario(t_end_ns=at(26.0), end="stop")
    sc = replace(
        sc,
        goals=(
            *sc.goals[:2],
            replace(sc.goals[0], t_request_ns=at(22.0), t_start_ns=at(23.0), t_end_ns=None),
        ),
        manual_operations=(),
    )
    run = read_rsbb_run(write_rsbb_run(tmp_path, sc).bag)
    assert run.end_kind is EndKind.STOP and run.t_end_ns == at(26.0)
    assert run.goals[-1].outcome is GoalOutcome.STOPPED
    assert run.goals[-1].t_end_ns == at(26.0)
    sc2 = replace(
        hnf_scenario(t_end_ns=at(28.0), end="global_timeout"),
        manual_operations=(replace(hnf_scenario().manual_operations[0], t_done_ns=None),),
        goals=hnf_scenario().goals[:2],
    )
    run2 = read_rsbb_run(write_rsbb_run(tmp_path / "b", sc2).bag)
    assert run2.end_kind is EndKind.GLOBAL_TIMEOUT
    (mo,) = run2.manual_operations
    assert mo.t_done_ns is None and mo.answer is None
    assert run2.timeouts_ns[-1] == at(28.0) + MS  # the global timeout's /timeout


def test_the_refbox_stream_and_its_changes(tmp_path: Path) -> None:
    paths = write_rsbb_run(tmp_path, hnf_scenario())
    stream = read_refbox_states(paths.bag)
    # 10 Hz heartbeats from 50 ms after the connect, plus one message per change
    assert len(stream) > 10 * 59
    ch = stream.changes()
    assert len(ch) < 40
    first_exec = int(np.flatnonzero(ch.benchmark == RefBoxState.EXECUTING_BENCHMARK)[0])
    assert ch.t_ns[first_exec] == at(2.0)
    ready = np.flatnonzero(
        (ch.goal == RefBoxState.READY) & (np.asarray(ch.goal_payload) == "reached: 3")
    )
    assert ch.t_ns[ready[0]] == at(40.0)


def test_the_bmbox_publishes_at_ten_hertz_only(tmp_path: Path) -> None:
    paths = write_rsbb_run(tmp_path, hnf_scenario())
    msgs = read_messages(paths.bag, BMBOX_STATE_TOPIC)
    t = np.array([m.t_ns for m in msgs])
    assert set(np.diff(t).tolist()) == {100 * MS}
    found = topics(paths.bag)
    assert found[BMBOX_STATE_TOPIC] == "rsbb_benchmarking_messages/BmBoxState"
    assert found[REFBOX_STATE_TOPIC] == "rsbb_benchmarking_messages/RefBoxState"


def test_live_scores_in_both_forms(tmp_path: Path) -> None:
    run19 = read_rsbb_run(write_rsbb_run(tmp_path / "a", hnf_scenario()).bag)
    run17 = read_rsbb_run(write_rsbb_run(tmp_path / "b", hnf_scenario(season="2017")).bag)
    for run, summary in ((run19, True), (run17, False)):
        assert [s.summary_form for s in run.live] == [summary, summary]
        last = run.live[-1].result
        assert last is not None
        assert last["score"] == {"segment_1": {"segment_time[s]": 6.0}, "reached_waypoints": 2}
        assert last["benchmark_info"]["end_description"] == "END: benchmark ended normally"
    assert "\n\nSCORE SUMMARY:\nreached_waypoints: 2\n" in run19.live[-1].text
    sc = hnf_scenario()
    text = live_score_text(result_object(sc, {"a": 1.5, "b": {"c": 1}}, at(3.0)), "2019")
    assert text.endswith("\n\nSCORE SUMMARY:\na: 1.5\n")


def test_referee_items_and_script_broadcasts(tmp_path: Path) -> None:
    paths = write_rsbb_run(tmp_path, hnf_scenario())
    found = read_referee_items(paths.bag, "HNF", "teamA", 1)
    assert found is not None
    _, items = found
    assert [(i.group, i.desc, i.kind, i.value) for i in items] == [
        ("Penalized Behaviors", "bumps", "uint", 1)
    ]
    assert read_referee_items(paths.bag, "HNF", "teamB", 1) is None
    lookups = read_script_broadcasts(paths.bag, HNF_FRAMES[0])
    assert lookups.t_ns.tolist() == [at(10.01), at(21.01), at(40.01)]


def test_not_an_rsbb_bag(tmp_path: Path) -> None:
    bag = tmp_path / "other.bag"
    with BagWriter(bag) as w:
        w.write_string("/chatter", [1, 2], "hi")
    with pytest.raises(TopicError, match="not an RSBB run bag"):
        read_rsbb_run(bag)
