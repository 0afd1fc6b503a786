"""RefBox END payloads: one table, read the same by every benchmark and by the audit.

The table is derived from the 2015 code and the seed, not from ertools:

- ``rockin_scoring/BmBox.py`` (rockin-robot-challenge/benchmark_and_scoring_fbm at 7628309)
  compares the whole payload with ``==`` / ``!=``: ``"reason: timeout"`` (l. 49, 97, 117:
  ``Timeout()``) and ``"reason: stop"`` (l. 53, 100, 126: ``Running()``). Nothing else was a
  timeout or a stop to it: under ``--2015`` (``--exact-end-payloads``) only these two strings
  are.
- The 2015 @Home RefBox (rockin-robot-challenge/at_home_rsbb, src/core_zone_exec.h,
  ``phase_post_2``) sent exactly those two strings.
- The seed (6.2.3) names ``timeout`` and ``halt`` (the referee's stop); an END without payload is
  one the RefBox did not issue for a reason. ertools' default reads these two words by their
  meaning too (a documented reading, said in a ``differs from 2015`` line).
- Anything else (another case, a trailing blank, a word inside a longer text) is no known form
  in either mode: one warning naming the file and time, and neither a timeout nor a stop.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pytest

from ertools.auditing.analyse import audit_states
from ertools.benchmarks.common.ending import (
    RULE_END_PAYLOADS,
    cut_warning,
    end_payload_deviation,
    log_cut,
    refbox_ends,
)
from ertools.benchmarks.fbm1.runs import runs_from_states
from ertools.benchmarks.fbm2h.runs import from_states
from ertools.benchmarks.fbm3w.runs import find_states
from ertools.io.model import BenchmarkStates
from ertools.states import (
    END_PAYLOAD_FORMS,
    BmBoxState,
    ClientState,
    EndReason,
    Machine,
    RefBoxState,
    end_reason,
    unknown_end_warning,
)
from ertools.streams import StateStream

S = 1_000_000_000
T0 = 1_448_020_800 * S
SOURCE = "run.bag"

T, P, N, U = "timeout", "stop", "neither", "unknown"  # P: a stop (halt)

# payload -> (ertools' default reading, the 2015 BmBox's reading)
TABLE: dict[str, tuple[str, str]] = {
    "reason: timeout": (T, T),  # BmBox.py Timeout(); at_home_rsbb phase_post_2
    "reason: stop": (P, P),  # BmBox.py Running(); at_home_rsbb phase_post_2
    "timeout": (T, U),  # seed 6.2.3; not a string BmBox.py compares
    "halt": (P, U),  # seed 6.2.3; not a string BmBox.py compares
    "": (N, N),  # no reason given (seed 6.2.3); neither string to BmBox.py
    "Reason: Stop": (U, U),  # compared whole: case matters
    "reason: stop ": (U, U),  # and blanks
    "reason: timeout\n": (U, U),
    "stop": (U, U),
    "TIMEOUT": (U, U),
    "emergency halt": (U, U),  # a word inside a longer text is no form
    "timeout exceeded": (U, U),
    "reason: finished": (U, U),
}
MODES = {"default": False, "2015": True}
CASES = [(p, mode) for p in TABLE for mode in MODES]
IDS = [f"{mode}-{p!r}" for p, mode in CASES]


def _expected(payload: str, mode: str) -> str:
    return TABLE[payload][0 if mode == "default" else 1]


def _stream(machine: Machine, rows: list[tuple[float, int, str]], topic: str) -> StateStream:
    t = np.array([T0 + round(a * S) for a, _, _ in rows], np.int64)
    return StateStream(
        machine,
        t,
        np.array([s for _, s, _ in rows], np.uint8),
        tuple(p for *_, p in rows),
        topic,
        SOURCE,
    )


@dataclass(frozen=True)
class Log:
    """One run: manual operation, goal, path; the RefBox ENDs at 5 s with the payload; the
    BmBox leaves WAITING_RESULT at 5.05 s and sends its score; the robot never answers."""

    bmbox: StateStream
    refbox: StateStream
    client: StateStream


def _log(payload: str, ns: str = "fbm1h", *, answered: bool = False) -> Log:
    """``answered``: the robot reports at 5.5 s and the BmBox leaves WAITING_RESULT at 5.6 s,
    as the 2015 BmBox did after an END payload it did not compare equal (it waited on)."""
    B, R, C = BmBoxState, RefBoxState, ClientState
    back = 5.6 if answered else 5.05
    bmbox = _stream(
        Machine.BMBOX,
        [
            (0.0, B.READY, ""),
            (1.0, B.WAITING_MANUAL_OPERATION, "Place item 1 (a1) on the table"),
            (2.0, B.COMPLETED_MANUAL_OPERATION, ""),
            (3.0, B.TRANSMITTING_GOAL, "line"),
            (3.2, B.EXECUTING_GOAL, ""),
            (3.3, B.WAITING_RESULT, ""),
            (back, B.READY, ""),
            (6.0, B.TRANSMITTING_SCORE, "{}"),
            (6.5, B.END, ""),
        ],
        f"/{ns}/bmbox_state",
    )
    refbox = _stream(
        Machine.REFBOX,
        [
            (0.0, R.READY, ""),
            (1.1, R.EXECUTING_MANUAL_OPERATION, ""),
            (1.9, R.EXECUTING_GOAL, ""),
            (5.0, R.END, payload),
        ],
        f"/{ns}/refbox_state",
    )
    answer = "{item_class: a, item_instance: a1, x: 0.1, y: 0.2, theta: 0.0}"
    client = _stream(
        Machine.CLIENT,
        [
            (0.0, C.READY, ""),
            (0.5, C.WAITING_GOAL, ""),
            (3.1, C.EXECUTING_GOAL, ""),
            *([(5.5, C.COMPLETED_GOAL, answer)] if answered else []),
        ],
        f"/{ns}/client_state",
    )
    return Log(bmbox, refbox, client)


def _unknown_lines(warnings: tuple[str, ...] | list[str], payload: str) -> list[str]:
    return [w for w in warnings if f"RefBox END with payload {payload!r}" in w]


def _check_warned(warnings: tuple[str, ...] | list[str], payload: str, want: str) -> None:
    said = _unknown_lines(warnings, payload)
    if want != U:
        assert said == []
        return
    # one warning, naming the file, the topic and the time (5 s after the first BmBox message)
    assert len(said) == 1, warnings
    assert said[0].startswith(f"{SOURCE}: /")
    assert "refbox_state at t=5.000 s: RefBox END" in said[0]
    assert "neither a timeout nor a stop" in said[0]


# --- the reading itself ---------------------------------------------------------------------


@pytest.mark.parametrize(("payload", "mode"), CASES, ids=IDS)
def test_end_reason_is_the_table(payload: str, mode: str) -> None:
    want = {T: EndReason.TIMEOUT, P: EndReason.STOP, N: EndReason.NONE, U: EndReason.UNKNOWN}
    assert end_reason(payload, exact_2015=MODES[mode]) is want[_expected(payload, mode)]


def test_the_forms_are_the_ones_the_sources_name() -> None:
    forms = {f.text: f for f in END_PAYLOAD_FORMS}
    assert set(forms) == {"reason: timeout", "reason: stop", "timeout", "halt", ""}
    assert {t for t, f in forms.items() if f.read_2015} == {"reason: timeout", "reason: stop", ""}
    assert all(f.source for f in forms.values())
    line = unknown_end_warning("reason: finished", "t=3.0 s", exact_2015=True)
    assert "'reason: finished'" in line and "'reason: stop'" in line and "'halt'" not in line
    assert "\n" not in line


# --- every consumer reads the table the same way ---------------------------------------------


@pytest.mark.parametrize(("payload", "mode"), CASES, ids=IDS)
def test_fbm1_reads_the_table(payload: str, mode: str) -> None:
    log = _log(payload)
    found = runs_from_states(log.bmbox, log.refbox, log.client, t0_ns=T0, exact_2015=MODES[mode])
    (run,) = found.runs
    want = _expected(payload, mode)
    assert run.ended_by == {T: "timeout", P: "stop"}.get(want)
    _check_warned(found.warnings, payload, want)
    seed = mode == "default" and payload in ("timeout", "halt")
    assert [d.rule for d in found.deviations] == ([RULE_END_PAYLOADS] if seed else [])


@pytest.mark.parametrize(("payload", "mode"), CASES, ids=IDS)
def test_fbm3w_reads_the_table(payload: str, mode: str) -> None:
    log = _log(payload, "fbm3w")
    states = BenchmarkStates(log.bmbox, log.refbox, log.client)
    (run,) = find_states(states, exact_2015=MODES[mode])
    want = _expected(payload, mode)
    assert run.status == {T: "timeout", P: "stopped"}.get(want, "completed")
    _check_warned(run.warnings, payload, want)


@pytest.mark.parametrize("clock", ["client", "bmbox"])
@pytest.mark.parametrize(("payload", "mode"), CASES, ids=IDS)
def test_fbm2h_reads_the_table(payload: str, mode: str, clock: str) -> None:
    log = _log(payload, "fbm2h")
    moments = from_states(
        log.bmbox, log.client, log.refbox, clock=clock, exact_2015=MODES[mode], t0_ns=T0
    )
    want = _expected(payload, mode)
    early = moments.early_end
    if want in (T, P):
        assert early is not None and early.kind == {T: "timeout", P: "stop"}[want]
        assert len(moments) == 0
    elif clock == "client":
        # the robot never reported the waypoint: the END ended the segment, for no reason
        assert early is not None and early.kind == "ended"
    else:
        # the 2015 clock: the BmBox went back to READY with neither string: a completed segment
        assert early is None and len(moments) == 1
    _check_warned(moments.warnings, payload, want)
    seed = mode == "default" and payload in ("timeout", "halt")
    assert [d.rule for d in moments.deviations] == ([RULE_END_PAYLOADS] if seed else [])


@pytest.mark.parametrize("payload", list(TABLE), ids=[repr(p) for p in TABLE])
def test_the_audit_reads_the_table(payload: str) -> None:
    """The audit reads as the scorers' default (it has no --2015)."""
    log = _log(payload)
    audit = audit_states(log.bmbox, log.refbox, log.client)
    want = _expected(payload, "default")
    named = {T: "timeout", P: "halt"}  # the audit's words for the two early ends
    assert [e.reason for e in audit.early_ends] == ([named[want]] if want in named else [])
    _check_warned(audit.warnings, payload, want)


