"""The toy's frozen result: its listing and its table (``to_dict``/``to_yaml``/``to_frames``
come from :class:`ertools.benchmarks.results.ResultBase`)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from ertools.benchmarks.base import Rows
from ertools.benchmarks.results import ResultBase
from ertools.fidelity import Deviation
from ertools.streams import Provenance


@dataclass(frozen=True)
class ToyResult(ResultBase):
    """The count of marker poses (times ``scale``) and their mean x."""

    count: float
    mean_x: float
    name: str = "toy"
    warnings: tuple[str, ...] = ()
    deviations: tuple[Deviation, ...] = ()
    failures: tuple[str, ...] = ()
    provenance: Provenance = field(default_factory=Provenance)

    def listing(self) -> dict[Any, Any]:
        return {"count": self.count, "mean_x": self.mean_x}

    def tables(self) -> dict[str, Rows]:
        return {"score": [{"count": self.count, "mean_x": self.mean_x}]}
