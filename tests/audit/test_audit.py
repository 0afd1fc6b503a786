"""The audit of hand-built state streams whose findings are known by construction."""

from __future__ import annotations

from dataclasses import replace

import pytest

from ertools.auditing.analyse import audit_states, parse_payload
from ertools.states import BmBoxState as B
from ertools.states import ClientState as C
from ertools.states import Machine
from ertools.states import RefBoxState as R
from tests.helpers.audit_streams import BEAT_NS, BMBOX, CLIENT, GOAL, REFBOX, T0_NS, heartbeat


def _ns(seconds: float) -> int:
    return T0_NS + round(seconds * 1e9)


@pytest.fixture
def audit():  # type: ignore[no-untyped-def]
    bm = heartbeat(Machine.BMBOX, BMBOX, 20.0, drop=(5.0, 7.0), topic="/fbm2h/bmbox_state")
    rb = heartbeat(Machine.REFBOX, REFBOX, 20.0, topic="/fbm2h/refbox_state")
    cl = heartbeat(Machine.CLIENT, CLIENT, 20.0, topic="/fbm2h/client_state")
    return audit_states(bm, rb, cl, benchmark="/fbm2h")


def test_illegal_transition_found_once(audit) -> None:  # type: ignore[no-untyped-def]
    assert [(x.from_state, x.to_state) for x in audit.illegal_transitions] == [
        ("EXECUTING_GOAL", "TRANSMITTING_GOAL")
    ]
    assert audit.illegal_transitions[0].t_ns == _ns(12.0)
    # 13 BmBox states in the schedule: 12 transitions, every one checked.
    assert audit.transitions_checked == 12
    assert set(audit.illegal_transitions[0].allowed) == {"WAITING_RESULT", "READY", "END"}


def test_silence_measured_between_last_and_next_beat(audit) -> None:  # type: ignore[no-untyped-def]
    # Beats at 5.0 and 7.0 s survive (the drop is exclusive): a 2.0 s gap, exact in ns.
    assert len(audit.silences) == 1
    s = audit.silences[0]
    assert (s.machine, s.start_ns, s.end_ns) == (Machine.BMBOX, _ns(5.0), _ns(7.0))
    assert s.duration_ns == 2_000_000_000
    assert s.state_name == "WAITING_RESULT"
    assert s.topic == "/fbm2h/bmbox_state"


def test_silence_threshold_is_strict() -> None:
    bm = heartbeat(Machine.BMBOX, BMBOX, 20.0, drop=(5.0, 7.0))
    # A 2.0 s gap is reported at 1.99 s but not at exactly 2.0 s; 0.1 s beats never are.
    assert len(audit_states(bm, max_silence_ns=1_990_000_000).silences) == 1
    assert len(audit_states(bm, max_silence_ns=2_000_000_000).silences) == 0
    bm_full = heartbeat(Machine.BMBOX, BMBOX, 20.0)
    assert audit_states(bm_full, max_silence_ns=BEAT_NS).silences == ()


def test_timeout_ends_the_second_run(audit) -> None:  # type: ignore[no-untyped-def]
    assert len(audit.early_ends) == 1
    end = audit.early_ends[0]
    assert (end.t_ns, end.reason, end.run, end.bmbox_state) == (
        _ns(19.9),
        "timeout",
        1,
        "WAITING_RESULT",
    )
    assert any("timeout" in w for w in audit.warnings)


def test_runs_with_goal_result_and_outcome(audit) -> None:  # type: ignore[no-untyped-def]
    assert len(audit.runs) == 2
    r0, r1 = audit.runs
    assert (r0.start_ns, r0.end_ns, r0.outcome) == (_ns(3.0), _ns(10.0), "completed")
    assert r0.goal == GOAL
    assert (r0.result, r0.result_ns) == ("{int: 1}", _ns(9.8))
    assert r0.executing_ns == _ns(3.5)
    assert r0.states == ("TRANSMITTING_GOAL", "EXECUTING_GOAL", "WAITING_RESULT")
    assert (r1.start_ns, r1.end_ns, r1.outcome) == (_ns(11.0), _ns(20.0), "timeout")
    assert r1.result == ""


