"""How ertools writes YAML: the safe dumper, with floats rounded to 9 decimal places.

Every quantity ertools writes is in seconds, metres, radians, degrees or a ratio, so 9
decimals keep the nanosecond, the nanometre and the nanoradian, far finer than anything
measured (mocap noise is ~0.1 mm; errors matter to 0.1 um), and drop the binary noise of float
arithmetic (41.199999999999996 is written 41.2, 0.7320016638025953 as 0.732001664). Epoch
seconds are unchanged: a float64 near 1.4e9 s holds 0.24 us, coarser than 1e-9. A value moves
by at most 5e-10; JSON keeps the full float64 for scripts that compare results more finely.
"""

from __future__ import annotations

import math
from typing import Any

import yaml

YAML_DECIMALS = 9


def yaml_float(value: float) -> float:
    """``value`` as YAML writes it: rounded to :data:`YAML_DECIMALS` places (NaN/inf kept)."""
    return round(value, YAML_DECIMALS) if math.isfinite(value) else value


def _represent_float(dumper: yaml.SafeDumper, value: float) -> yaml.Node:
    return dumper.represent_float(yaml_float(float(value)))


class Dumper(yaml.SafeDumper):
    """The safe dumper, taking ``str`` subclasses (``fidelity.Deviation``) as plain text and
    writing floats (NumPy's too) rounded by :func:`yaml_float`. Subclass it to add
    representers (a subclass copies the tables, so this one stays as it is)."""


Dumper.add_multi_representer(str, yaml.SafeDumper.represent_str)
Dumper.add_representer(float, _represent_float)  # the exact type's entry wins over multi
Dumper.add_multi_representer(float, _represent_float)


def dump(data: Any, **options: Any) -> str:
    """YAML text of ``data`` (block style, keys in insertion order unless ``options`` say
    otherwise) through :class:`Dumper`."""
    kwargs: dict[str, Any] = {
        "default_flow_style": False,
        "sort_keys": False,
        "allow_unicode": True,
        **options,
    }
    kwargs.setdefault("Dumper", Dumper)
    text: str = yaml.dump(data, **kwargs)
    return text
