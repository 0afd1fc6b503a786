"""Results as pandas DataFrames, for notebooks and users' own analysis.

Every result's ``to_frames()`` (a benchmark result, an audit) is :func:`tables_to_frames` of
its ``tables()``: each table a DataFrame. Columns that hold times become UTC datetimes:
epoch-second columns (``time``,
``start_time``, ``*_time`` with values after 2001) are converted, and when a table has one,
it becomes the DatetimeIndex named ``time``. Columns of seconds *from the start* (``start``,
``duration``, ``segment_time``...) stay floats: they are durations, not instants.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from ertools.timeutil import EPOCH_THRESHOLD_S

if TYPE_CHECKING:
    import pandas as pd

# Columns preferred as the index, in this order, when they hold epoch times.
_INDEX_PREFERENCE = ("time", "t", "start_time", "stamp", "timestamp", "from_time")


def _looks_epoch(series: pd.Series) -> bool:
    """A numeric column whose values are all epoch seconds (> 1e9) or missing."""
    import pandas as pd  # lazy: pandas only for DataFrames (~0.2 s to import)

    if not pd.api.types.is_numeric_dtype(series) or pd.api.types.is_bool_dtype(series):
        return False
    values = series.dropna()
    return bool(len(values)) and bool((values > EPOCH_THRESHOLD_S).all())


def _is_time_name(name: str) -> bool:
    lower = name.lower()
    return lower in _INDEX_PREFERENCE or lower.endswith(("_time", "_stamp", "_t"))


def rows_to_dataframe(rows: list[dict[str, Any]]) -> pd.DataFrame:
    """One table (list of dicts) as a DataFrame, epoch columns as UTC datetimes."""
    import pandas as pd  # lazy: pandas only for DataFrames (~0.2 s to import)

    df = pd.DataFrame.from_records(rows)
    converted = []
    for col in df.columns:
        if _is_time_name(str(col)) and _looks_epoch(df[col]):
            # Seconds -> ns in int64 would round through float64 anyway; float seconds are
            # what tables() hold (microsecond-exact for 2015 epoch values).
            df[col] = pd.to_datetime(df[col], unit="s", utc=True)
            converted.append(str(col))
    for name in _INDEX_PREFERENCE:
        if name in converted:
            df = df.set_index(name)
            df.index.name = "time"
            break
    return df


def tables_to_frames(tables: dict[str, list[dict[str, Any]]]) -> dict[str, pd.DataFrame]:
    """Every table of a result's ``tables()`` as a DataFrame.

    Returns:
        Table name -> DataFrame; times as a UTC DatetimeIndex named ``time`` where a column
        of epoch times exists (``time``, ``start_time``...), other time columns converted in
        place.
    """
    return {name: rows_to_dataframe(rows) for name, rows in tables.items()}