def test_timeline_durations(audit) -> None:  # type: ignore[no-untyped-def]
    bm = [e for e in audit.timeline if e.machine is Machine.BMBOX]
    assert [e.state for e in bm] == [s for _, s, _ in BMBOX]
    waiting = bm[5]
    # WAITING_RESULT from 4.0 s until READY at 10.0 s, the silence inside does not split it.
    assert (waiting.state_name, waiting.duration_ns) == ("WAITING_RESULT", 6_000_000_000)
    assert bm[3].kind == "goal" and bm[3].payload == GOAL
    assert bm[-1].duration_ns == 0  # END is the last heartbeat
    refbox_end = next(e for e in audit.timeline if e.machine is Machine.REFBOX and e.state == 6)
    assert (refbox_end.kind, refbox_end.duration_ns) == ("end_reason", 100_000_000)
    result = next(e for e in audit.timeline if e.kind == "result")
    assert result.duration_ns == 400_000_000  # COMPLETED_GOAL 9.8 s -> WAITING_GOAL 10.2 s
    starts = [e.start_ns for e in audit.timeline]
    assert starts == sorted(starts)
    assert (audit.start_ns, audit.end_ns) == (_ns(0.0), _ns(20.0))
    assert audit.benchmark == "fbm2h"


def test_tables_and_dict(audit) -> None:  # type: ignore[no-untyped-def]
    tables = audit.tables()
    assert len(tables["timeline"]) == len(BMBOX) + len(REFBOX) + len(CLIENT)
    assert tables["silences"][0]["duration"] == pytest.approx(2.0, abs=1e-12)
    assert tables["runs"][1]["outcome"] == "timeout"
    d = audit.to_dict()
    assert d["illegal_transitions"][0]["t"] == pytest.approx(12.0, abs=1e-9)
    assert d["runs"]["0"]["duration"] == pytest.approx(7.0, abs=1e-12)
    assert "live_score" in audit.to_yaml()


def test_complete_benchmark_with_live_score() -> None:
    score = "best_distance_error: 0.0123\nbest_run: 2\nexecution_time: 41.5\n"
    bm = heartbeat(
        Machine.BMBOX,
        [
            (0.0, B.START, ""),
            (0.2, B.WAITING_CLIENT, ""),
            (0.5, B.READY, ""),
            (1.0, B.WAITING_MANUAL_OPERATION, "Place item 3 (a3) on the table"),
            (2.0, B.COMPLETED_MANUAL_OPERATION, ""),
            (2.5, B.TRANSMITTING_GOAL, "line"),
            (3.0, B.EXECUTING_GOAL, ""),
            (4.0, B.WAITING_RESULT, ""),
            (5.0, B.READY, ""),
            (5.5, B.WAITING_MANUAL_OPERATION, "Place item 4 (a4) on the table"),
            (6.0, B.READY, ""),  # allowed: the referee cancelled the manual operation
            (6.5, B.TRANSMITTING_SCORE, score),
            (7.0, B.END, ""),
        ],
        7.0,
    )
    audit = audit_states(bm)
    assert audit.illegal_transitions == ()
    assert audit.silences == ()
    assert audit.live_score == {
        "best_distance_error": 0.0123,
        "best_run": 2,
        "execution_time": 41.5,
    }
    assert audit.live_score_text == score
    assert [r.outcome for r in audit.runs] == ["completed", "cancelled"]
    assert audit.runs[0].manual_operation == "Place item 3 (a3) on the table"
    assert audit.runs[0].goal == "line"
    # Missing RefBox and Client topics are said, not failed.
    assert sum("no refbox" in w or "no client" in w for w in audit.warnings) == 2


def test_unknown_state_code_is_illegal() -> None:
    bm = heartbeat(Machine.BMBOX, [(0.0, B.START, ""), (1.0, 42, "")], 2.0)
    audit = audit_states(bm)
    assert [(x.from_state, x.to_state) for x in audit.illegal_transitions] == [
        ("START", "UNKNOWN(42)")
    ]


