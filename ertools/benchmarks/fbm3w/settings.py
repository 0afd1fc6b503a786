"""The FBM3@Work config (seed Listing 14) with the optional ``d_min`` and ``shapes`` keys.

::

    runs_specifications: [line, spline, line, spline, line]   # Listing 14
    d_min: 0.00033          # metres; the 2015 script's D_MIN (optional)
    shapes:                 # optional, adds to / overrides the built-in shapes
      semi: {x: "0.05 - 0.05*cos(pi*l)", y: "0.048*sin(pi*l)"}
      hook: {points: [[0, 0], [0.05, 0.01], [0.10, 0.04]]}

A shape that cannot be used (bad expression, not starting at the origin...) does not stop the
whole benchmark: the runs that name it fail with the shape's error, the other runs are scored.
"""

from __future__ import annotations

import math
from dataclasses import field
from pathlib import Path
from typing import Any

from ertools.benchmarks.fbm3w.shapes import Shape, builtin_shapes, parse_shape
from ertools.configs._yaml import load_yaml, show
from ertools.errors import ConfigError
from ertools.frozen_dataclass import frozen_dataclass

# The 2015 script's threshold (rockin_scoring/scripts/fbm3w, Lisbon 2015: "reasonable with a
# smoothing value of 15").
DEFAULT_D_MIN = 0.00033
# Listing 14.
DEFAULT_RUNS: tuple[str, ...] = ("line", "spline", "line", "spline", "line")


@frozen_dataclass
class Fbm3wConfig:
    """A validated FBM3@Work config.

    Attributes:
        runs_specifications: the shape name of each run, in order.
        d_min: subsampling threshold in metres.
        shapes: usable shapes by name (built-ins plus valid user shapes).
        shape_errors: user shapes that could not be built: name -> one-line error.
        source: the file it came from ("the built-in 2015 config" for the defaults).
    """

    runs_specifications: tuple[str, ...] = DEFAULT_RUNS
    d_min: float = DEFAULT_D_MIN
    shapes: dict[str, Shape] = field(default_factory=builtin_shapes)
    shape_errors: dict[str, str] = field(default_factory=dict)
    source: str = "the built-in 2015 config"

    def shape(self, name: str) -> Shape:
        """The shape named ``name``.

        Raises:
            ConfigError: the name is unknown or its definition was rejected.
        """
        if name in self.shape_errors:
            raise ConfigError(self.shape_errors[name])
        if name not in self.shapes:
            raise ConfigError(
                f"unknown shape {name!r} in {self.source}; known shapes: "
                f"{', '.join(sorted(self.shapes))} (define it under `shapes:`)"
            )
        return self.shapes[name]

    def with_d_min(self, d_min: float) -> Fbm3wConfig:
        """A copy with another ``d_min`` (validated)."""
        return Fbm3wConfig(
            self.runs_specifications,
            check_d_min(d_min, "--d-min"),
            self.shapes,
            self.shape_errors,
            self.source,
        )


def check_d_min(value: Any, where: str) -> float:
    """``value`` as a finite, non-negative float, or a ConfigError naming ``where``."""
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise ConfigError(f"{where}: d_min must be a number of metres, got {show(value)}")
    if isinstance(value, int) and abs(value) > 1:  # a 400-digit integer overflows float()
        raise ConfigError(f"{where}: d_min {show(value)} m is larger than 5 cm")
    d_min = float(value)
    if not math.isfinite(d_min) or d_min < 0.0:
        raise ConfigError(f"{where}: d_min must be finite and >= 0 metres, got {value!r}")
    if d_min > 0.05:
        raise ConfigError(
            f"{where}: d_min {d_min} m is larger than 5 cm; d_min is in metres (2015: 0.00033)"
        )
    return d_min


def parse_fbm3w_config(data: Any, source: str = "<config>") -> Fbm3wConfig:
    """Validate the parsed YAML of an FBM3@Work config."""
    if not isinstance(data, dict):
        raise ConfigError(
            "expected a mapping with `runs_specifications` (seed Listing 14)", path=source
        )
    unknown = set(data) - {"runs_specifications", "d_min", "shapes"}
    if unknown:
        raise ConfigError(
            f"unknown key(s) {', '.join(sorted(map(str, unknown)))}; "
            "expected runs_specifications, d_min, shapes",
            path=source,
        )
    if "runs_specifications" not in data:
        raise ConfigError("missing key 'runs_specifications' (seed Listing 14)", path=source)
    runs = data["runs_specifications"]
    if (
        not isinstance(runs, list)
        or not runs
        or not all(isinstance(r, str) and r.strip() for r in runs)
    ):
        raise ConfigError(
            "runs_specifications must be a non-empty list of shape names (e.g. 'line')",
            path=source,
        )
    d_min = check_d_min(data.get("d_min", DEFAULT_D_MIN), f"{source}: d_min")
    shapes = builtin_shapes()
    errors: dict[str, str] = {}
    user = data.get("shapes") or {}
    if not isinstance(user, dict):
        raise ConfigError("shapes must be a mapping name -> definition", path=source)
    for name, spec in user.items():
        try:
            shapes[str(name)] = parse_shape(str(name), spec, source=source)
        except ConfigError as err:
            shapes.pop(str(name), None)  # a broken override must not fall back silently
            errors[str(name)] = str(err)
    return Fbm3wConfig(tuple(r.strip() for r in runs), d_min, shapes, errors, source)


def load_fbm3w_config(path: str | Path | None) -> Fbm3wConfig:
    """The config at ``path``, or the built-in 2015 defaults when ``path`` is None."""
    if path is None:
        return Fbm3wConfig()
    return parse_fbm3w_config(load_yaml(path, "FBM3@Work config"), str(path))
