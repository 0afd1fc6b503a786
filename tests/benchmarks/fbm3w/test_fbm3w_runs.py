"""Run finding from BmBox/RefBox transitions on hand-made state streams."""

from __future__ import annotations

import numpy as np
import pytest

from ertools.benchmarks.fbm3w.runs import find_states, find_windows, with_specs
from ertools.benchmarks.fbm3w.settings import Fbm3wConfig
from ertools.errors import SegmentationError
from ertools.io.model import BenchmarkStates
from ertools.states import BmBoxState as B
from ertools.states import Machine
from ertools.states import RefBoxState as R
from ertools.streams import StateStream

S = 1_000_000_000


def stream(machine: Machine, items: list[tuple[float, int, str]]) -> StateStream:
    """Transitions plus a 10 Hz heartbeat repeating each state (as the 2015 nodes)."""
    t, st, pl = [], [], []
    for i, (ts, code, payload) in enumerate(items):
        end = items[i + 1][0] if i + 1 < len(items) else ts + 0.3
        for k in np.arange(ts, end, 0.1):
            t.append(round(k * S))
            st.append(code)
            pl.append(payload)
    return StateStream(machine, np.array(t, np.int64), np.array(st, np.uint8), tuple(pl))


def run_items(t0: float, spec: str) -> list[tuple[float, int, str]]:
    return [
        (t0, B.WAITING_MANUAL_OPERATION, ""),
        (t0 + 1.0, B.COMPLETED_MANUAL_OPERATION, ""),
        (t0 + 1.5, B.TRANSMITTING_GOAL, spec),
        (t0 + 3.0, B.EXECUTING_GOAL, ""),
        (t0 + 3.05, B.WAITING_RESULT, ""),
        (t0 + 9.0, B.READY, ""),
    ]


def test_two_runs_and_end() -> None:
    items = [
        (0.0, B.START, ""),
        (0.5, B.READY, ""),
        *run_items(1.0, "line"),
        *run_items(11.0, "spline"),
    ]
    items += [(21.0, B.TRANSMITTING_SCORE, "score"), (21.5, B.END, "")]
    runs = find_states(BenchmarkStates(stream(Machine.BMBOX, items), None, None))
    assert [(r.spec, r.status) for r in runs] == [("line", "completed"), ("spline", "completed")]
    assert runs[0].ref_ns == 2 * S and runs[0].start_ns == 4 * S and runs[0].end_ns == 10 * S
    assert runs[1].execution_time_s == pytest.approx(6.0)


def test_refbox_timeout_marks_the_run() -> None:
    items = [(0.0, B.READY, ""), *run_items(1.0, "line")[:-1], (8.0, B.READY, ""), (8.3, B.END, "")]
    refbox = stream(
        Machine.REFBOX, [(0.0, R.READY, ""), (4.0, R.EXECUTING_GOAL, ""), (7.95, R.END, "timeout")]
    )
    runs = find_states(BenchmarkStates(stream(Machine.BMBOX, items), refbox, None))
    assert runs[0].status == "timeout"
    assert runs[0].execution_time_s == pytest.approx(4.0)  # EXECUTING_GOAL at 4 s, READY at 8 s


def test_stop_interrupt_and_log_end() -> None:
    # run 0 stopped by the RefBox during its path; BmBox goes straight to END
    items = [(0.0, B.READY, ""), *run_items(1.0, "line")[:-1], (6.0, B.END, "")]
    refbox = stream(Machine.REFBOX, [(0.0, R.READY, ""), (5.9, R.END, "reason: stop")])
    run = find_states(BenchmarkStates(stream(Machine.BMBOX, items), refbox, None))[0]
    assert (run.status, run.warnings) == ("stopped", ())
    assert "RefBox END 'reason: stop'" in run.note
    # benchmark ends during the manual operation: reported, no path window
    items = [(0.0, B.READY, ""), *run_items(1.0, "line")[:2], (2.5, B.END, "")]
    run = find_states(BenchmarkStates(stream(Machine.BMBOX, items), None, None))[0]
    assert (run.status, run.start_ns, run.end_ns) == ("interrupted", None, None)
    # the log stops while the path is collected: the benchmark stopped there, said so
    items = [(0.0, B.READY, ""), *run_items(1.0, "line")[:-1]]
    bm = stream(Machine.BMBOX, items)
    run = find_states(BenchmarkStates(bm, None, None))[0]
    assert (run.status, run.end_ns) == ("stopped", int(bm.t_ns[-1]))
    (said,) = run.warnings
    assert "inside run 0 (BmBox in WAITING_RESULT)" in said and "stopped there" in said
    # ... and while the manual operation is waited for: no path, said too
    items = [(0.0, B.READY, ""), *run_items(1.0, "line")[:1]]
    run = find_states(BenchmarkStates(stream(Machine.BMBOX, items), None, None))[0]
    assert (run.status, run.start_ns) == ("interrupted", None)
    assert "its path had not started" in run.warnings[0]