def test_late_recording_is_warned_not_failed() -> None:
    bm = heartbeat(Machine.BMBOX, [(0.0, B.READY, ""), (1.0, B.TRANSMITTING_GOAL, "")], 2.0)
    audit = audit_states(bm)
    assert audit.illegal_transitions == ()
    assert any("starts in READY" in w for w in audit.warnings)
    assert [r.outcome for r in audit.runs] == ["unfinished"]


def test_empty_audit() -> None:
    audit = audit_states(None)
    assert audit.timeline == () and audit.runs == ()
    assert len(audit.warnings) == 3


def test_payload_with_python_tags_is_read_as_data_not_constructed() -> None:
    text = (
        "details:\n  1:\n    robot_pose: !!python/object:geometry_msgs.msg._Pose2D.Pose2D"
        " {theta: 0.5, x: 1.0, y: 2.0}\nposition_accuracy: 0.25\n"
        "evil: !!python/object/apply:os.system ['echo pwned']\n"
    )
    data = parse_payload(text)
    assert data["details"][1]["robot_pose"] == {"theta": 0.5, "x": 1.0, "y": 2.0}
    assert data["position_accuracy"] == 0.25
    assert data["evil"] == ["echo pwned"]  # a plain list, never called


def test_unparsable_live_score_is_kept_as_text() -> None:
    bm = heartbeat(
        Machine.BMBOX,
        [
            (0.0, B.START, ""),
            (0.5, B.WAITING_CLIENT, ""),
            (1.0, B.READY, ""),
            (1.5, B.TRANSMITTING_SCORE, "a: [unclosed"),
            (2.0, B.END, ""),
        ],
        2.0,
    )
    audit = audit_states(bm)
    assert audit.live_score is None and audit.live_score_text == "a: [unclosed"
    assert any("not YAML" in w for w in audit.warnings)


def test_topic_that_stops_before_the_log_ends() -> None:
    # The Client's node dies at 12.0 s in EXECUTING_GOAL; the BmBox goes on until 20.0 s.
    bm = heartbeat(Machine.BMBOX, BMBOX, 20.0)
    cl = heartbeat(Machine.CLIENT, CLIENT[:-1], 12.0)
    audit = audit_states(bm, None, cl)
    (s,) = audit.silences
    assert (s.machine, s.start_ns, s.end_ns, s.trailing) == (
        Machine.CLIENT,
        _ns(12.0),
        _ns(20.0),
        True,
    )
    assert s.state_name == "EXECUTING_GOAL"
    # A machine silent after END is not a silence: the 2015 nodes stopped publishing then.
    cl_end = heartbeat(Machine.CLIENT, [*CLIENT[:-1], (12.0, C.END, "")], 12.0)
    assert audit_states(bm, None, cl_end).silences == ()


def test_halt_between_runs() -> None:
    # The referee halts the benchmark at 2.5 s, after READY and before any run started.
    bm = heartbeat(Machine.BMBOX, [*BMBOX[:3], (2.6, B.END, "")], 3.0)
    rb = heartbeat(Machine.REFBOX, [(0.0, R.START, ""), (2.5, R.END, "halt")], 3.0)
    audit = audit_states(bm, rb, None)
    (end,) = audit.early_ends
    assert (end.reason, end.payload, end.run, end.bmbox_state) == ("halt", "halt", None, "READY")
    assert audit.runs == ()
    assert not any("without sending a score" in w for w in audit.warnings)  # it was halted


def test_an_unknown_end_payload_is_warned_about_and_is_no_halt() -> None:
    # "emergency halt" is neither the seed's "halt" nor the 2015 "reason: stop": no guessing
    # from its words; one warning naming the file and the time, and no early end.
    bm = heartbeat(Machine.BMBOX, [*BMBOX[:3], (2.6, B.END, "")], 3.0)
    rb = heartbeat(Machine.REFBOX, [(0.0, R.START, ""), (2.5, R.END, "emergency halt")], 3.0)
    rb = replace(rb, source="run7.bag", topic="/fbm2h/refbox_state")
    audit = audit_states(bm, rb, None)
    assert audit.early_ends == ()
    said = [w for w in audit.warnings if "emergency halt" in w]
    assert len(said) == 1
    assert said[0].startswith("run7.bag: /fbm2h/refbox_state at t=2.500 s: RefBox END")
    assert "neither a timeout nor a stop" in said[0]
