"""FBM3@Work target paths: the built-in 2015 shapes and user shapes, evaluated on arrays.

A shape is a planar curve ``t(l) = (x(l), y(l))`` for ``l`` in [0, 1], in the run frame (origin
at the starting position, x axis along reference -> start). The scorer compares the measured
point at normalised path length ``l`` with ``t(l)``.

Built-ins (seed Listing 15, the Lisbon 2015 script): ``line_path``, ``semi_ellipse``, ``sine``
and ``spline_path`` (= ``sine``); the run specifications of Listing 14 name them ``line``
(= ``line_path``) and ``spline`` (= ``sine``).

User shapes come from YAML, either as parametric expressions of ``l``::

    semi: {x: "0.05 - 0.05*cos(pi*l)", y: "0.048*sin(pi*l)"}

or as points joined by a spline, parametrised by normalised arc length::

    hook: {points: [[0, 0], [0.05, 0.01], [0.10, 0.04]]}

Expressions are parsed with :mod:`ast` and compiled into NumPy closures from a whitelist of
numbers, ``l``, ``pi``, ``e``, ``tau``, arithmetic operators and math functions; anything else
(attributes, subscripts, names, keywords, lambdas...) is rejected. Python's ``eval`` is never
used, so a config file cannot run code.
"""

from __future__ import annotations

import ast
import math
from collections.abc import Callable, Mapping
from typing import Any

import numpy as np

from ertools.arrays import F64
from ertools.configs._yaml import MAX_NUMBER, show
from ertools.errors import ConfigError
from ertools.frozen_dataclass import frozen_dataclass

Curve = Callable[[F64], F64]

# Longest expression accepted: a target path is a short formula; this bounds parse time and
# closure depth for hostile input.
MAX_EXPRESSION_CHARS = 400
# Most points accepted for a point-list shape (a printed path needs tens, not millions).
MAX_POINTS = 10_000
# Dense samples used to reparametrise a point-list spline by arc length and to check shapes.
_DENSE = 4097
# A shape must start at the run frame's origin (the starting position) within this distance.
ORIGIN_TOLERANCE_M = 1e-6


@frozen_dataclass(eq=False)
class Shape:
    """A named target path.

    Attributes:
        name: the name used in ``runs_specifications``.
        curve: vectorised ``l (N,) -> (N, 2)`` positions in metres.
        definition: how it was defined, for reports (a formula or "N points").
        builtin: True for the 2015 shapes.
    """

    name: str
    curve: Curve
    definition: str
    builtin: bool = False

    def __call__(self, l_norm: F64 | float) -> F64:
        """Positions (N, 2) at normalised lengths ``l_norm`` (scalars give (1, 2))."""
        ll = np.atleast_1d(np.asarray(l_norm, dtype=np.float64))
        return self.curve(ll)

    def dense(self, n: int = 1001) -> F64:
        """(n, 2) positions at evenly spaced l in [0, 1] (for plots and lengths)."""
        return self.curve(np.linspace(0.0, 1.0, n))

    def length(self, n: int = _DENSE) -> float:
        """Arc length of the curve (polyline of ``n`` samples), metres."""
        pts = self.dense(n)
        return float(np.sum(np.hypot(*np.diff(pts, axis=0).T)))

    def arc_length_gap(self) -> float:
        """Largest distance between t(l) and the point at fraction l of the arc length, metres.

        0 for shapes parametrised by arc length (line, semi_ellipse); the 2015 formula compares
        the robot at fraction l of its length with t(l), so a shape with a large gap (``sine``)
        penalises even a robot exactly on it.
        """
        uu = np.linspace(0.0, 1.0, _DENSE)
        pts = self.curve(uu)
        by_arc = self.by_arc_length().curve(uu)
        return float(np.max(np.hypot(*(pts - by_arc).T)))

    def by_arc_length(self) -> Shape:
        """The same curve reparametrised so that l is the fraction of its arc length."""
        return Shape(
            self.name,
            _arc_length_curve(self.curve),
            f"{self.definition} (by arc length)",
            self.builtin,
        )


def _arc_length_curve(curve: Curve) -> Curve:
    """``curve`` reparametrised by normalised arc length (dense polyline, linear lookup)."""
    uu = np.linspace(0.0, 1.0, _DENSE)
    dense = curve(uu)
    s = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(dense, axis=0).T))])
    if s[-1] > 0:
        s /= s[-1]

    def reparametrised(ll: F64) -> F64:
        return curve(np.interp(np.clip(ll, 0.0, 1.0), s, uu))

    return reparametrised


# --- the 2015 built-ins (seed Listing 15) -------------------------------------------------


def _line_path(ll: F64) -> F64:
    # straight line from (0, 0) to (15, 4.5) cm
    return np.column_stack([0.15 * ll, 0.045 * ll])


def _semi_ellipse(ll: F64) -> F64:
    # half circle of radius 11 cm from (0, 0) through (11, 11) to (22, 0) cm
    return np.column_stack([0.11 - 0.11 * np.cos(np.pi * ll), 0.11 * np.sin(np.pi * ll)])


