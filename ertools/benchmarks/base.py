"""What every benchmark result offers, so that the CLI and the reports treat them alike."""

from __future__ import annotations

import math
from typing import Any, Protocol, runtime_checkable

from ertools.fidelity import Deviation
from ertools.streams import Provenance

Rows = list[dict[str, Any]]


@runtime_checkable
class BenchmarkResult(Protocol):
    """A frozen result of one benchmark execution.

    Attributes:
        name: the benchmark (``fbm3w``...), a key of ``ertools.benchmarks.REGISTRY``.
        warnings: things a referee should know (d_min below the noise, identity transform...).
        deviations: every place where ertools deliberately differs from the 2015 node.
        failures: runs/segments/items that could not be scored (the CLI then exits 1).
        provenance: inputs and parameters.
    """

    # Read-only properties, so that frozen dataclasses with these fields satisfy the protocol.
    @property
    def name(self) -> str: ...

    @property
    def warnings(self) -> tuple[str, ...]: ...

    @property
    def deviations(self) -> tuple[Deviation, ...]: ...

    @property
    def failures(self) -> tuple[str, ...]: ...

    @property
    def provenance(self) -> Provenance: ...

    def to_dict(self) -> dict[str, Any]:
        """JSON-able structure (same nesting as the YAML; run indices as string keys)."""
        ...

    def to_yaml(self) -> str:
        """The seed's score listing for this benchmark."""
        ...

    def tables(self) -> dict[str, Rows]:
        """CSV-ready tables by name (``runs``, ``segments``, ``items``, ``samples``...)."""
        ...


def dump_yaml(data: Any) -> str:
    """YAML as the 2015 nodes dumped it (block style, keys in insertion order), floats
    rounded to 9 decimal places (:mod:`ertools.yamlout`)."""
    from ertools.yamlout import dump

    return dump(data)


def jsonable(value: Any) -> Any:
    """Convert NumPy scalars/arrays and tuples inside ``value`` to plain JSON types."""
    import numpy as np

    if isinstance(value, dict):
        return {str(k): jsonable(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [jsonable(v) for v in value]
    if isinstance(value, np.ndarray):
        return jsonable(value.tolist())
    if isinstance(value, np.bool_):
        return bool(value)
    if isinstance(value, np.integer):
        return int(value)
    if isinstance(value, np.floating):
        f = float(value)
        return None if math.isnan(f) else f
    if isinstance(value, float) and math.isnan(value):
        return None
    return value
