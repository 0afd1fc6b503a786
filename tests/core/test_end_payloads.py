"""RefBox END payloads as the 2015 BmBox read them, and a log ending inside a benchmark.

The forms come from ``rockin_scoring/BmBox.py`` (svenschneider/benchmark_and_scoring_fbm at
90d5c4d: lines 49, 53, 97, 100, 117, 126 compare ``"reason: timeout"`` and ``"reason: stop"``
with ``==`` / ``!=``) and the seed (6.2.3: ``timeout`` and ``halt``).
"""

from __future__ import annotations

import numpy as np
import pytest

from ertools.benchmarks.common.ending import cut_warning, log_cut, refbox_ends
from ertools.states import (
    END_PAYLOAD_FORMS,
    BmBoxState,
    EndReason,
    Machine,
    RefBoxState,
    end_reason,
    unknown_end_warning,
)
from ertools.streams import StateStream

S = 1_000_000_000


def _stream(machine: Machine, rows: list[tuple[float, int, str]]) -> StateStream:
    t = np.array([round(a * S) for a, _, _ in rows], np.int64)
    return StateStream(
        machine, t, np.array([s for _, s, _ in rows], np.uint8), tuple(p for *_, p in rows)
    )


@pytest.mark.parametrize(
    ("payload", "reason"),
    [
        ("reason: timeout", EndReason.TIMEOUT),  # BmBox.Timeout(): == "reason: timeout"
        ("reason: stop", EndReason.STOP),  # BmBox.Running(): != "reason: stop"
        ("timeout", EndReason.TIMEOUT),  # seed 6.2.3
        ("halt", EndReason.STOP),  # seed 6.2.3
        # compared exactly in 2015: none of these was a timeout or a stop to the BmBox
        ("reason: Stop", EndReason.UNKNOWN),
        ("reason: stop ", EndReason.UNKNOWN),
        ("stop", EndReason.UNKNOWN),
        ("emergency halt", EndReason.UNKNOWN),
        ("", EndReason.UNKNOWN),
    ],
)
def test_end_reason_is_an_exact_comparison(payload: str, reason: EndReason) -> None:
    assert end_reason(payload) is reason


def test_every_form_is_listed_with_its_source() -> None:
    assert {f.text for f in END_PAYLOAD_FORMS} == {
        "reason: timeout",
        "reason: stop",
        "timeout",
        "halt",
    }
    assert all(f.source for f in END_PAYLOAD_FORMS)
    line = unknown_end_warning("reason: finished", "t=3.0 s")
    assert "'reason: finished'" in line and "'reason: stop'" in line and "\n" not in line


def test_refbox_ends_one_per_stretch_and_payload() -> None:
    rb = _stream(
        Machine.REFBOX,
        [
            (0.0, RefBoxState.READY, ""),
            (1.0, RefBoxState.END, "reason: timeout"),
            (1.1, RefBoxState.END, "reason: timeout"),  # heartbeat: the same END
            (1.2, RefBoxState.END, "reason: stop"),  # a new payload: a new END
        ],
    )
    ends = refbox_ends(rb)
    assert [(e.t_ns, e.reason) for e in ends] == [
        (S, EndReason.TIMEOUT),
        (1_200_000_000, EndReason.STOP),
    ]
    assert refbox_ends(rb, 1_100_000_000, None)[0].payload == "reason: stop"
    assert refbox_ends(None) == []


def test_log_cut_only_inside_the_benchmark() -> None:
    inside = _stream(
        Machine.BMBOX, [(0.0, BmBoxState.READY, ""), (2.5, BmBoxState.WAITING_RESULT, "")]
    )
    assert log_cut(inside) == 2_500_000_000
    done = _stream(
        Machine.BMBOX, [(0.0, BmBoxState.READY, ""), (2.5, BmBoxState.TRANSMITTING_SCORE, "")]
    )
    assert log_cut(done) is None
    stopped = _stream(
        Machine.REFBOX, [(0.0, RefBoxState.READY, ""), (2.0, RefBoxState.END, "reason: stop")]
    )
    assert log_cut(inside, stopped) is None
    # an unknown END is not a stop: the log is still cut inside the benchmark
    odd = _stream(Machine.REFBOX, [(0.0, RefBoxState.READY, ""), (2.0, RefBoxState.END, "over")])
    assert log_cut(inside, odd) == 2_500_000_000
    line = cut_warning(2_500_000_000, inside, 0, "run 3", "run 3 not scored")
    assert "t=2.500 s inside run 3 (BmBox in WAITING_RESULT)" in line and "stopped there" in line