def _sine(ll: F64) -> F64:
    # 15 cm along x, 7.5 cm amplitude, 12.5*pi*0.15 rad of phase over the run
    return np.column_stack([0.15 * ll, 0.075 * np.sin(12.5 * np.pi * 0.15 * ll)])


_LINE = Shape("line_path", _line_path, "x = 0.15*l, y = 0.045*l", builtin=True)
_SEMI = Shape(
    "semi_ellipse", _semi_ellipse, "x = 0.11 - 0.11*cos(pi*l), y = 0.11*sin(pi*l)", builtin=True
)
_SINE = Shape("sine", _sine, "x = 0.15*l, y = 0.075*sin(12.5*pi*0.15*l)", builtin=True)


def builtin_shapes() -> dict[str, Shape]:
    """Name -> shape for the 2015 shapes and the names Listing 14 uses."""
    return {
        "line": _LINE,
        "spline": _SINE,
        "line_path": _LINE,
        "semi_ellipse": _SEMI,
        "sine": _SINE,
        "spline_path": _SINE,
    }


# --- safe expressions ---------------------------------------------------------------------

_CONSTANTS: dict[str, float] = {"pi": math.pi, "e": math.e, "tau": math.tau}

_FUNCTIONS: dict[str, tuple[Callable[..., Any], int]] = {
    "sin": (np.sin, 1),
    "cos": (np.cos, 1),
    "tan": (np.tan, 1),
    "asin": (np.arcsin, 1),
    "acos": (np.arccos, 1),
    "atan": (np.arctan, 1),
    "atan2": (np.arctan2, 2),
    "sinh": (np.sinh, 1),
    "cosh": (np.cosh, 1),
    "tanh": (np.tanh, 1),
    "exp": (np.exp, 1),
    "log": (np.log, 1),
    "log10": (np.log10, 1),
    "sqrt": (np.sqrt, 1),
    "abs": (np.abs, 1),
    "fabs": (np.abs, 1),
    "hypot": (np.hypot, 2),
    "floor": (np.floor, 1),
    "ceil": (np.ceil, 1),
    "min": (np.minimum, 2),
    "max": (np.maximum, 2),
}

_BINOPS: dict[type[ast.operator], Callable[[Any, Any], Any]] = {
    ast.Add: np.add,
    ast.Sub: np.subtract,
    ast.Mult: np.multiply,
    ast.Div: np.divide,
    ast.Pow: np.power,
    ast.Mod: np.mod,
}

_UNARY: dict[type[ast.unaryop], Callable[[Any], Any]] = {
    ast.UAdd: np.positive,
    ast.USub: np.negative,
}

Node = Callable[[F64], Any]


class _RejectedError(Exception):
    """An expression element outside the whitelist (turned into a ConfigError)."""


def _compile(node: ast.AST) -> Node:
    """A closure computing ``node`` on an array of l, or _RejectedError."""
    if isinstance(node, ast.Expression):
        return _compile(node.body)
    if isinstance(node, ast.Constant):
        value = node.value
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise _RejectedError(f"constant {value!r}")
        if abs(value) > MAX_NUMBER:  # a 400-digit literal would overflow float()
            raise _RejectedError(f"constant {show(value)}: too large")
        number = float(value)
        return lambda ll: number
    if isinstance(node, ast.Name):
        if node.id == "l":
            return lambda ll: ll
        if node.id in _CONSTANTS:
            constant = _CONSTANTS[node.id]
            return lambda ll: constant
        raise _RejectedError(f"name {node.id!r} (only l, pi, e, tau and functions)")
    if isinstance(node, ast.BinOp):
        op = _BINOPS.get(type(node.op))
        if op is None:
            raise _RejectedError(f"operator {type(node.op).__name__}")
        left, right = _compile(node.left), _compile(node.right)
        return lambda ll: op(left(ll), right(ll))
    if isinstance(node, ast.UnaryOp):
        uop = _UNARY.get(type(node.op))
        if uop is None:
            raise _RejectedError(f"operator {type(node.op).__name__}")
        operand = _compile(node.operand)
        return lambda ll: uop(operand(ll))
    if isinstance(node, ast.Call):
        if not isinstance(node.func, ast.Name) or node.func.id not in _FUNCTIONS:
            what = node.func.id if isinstance(node.func, ast.Name) else ast.dump(node.func)[:40]
            raise _RejectedError(f"function {what!r} (allowed: {', '.join(sorted(_FUNCTIONS))})")
        if node.keywords:
            raise _RejectedError("keyword arguments")
        func, arity = _FUNCTIONS[node.func.id]
        if len(node.args) != arity:
            raise _RejectedError(
                f"{node.func.id}() takes {arity} argument(s), got {len(node.args)}"
            )
        args = [_compile(a) for a in node.args]
        if arity == 1:
            (a0,) = args
            return lambda ll: func(a0(ll))
        a1, a2 = args
        return lambda ll: func(a1(ll), a2(ll))
    raise _RejectedError(type(node).__name__)