@pytest.mark.parametrize(("payload", "mode"), CASES, ids=IDS)
def test_neither_means_the_run_goes_on_in_every_consumer(payload: str, mode: str) -> None:
    """The robot answers after the END: a timeout or a stop ended the run first (its answer is
    ignored); any other END changed nothing, in FBM1, FBM2H, FBM3W and the audit alike."""
    exact = MODES[mode]
    want = _expected(payload, mode)
    early = want in (T, P)
    log = _log(payload, answered=True)
    (run,) = runs_from_states(log.bmbox, log.refbox, log.client, t0_ns=T0, exact_2015=exact).runs
    assert (run.answer_payload is None) is early and (run.ended_by is not None) is early
    log = _log(payload, "fbm2h", answered=True)
    for clock in ("client", "bmbox"):
        moments = from_states(
            log.bmbox, log.client, log.refbox, clock=clock, exact_2015=exact, t0_ns=T0
        )
        assert (len(moments), moments.early_end is not None) == (int(not early), early), clock
    log = _log(payload, "fbm3w", answered=True)
    (window,) = find_states(BenchmarkStates(log.bmbox, log.refbox, log.client), exact_2015=exact)
    assert (window.status == "completed") is not early
    if mode == "default":
        audit = audit_states(log.bmbox, log.refbox, log.client)
        (audited,) = audit.runs
        assert (audited.outcome == "completed") is not early


