"""Finding FBM1 runs in the state topics (@Home, @Work, short states, timeouts, orders)."""

from __future__ import annotations

import numpy as np
import pytest

from ertools.benchmarks.fbm1.pipeline import score_fbm1
from ertools.benchmarks.fbm1.runs import parse_item_ref, runs_from_states
from ertools.configs._yaml import parse_yaml
from ertools.configs.items import parse_items
from ertools.states import BmBoxState as B
from ertools.states import ClientState as C
from ertools.states import Machine
from ertools.states import RefBoxState as R
from ertools.streams import StateStream
from tests.benchmarks.fbm1.fbm1_testkit import ITEMS_YAML, RunSpec, bodies, ns, state_streams


def _stream(machine: Machine, rows: list[tuple[float, int, str]]) -> StateStream:
    return StateStream(
        machine,
        np.array([ns(t) for t, _, _ in rows], dtype=np.int64),
        np.array([s for _, s, _ in rows], dtype=np.uint8),
        tuple(p for _, _, p in rows),
    )


@pytest.mark.parametrize(
    ("text", "item_id", "instance"),
    [
        ("Place item 3 (a3) on the table", 3, "a3"),
        ("place item 12 (Bearing Boxes AX-16) on the table ", 12, "Bearing Boxes AX-16"),
        ("7", 7, None),
        ("EM-01", None, "EM-01"),
    ],
)
def test_parse_item_ref(text: str, item_id: int | None, instance: str | None) -> None:
    ref = parse_item_ref(text, "bmbox payload")
    assert ref is not None and (ref.item_id, ref.instance) == (item_id, instance)


def test_home_runs_with_moments_and_answers() -> None:
    runs = [
        RunSpec("Place item 1 (a1) on the table", "{x: 1}"),
        RunSpec("Place item 2 (b1) on the table", None, timeout=True),
    ]
    s = state_streams(runs)
    found = runs_from_states(s[Machine.BMBOX], s[Machine.REFBOX], s[Machine.CLIENT])
    r1, r2 = found.runs
    assert (r1.start_ns, r1.placed_ns, r1.goal_ns) == (ns(10.0), ns(13.02), ns(14.0))
    assert (r1.executing_ns, r1.result_ns) == (ns(14.1), ns(16.1))
    assert r1.item is not None and r1.item.item_id == 1
    assert r1.answer_payload == "{x: 1}" and r1.status == "answered"
    assert r2.status == "no_answer" and r2.ended_by == "timeout"
    assert found.logged_score == "{class_accuracy: 0.5}"


def test_work_item_from_refbox_payload() -> None:
    runs = [RunSpec("", "{x: 1}", refbox_payload="EM-01")]
    s = state_streams(runs)
    found = runs_from_states(
        s[Machine.BMBOX], s[Machine.REFBOX], s[Machine.CLIENT], benchmark="fbm1w"
    )
    ref = found.runs[0].item
    assert ref is not None and ref.instance == "EM-01" and ref.source == "refbox payload"


def test_home_prefers_bmbox_payload_work_prefers_refbox() -> None:
    runs = [RunSpec("Place item 1 (a1) on the table", "{x: 1}", refbox_payload="b1")]
    s = state_streams(runs)
    home = runs_from_states(s[Machine.BMBOX], s[Machine.REFBOX], s[Machine.CLIENT])
    work = runs_from_states(
        s[Machine.BMBOX], s[Machine.REFBOX], s[Machine.CLIENT], benchmark="fbm1w"
    )
    assert home.runs[0].item.item_id == 1  # type: ignore[union-attr]
    assert work.runs[0].item.instance == "b1"  # type: ignore[union-attr]


