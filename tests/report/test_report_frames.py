"""Results as DataFrames with UTC DatetimeIndex."""

from __future__ import annotations

import pandas as pd
import pytest

from ertools.auditing.analyse import audit_states
from ertools.frames import rows_to_dataframe, tables_to_frames
from ertools.states import Machine
from tests.helpers.audit_streams import BMBOX, T0_NS, heartbeat
from tests.helpers.report_fakes import fbm3w_like


def test_epoch_column_becomes_utc_index() -> None:
    frames = tables_to_frames(fbm3w_like().tables())
    runs = frames["runs"]
    assert isinstance(runs.index, pd.DatetimeIndex)
    assert str(runs.index.tz) == "UTC" and runs.index.name == "time"
    # 1.4e9 s = 2014-05-13T16:53:20Z; the second run 30.5 s later.
    assert runs.index[0] == pd.Timestamp("2014-05-13T16:53:20", tz="UTC")
    assert (runs.index[1] - runs.index[0]).total_seconds() == pytest.approx(30.5, abs=1e-6)
    assert list(runs["spec"])[1] == "spline"


def test_relative_seconds_stay_numbers() -> None:
    df = rows_to_dataframe([{"start": 1.5, "end_time": 1.4e9, "segment_time": 7.0}])
    assert df["start"].dtype.kind == "f" and df["segment_time"].dtype.kind == "f"
    assert isinstance(df.index, pd.RangeIndex)  # end_time converted but not an index name
    assert df["end_time"].iloc[0] == pd.Timestamp(1.4e9, unit="s", tz="UTC")


def test_audit_tables_as_frames() -> None:
    frames = audit_states(heartbeat(Machine.BMBOX, BMBOX, 20.0)).to_frames()
    tl = frames["timeline"]
    assert tl.index[0] == pd.Timestamp(T0_NS, unit="ns", tz="UTC")
    assert len(tl) == len(BMBOX)
