"""What every benchmark result shares: its score listing written as JSON types and as YAML, and
its tables as pandas DataFrames, each written once here (:class:`ResultBase`).

A result class (a frozen dataclass in the benchmark's ``result`` module) subclasses
:class:`ResultBase` and gives two things: :meth:`~ResultBase.listing`, the seed's nesting of its
score (run or segment indices as integer keys, as the 2015 nodes dumped them), and
:meth:`~ResultBase.tables`, its rows for CSV files and DataFrames.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from typing import TYPE_CHECKING, Any

from ertools.frames import tables_to_frames
from ertools.serialize import dump_yaml, jsonable

if TYPE_CHECKING:
    import pandas as pd

    from ertools.benchmarks.base import Rows


class ResultBase(ABC):
    """``to_dict``, ``to_yaml`` and ``to_frames`` from :meth:`listing` and :meth:`tables`."""

    @abstractmethod
    def listing(self) -> dict[Any, Any]:
        """The score as the seed lists it: nested mappings, integer keys where it numbers runs."""

    @abstractmethod
    def tables(self) -> dict[str, Rows]:
        """CSV-ready tables by name (``runs``, ``segments``, ``items``, ``samples``...)."""

    def to_dict(self) -> dict[str, Any]:
        """The listing as JSON types (what ``--format json`` prints): keys as text, NaN as
        None."""
        data: dict[str, Any] = jsonable(self.listing())
        return data

    def to_yaml(self) -> str:
        """The listing as the seed's YAML (integer keys kept, floats to 9 decimals)."""
        return dump_yaml(jsonable(self.listing(), string_keys=False))

    def to_frames(self) -> dict[str, pd.DataFrame]:
        """Every table of :meth:`tables` as a pandas DataFrame, epoch times as a UTC index
        (:func:`ertools.frames.tables_to_frames`)."""
        return tables_to_frames(self.tables())