def test_missing_short_ready_still_closes_the_run() -> None:
    # The READY between runs lasted less than one heartbeat and was never published.
    bm = _stream(
        Machine.BMBOX,
        [
            (1.0, B.READY, ""),
            (2.0, B.WAITING_MANUAL_OPERATION, "Place item 1 (a1) on the table"),
            (3.0, B.COMPLETED_MANUAL_OPERATION, ""),
            (4.0, B.TRANSMITTING_GOAL, ""),
            (4.1, B.EXECUTING_GOAL, ""),
            (4.2, B.WAITING_RESULT, ""),
            (6.0, B.WAITING_MANUAL_OPERATION, "Place item 2 (b1) on the table"),
            (7.0, B.COMPLETED_MANUAL_OPERATION, ""),
            # TRANSMITTING_GOAL and EXECUTING_GOAL missing too.
            (8.2, B.WAITING_RESULT, ""),
            (9.0, B.READY, ""),
        ],
    )
    cl = _stream(
        Machine.CLIENT,
        [
            (5.9, C.COMPLETED_GOAL, "{a: 1}"),
            (6.5, C.WAITING_GOAL, ""),
            (8.9, C.COMPLETED_GOAL, "{a: 2}"),
        ],
    )
    found = runs_from_states(bm, None, cl)
    r1, r2 = found.runs
    assert r1.result_ns == ns(6.0) and r1.answer_payload == "{a: 1}"
    assert (r2.goal_ns, r2.executing_ns, r2.result_ns) == (ns(8.2), ns(8.2), ns(9.0))
    assert r2.answer_payload == "{a: 2}"


def test_aborted_run_and_stop() -> None:
    bm = _stream(
        Machine.BMBOX,
        [
            (1.0, B.READY, ""),
            (2.0, B.WAITING_MANUAL_OPERATION, "Place item 1 (a1) on the table"),
            (3.0, B.READY, ""),
            (4.0, B.END, ""),
        ],
    )
    rb = _stream(Machine.REFBOX, [(1.0, R.READY, ""), (2.9, R.END, "reason: stop")])
    found = runs_from_states(bm, rb, None)
    assert [r.status for r in found.runs] == ["aborted"]


def test_items_order_overrides_and_warns_on_count() -> None:
    runs = [RunSpec("Place item 1 (a1) on the table", "{x: 1}")] * 2
    s = state_streams(runs)
    found = runs_from_states(
        s[Machine.BMBOX], s[Machine.REFBOX], s[Machine.CLIENT], items_order=["3", "b1", "2"]
    )
    assert found.runs[0].item.item_id == 3  # type: ignore[union-attr]
    assert found.runs[1].item.instance == "b1"  # type: ignore[union-attr]
    assert found.warnings and "3 item(s)" in found.warnings[0]


def test_log_cut_during_a_run_is_the_run_stopped_there() -> None:
    """Issue 23: a log that ends inside the benchmark is the benchmark stopped there, what the
    2015 node did on a RefBox stop (fbm1h at e373be0 lines 94-96: ``if not Running():
    continue``, the run already counted in ``runs``): no answer, score 0, no time."""

    runs = [
        RunSpec(
            "Place item 1 (a1) on the table",
            "{item_class: a, item_instance: a1, x: 0.4, y: 0.2, theta: 0}",
        )
    ]
    s = state_streams(runs)
    # Cut the BmBox and Client logs at 15 s: the run's goal was sent at 14 s, no result.
    bm, cl = s[Machine.BMBOX].window(None, ns(15.0)), s[Machine.CLIENT].window(None, ns(15.0))
    found = runs_from_states(bm, s[Machine.REFBOX].window(None, ns(15.0)), cl)
    origin, board = bodies(runs)
    result = score_fbm1(origin, board, found, parse_items(parse_yaml(ITEMS_YAML)))
    assert [(r.status, r.ended_by) for r in result.runs] == [("no_answer", "stop")]
    assert result.runs[0].execution_time_ns == 0
    assert (result.totals.pose_score, result.totals.class_accuracy) == (0.0, 0.0)
    assert not result.failures
    said = [w for w in result.warnings if "stopped there" in w]
    assert len(said) == 1 and "inside run 1 (BmBox in WAITING_RESULT)" in said[0]
