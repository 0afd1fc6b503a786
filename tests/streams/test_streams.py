"""Streams: windows, changes, DataFrames."""

from __future__ import annotations

import numpy as np
import pytest

from ertools.states import BMBOX_TRANSITIONS, BmBoxState, Machine, state_name, state_topic
from ertools.streams import PoseStream, StateStream
from ertools.timeutil import iso_utc, resolve_time


def test_pose_window_inclusive() -> None:
    t = np.arange(0, 100, 10, dtype=np.int64)
    s = PoseStream(t, np.zeros((10, 3)), np.tile([0.0, 0, 0, 1], (10, 1)))
    w = s.window(20, 50)
    assert w.t_ns.tolist() == [20, 30, 40, 50]
    assert len(s.window(None, 5)) == 1
    assert len(s.window(95, None)) == 0


def test_pose_stream_rejects_bad_shapes() -> None:
    with pytest.raises(ValueError, match="shapes disagree"):
        PoseStream(np.zeros(3, np.int64), np.zeros((2, 3)), np.zeros((3, 4)))


def test_state_changes_keep_transitions_only() -> None:
    states = np.array([1, 1, 2, 2, 2, 3, 3], dtype=np.uint8)
    payload = ("", "", "", "", "goal", "goal", "goal")
    s = StateStream(Machine.BMBOX, np.arange(7, dtype=np.int64) * 100, states, payload)
    c = s.changes()
    assert c.t_ns.tolist() == [0, 200, 400, 500]
    assert c.payload == ("", "", "goal", "goal")


def test_dataframes_have_utc_index() -> None:
    t = np.array([1_445_616_940_000_000_000, 1_445_616_940_500_000_000], dtype=np.int64)
    s = PoseStream(t, np.ones((2, 3)), np.tile([0.0, 0, 0, 1], (2, 1)))
    df = s.to_dataframe()
    assert str(df.index.tz) == "UTC"
    assert df.index[0].isoformat() == "2015-10-23T16:15:40+00:00"
    st = StateStream(Machine.CLIENT, t, np.array([5, 6], np.uint8), ("r", ""))
    assert st.to_dataframe()["state_name"].tolist() == ["COMPLETED_GOAL", "END"]


def test_states_tables() -> None:
    assert state_name(Machine.BMBOX, 8) == "TRANSMITTING_SCORE"
    assert state_name(Machine.REFBOX, 42) == "UNKNOWN(42)"
    assert state_topic("fbm2h", Machine.BMBOX) == "/fbm2h/bmbox_state"
    assert BmBoxState.END in BMBOX_TRANSITIONS[BmBoxState.WAITING_RESULT]
    assert BmBoxState.EXECUTING_GOAL not in BMBOX_TRANSITIONS[BmBoxState.READY]


def test_time_resolution() -> None:
    start = 1_445_616_940_000_000_000
    assert resolve_time(1.5, start) == start + 1_500_000_000
    assert resolve_time(1445616941.0, start) == 1_445_616_941_000_000_000
    assert iso_utc(start) == "2015-10-23T16:15:40.000000+00:00"