def test_end_payloads_as_the_2015_bmbox_compared_them() -> None:
    """BmBox.py compares the whole payload: "reason: stop" stops, "reason: timeout" times
    out; by default the seed's "halt"/"timeout" mean the same (not under --exact-end-payloads:
    tests/benchmarks/common/test_end_payloads.py); any other END payload meant neither to it
    (Running() stayed true): the run is what the BmBox did, and a warning names the payload."""
    items = [(0.0, B.READY, ""), *run_items(1.0, "line")[:-1], (8.0, B.READY, ""), (8.3, B.END, "")]
    bm = stream(Machine.BMBOX, items)
    for payload, status in [
        ("reason: timeout", "timeout"),
        ("timeout", "timeout"),
        ("reason: stop", "stopped"),
        ("halt", "stopped"),
        ("Reason: Stop", "completed"),
        ("stopped by the referee", "completed"),
    ]:
        rb = stream(Machine.REFBOX, [(0.0, R.READY, ""), (7.95, R.END, payload)])
        run = find_states(BenchmarkStates(bm, rb, None))[0]
        assert run.status == status, payload
        assert bool(run.warnings) is (status == "completed"), payload
        if run.warnings:
            assert repr(payload) in run.warnings[0] and "'reason: stop'" in run.warnings[0]


def test_reference_carried_over_when_no_manual_operation() -> None:
    # an early 2015 variant acquired the reference once, then sent goals run after run
    second = [
        (12.5, B.TRANSMITTING_GOAL, "spline"),
        (14.0, B.EXECUTING_GOAL, ""),
        (14.05, B.WAITING_RESULT, ""),
        (20.0, B.READY, ""),
    ]
    items = [(0.0, B.READY, ""), *run_items(1.0, "line"), *second]
    runs = find_states(BenchmarkStates(stream(Machine.BMBOX, items), None, None))
    assert runs[1].ref_ns == runs[0].ref_ns == 2 * S
    assert "previous manual operation" in runs[1].note


def test_specs_from_config_with_warning() -> None:
    items = [(0.0, B.READY, ""), *run_items(1.0, "spline")]
    runs = find_states(BenchmarkStates(stream(Machine.BMBOX, items), None, None))
    fixed, warnings = with_specs(runs, Fbm3wConfig())
    assert fixed[0].spec == "line"  # Listing 14's first run
    assert "the BmBox goal says 'spline', the config says 'line'" in warnings[0]


def test_no_runs_or_no_topic() -> None:
    with pytest.raises(SegmentationError, match="bmbox_state"):
        find_states(BenchmarkStates(None, None, None))
    with pytest.raises(SegmentationError, match="no run found"):
        find_states(BenchmarkStates(stream(Machine.BMBOX, [(0.0, B.READY, "")]), None, None))


def test_windows_resolve_relative_and_epoch_times() -> None:
    start = 1_448_020_800 * S
    runs = find_windows(
        [("line", 1.0, 2.0, 3.5), ("line", 1_448_020_801.0, 1_448_020_802.0, 1_448_020_803.5)],
        start,
    )
    assert runs[0].ref_ns == runs[1].ref_ns == start + S
    assert runs[0].end_ns == runs[1].end_ns == start + 3 * S + S // 2