def compile_expression(text: str, *, where: str = "<expression>") -> Callable[[F64], F64]:
    """A vectorised function of ``l`` from a whitelisted arithmetic expression.

    Raises:
        ConfigError: the text is not a string, too long, not valid syntax, or uses anything
            outside the whitelist (e.g. ``__import__('os')``).
    """
    if isinstance(text, bool) or not isinstance(text, str | int | float):
        raise ConfigError(f"{where}: expected an expression string, got {type(text).__name__}")
    source = str(text).strip()
    if not source:
        raise ConfigError(f"{where}: empty expression")
    if len(source) > MAX_EXPRESSION_CHARS:
        raise ConfigError(f"{where}: expression longer than {MAX_EXPRESSION_CHARS} characters")
    try:
        tree = ast.parse(source, mode="eval")
    except SyntaxError as err:
        raise ConfigError(f"{where}: invalid expression {source!r}: {err.msg}") from None
    try:
        root = _compile(tree)
    except _RejectedError as err:
        raise ConfigError(
            f"{where}: {source!r} uses {err}, which is not allowed in a shape expression"
        ) from None
    except RecursionError:
        raise ConfigError(f"{where}: expression nested too deeply") from None

    def evaluate(ll: F64) -> F64:
        with np.errstate(all="ignore"):  # non-finite results are checked by the caller
            out = root(ll)
        return np.broadcast_to(np.asarray(out, dtype=np.float64), ll.shape).copy()

    return evaluate


def _expression_shape(name: str, spec: Mapping[str, Any], where: str) -> Shape:
    fx = compile_expression(spec["x"], where=f"{where}.x")
    fy = compile_expression(spec["y"], where=f"{where}.y")

    def curve(ll: F64) -> F64:
        return np.column_stack([fx(ll), fy(ll)])

    return Shape(name, curve, f"x = {spec['x']}, y = {spec['y']}")


def _points_shape(name: str, points: Any, where: str) -> Shape:
    from scipy.interpolate import CubicSpline  # lazy: scipy, 300 ms

    try:
        pts = np.asarray(points, dtype=np.float64)
    except (TypeError, ValueError):
        raise ConfigError(f"{where}.points: expected a list of [x, y] numbers") from None
    if pts.ndim != 2 or pts.shape[1] != 2 or not 2 <= len(pts) <= MAX_POINTS:
        raise ConfigError(f"{where}.points: expected 2 to {MAX_POINTS} [x, y] pairs")
    if not np.all(np.isfinite(pts)):
        raise ConfigError(f"{where}.points: non-finite coordinate")
    chord = np.hypot(*np.diff(pts, axis=0).T)
    if np.any(chord == 0.0):
        raise ConfigError(f"{where}.points: two consecutive points coincide")
    u = np.concatenate([[0.0], np.cumsum(chord)])
    u /= u[-1]
    if len(pts) == 2:

        def spline(uu: F64) -> F64:
            return np.asarray(pts[0] + np.outer(uu, pts[1] - pts[0]), dtype=np.float64)
    else:
        cubic = CubicSpline(u, pts, axis=0, bc_type="natural")

        def spline(uu: F64) -> F64:
            return np.asarray(cubic(uu), dtype=np.float64)

    # Parametrised by normalised arc length, so that l means "fraction of the target's length"
    # as it means "fraction of the robot's length" on the measured side.
    return Shape(name, _arc_length_curve(spline), f"spline through {len(pts)} points")


def parse_shape(name: str, spec: Any, *, source: str = "<config>") -> Shape:
    """A user shape from its YAML value (``{x: expr, y: expr}`` or ``{points: [...]}``).

    Raises:
        ConfigError: malformed, outside the whitelist, non-finite on [0, 1], or not starting
            at the origin.
    """
    where = f"{source}: shapes.{name}"
    if not isinstance(spec, Mapping):
        raise ConfigError(f"{where}: expected {{x: expr, y: expr}} or {{points: [[x, y], ...]}}")
    keys = set(spec)
    if keys == {"x", "y"}:
        shape = _expression_shape(name, spec, where)
    elif keys == {"points"}:
        shape = _points_shape(name, spec["points"], where)
    else:
        raise ConfigError(
            f"{where}: unknown keys {sorted(map(str, keys))}; "
            "expected {x: expr, y: expr} or {points: [[x, y], ...]}"
        )
    check = shape.dense(_DENSE)
    if check.shape != (_DENSE, 2) or not np.all(np.isfinite(check)):
        raise ConfigError(f"{where}: the curve is not finite everywhere on l in [0, 1]")
    if float(np.hypot(*check[0])) > ORIGIN_TOLERANCE_M:
        raise ConfigError(
            f"{where}: the curve starts at ({check[0, 0]:.6g}, {check[0, 1]:.6g}), not at (0, 0): "
            "the run frame's origin is the starting position"
        )
    if shape.length() == 0.0:
        raise ConfigError(f"{where}: the curve has zero length")
    return shape