# --- the shared pieces ----------------------------------------------------------------------


def test_the_deviation_names_the_seed_words_and_the_option() -> None:
    log = _log("halt")
    said = end_payload_deviation(log.refbox, T0)
    assert said is not None and said.rule is RULE_END_PAYLOADS
    assert "'halt' at t=5.000 s as a stop" in said and "--exact-end-payloads" in said
    assert end_payload_deviation(log.refbox, T0, exact_2015=True) is None
    assert end_payload_deviation(_log("reason: stop").refbox, T0) is None


def test_refbox_ends_one_per_stretch_and_payload() -> None:
    rb = _stream(
        Machine.REFBOX,
        [
            (0.0, RefBoxState.READY, ""),
            (1.0, RefBoxState.END, "reason: timeout"),
            (1.1, RefBoxState.END, "reason: timeout"),  # heartbeat: the same END
            (1.2, RefBoxState.END, "reason: stop"),  # a new payload: a new END
        ],
        "/fbm3w/refbox_state",
    )
    ends = refbox_ends(rb)
    assert [(e.t_ns - T0, e.reason) for e in ends] == [
        (S, EndReason.TIMEOUT),
        (1_200_000_000, EndReason.STOP),
    ]
    assert refbox_ends(rb, T0 + 1_100_000_000, None)[0].payload == "reason: stop"
    assert refbox_ends(None) == []


def test_log_cut_only_inside_the_benchmark() -> None:
    inside = _stream(
        Machine.BMBOX,
        [(0.0, BmBoxState.READY, ""), (2.5, BmBoxState.WAITING_RESULT, "")],
        "/fbm3w/bmbox_state",
    )
    assert log_cut(inside) == T0 + 2_500_000_000
    done = _stream(
        Machine.BMBOX,
        [(0.0, BmBoxState.READY, ""), (2.5, BmBoxState.TRANSMITTING_SCORE, "")],
        "/fbm3w/bmbox_state",
    )
    assert log_cut(done) is None

    def refbox(payload: str) -> StateStream:
        rows = [(0.0, RefBoxState.READY, ""), (2.0, RefBoxState.END, payload)]
        return _stream(Machine.REFBOX, rows, "/fbm3w/refbox_state")

    assert log_cut(inside, refbox("reason: stop")) is None
    # the seed's halt is a stop by default, nothing to the 2015 BmBox: then the log is cut
    assert log_cut(inside, refbox("halt")) is None
    assert log_cut(inside, refbox("halt"), exact_2015=True) == T0 + 2_500_000_000
    # an unknown END is not a stop: the log is still cut inside the benchmark
    assert log_cut(inside, refbox("over")) == T0 + 2_500_000_000
    line = cut_warning(T0 + 2_500_000_000, inside, T0, "run 3", "run 3 not scored")
    assert "t=2.500 s inside run 3 (BmBox in WAITING_RESULT)" in line and "stopped there" in line
