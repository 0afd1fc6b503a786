"""Results as plain data and text: :func:`jsonable` (JSON types) and :func:`dump_yaml` (YAML
through the safe dumper, floats rounded to 9 decimal places).

Every quantity ertools writes is in seconds, metres, radians, degrees or a ratio, so 9
decimals keep the nanosecond, the nanometre and the nanoradian, far finer than anything
measured (mocap noise is ~0.1 mm; errors matter to 0.1 um), and drop the binary noise of float
arithmetic (41.199999999999996 is written 41.2, 0.7320016638025953 as 0.732001664). Epoch
seconds are unchanged: a float64 near 1.4e9 s holds 0.24 us, coarser than 1e-9. A value moves
by at most 5e-10; JSON keeps the full float64 for scripts that compare results more finely.
"""

from __future__ import annotations

import functools
import json
import math
from collections.abc import Callable, Mapping
from typing import TYPE_CHECKING, Any, cast

import numpy as np

if TYPE_CHECKING:
    import yaml

YAML_DECIMALS = 9


def yaml_float(value: float) -> float:
    """``value`` as YAML writes it: rounded to :data:`YAML_DECIMALS` places (NaN/inf kept)."""
    return round(value, YAML_DECIMALS) if math.isfinite(value) else value


def _represent_float(dumper: yaml.SafeDumper, value: float) -> yaml.Node:
    return dumper.represent_float(yaml_float(float(value)))


@functools.cache
def _dumper() -> type[yaml.SafeDumper]:
    """The safe dumper, taking ``str`` subclasses (``fidelity.Deviation``) as plain text and
    writing floats (NumPy's too) rounded by :func:`yaml_float`."""
    import yaml  # lazy: PyYAML, 10-20 ms, only for YAML output (JSON output needs none)

    class Dumper(yaml.SafeDumper):
        pass

    Dumper.add_multi_representer(str, yaml.SafeDumper.represent_str)
    Dumper.add_representer(float, _represent_float)  # the exact type's entry wins over multi
    Dumper.add_multi_representer(float, _represent_float)
    return Dumper


Representer = Callable[[Any, Any], Any]


def dump_yaml(
    data: Any, *, representers: Mapping[type, Representer] | None = None, **options: Any
) -> str:
    """YAML as the 2015 nodes dumped it (block style, keys in insertion order unless
    ``options`` say otherwise) through the safe dumper, floats rounded to 9 decimals;
    ``representers`` by type added to it for this text only (``yaml.add_representer``'s)."""
    import yaml  # lazy: PyYAML, 10-20 ms, only for YAML output (JSON output needs none)

    dumper = _dumper()
    if representers:
        # a subclass copies the tables on its first add: the shared dumper stays as it is
        dumper = cast("type[yaml.SafeDumper]", type("Dumper", (dumper,), {}))
        for kind, represent in representers.items():
            dumper.add_representer(kind, represent)
    kwargs: dict[str, Any] = {
        "default_flow_style": False,
        "sort_keys": False,
        "allow_unicode": True,
        "Dumper": dumper,
        **options,
    }
    text: str = yaml.dump(data, **kwargs)
    return text


def json_text(data: Any) -> str:
    """``data`` as indented JSON (NumPy values as plain numbers, NaN as null)."""
    return json.dumps(jsonable(data), indent=2, allow_nan=False)


def jsonable(value: Any, *, string_keys: bool = True) -> Any:
    """``value`` as plain JSON types: NumPy scalars and arrays as numbers and lists, tuples as
    lists, mapping keys as text (integer keys kept when not ``string_keys``: the 2015 YAML's
    ``0:``), NaN as None."""

    if isinstance(value, dict):
        return {
            k if not string_keys and isinstance(k, int) else str(k): jsonable(
                v, string_keys=string_keys
            )
            for k, v in value.items()
        }
    if isinstance(value, list | tuple):
        return [jsonable(v, string_keys=string_keys) for v in value]
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
