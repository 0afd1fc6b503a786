"""Shapes and the FBM3@Work config: built-ins, safe expressions, point lists, validation."""

from __future__ import annotations

import ast
import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from ertools.benchmarks.fbm3w.settings import DEFAULT_RUNS, load_fbm3w_config, parse_fbm3w_config
from ertools.benchmarks.fbm3w.shapes import builtin_shapes, compile_expression, parse_shape
from ertools.errors import ConfigError

L = np.linspace(0.0, 1.0, 11)


def test_builtins_are_listing_15() -> None:
    shapes = builtin_shapes()
    # hand values of seed Listing 15 at l = 0.5
    assert shapes["line"](0.5)[0] == pytest.approx([0.075, 0.0225], abs=1e-15)
    assert shapes["line_path"] is shapes["line"]
    assert shapes["spline"] is shapes["sine"] is shapes["spline_path"]
    assert shapes["sine"](0.5)[0] == pytest.approx(
        [0.075, 0.075 * math.sin(12.5 * math.pi * 0.15 * 0.5)], abs=1e-15
    )
    assert shapes["semi_ellipse"](0.5)[0] == pytest.approx([0.11, 0.11], abs=1e-15)
    for shape in shapes.values():
        assert np.allclose(shape(0.0), 0.0)


def test_expression_is_vectorised_and_matches_numpy() -> None:
    f = compile_expression("0.05 - 0.05*cos(pi*l) + 2**-3*l % 0.3 - -l/4 + atan2(l, 1)")
    expected = 0.05 - 0.05 * np.cos(np.pi * L) + (2**-3 * L) % 0.3 + L / 4 + np.arctan2(L, 1)
    assert f(L) == pytest.approx(expected, abs=1e-15)
    assert compile_expression("0.2")(L).shape == L.shape  # constants broadcast


@pytest.mark.parametrize(
    "expr",
    [
        "__import__('os')",
        "__import__('os').system('true')",
        "l.__class__",
        "os",
        "(lambda: 1)()",
        "[l for l in (1,)]",
        "l[0]",
        "sin(x=l)",
        "'abc'",
        "True",
        "l if l else 1",
        "l < 1",
        "open('f')",
        "sin(l, l)",
        "1 +",
        "l" + " + l" * 300,
    ],
)
def test_expression_outside_whitelist_is_rejected(expr: str) -> None:
    with pytest.raises(ConfigError) as err:
        compile_expression(expr, where="shapes.bad.x")
    assert "\n" not in str(err.value)
    assert "shapes.bad.x" in str(err.value)


def test_user_expression_shape() -> None:
    shape = parse_shape("semi", {"x": "0.05 - 0.05*cos(pi*l)", "y": "0.048*sin(pi*l)"})
    pts = shape(L)
    assert pts[:, 0] == pytest.approx(0.05 - 0.05 * np.cos(np.pi * L), abs=1e-15)
    assert pts[:, 1] == pytest.approx(0.048 * np.sin(np.pi * L), abs=1e-15)
    assert not shape.builtin


def test_point_list_shape_is_a_spline_by_arc_length() -> None:
    pts = [[0.0, 0.0], [0.05, 0.02], [0.10, 0.0], [0.15, -0.02]]
    shape = parse_shape("wave", {"points": pts})
    dense = shape.dense(20001)
    # passes through every given point (within the dense sampling step)
    for p in pts:
        assert np.min(np.hypot(*(dense - p).T)) < 2e-5
    # l is the fraction of arc length: equal steps in l give equal distances along the curve
    steps = np.hypot(*np.diff(shape(np.linspace(0, 1, 101)), axis=0).T)
    assert np.ptp(steps) / steps.mean() < 0.01
    # two points: the straight segment
    seg = parse_shape("seg", {"points": [[0, 0], [0.1, 0.05]]})
    assert seg(0.5)[0] == pytest.approx([0.05, 0.025], abs=1e-12)


@pytest.mark.parametrize(
    ("spec", "message"),
    [
        ({"x": "l + 0.01", "y": "0"}, "not at (0, 0)"),
        ({"x": "log(l - 2)", "y": "0"}, "not finite"),
        ({"x": "0", "y": "0"}, "zero length"),
        ({"points": [[0, 0], [0, 0], [1, 1]]}, "coincide"),
        ({"points": [[0, 0]]}, "2 to"),
        ({"points": "abc"}, "[x, y]"),
        ({"x": "l"}, "unknown keys"),
        ("l", "expected"),
    ],
)
def test_bad_shape_definitions(spec: object, message: str) -> None:
    with pytest.raises(ConfigError, match=message.replace("(", r"\(").replace(")", r"\)")):
        parse_shape("s", spec)


def test_shipped_config_equals_builtin_defaults() -> None:
    shipped = Path(__file__).resolve().parents[3] / "configs" / "fbm3w.yaml"
    cfg = load_fbm3w_config(shipped)
    default = load_fbm3w_config(None)
    assert cfg.runs_specifications == default.runs_specifications == DEFAULT_RUNS
    assert cfg.d_min == default.d_min == 0.00033


def test_bad_shape_fails_only_its_runs() -> None:
    cfg = parse_fbm3w_config(
        {
            "runs_specifications": ["line", "evil", "good"],
            "shapes": {"evil": {"x": "__import__('os')", "y": "0"}, "good": {"x": "l", "y": "0"}},
        }
    )
    assert cfg.shape("line").name == "line_path"
    assert cfg.shape("good")(1.0)[0] == pytest.approx([1.0, 0.0])
    with pytest.raises(ConfigError, match="not allowed"):
        cfg.shape("evil")
    with pytest.raises(ConfigError, match="unknown shape 'nope'"):
        cfg.shape("nope")


@pytest.mark.parametrize(
    ("data", "message"),
    [
        ([], "mapping"),
        ({"runs": ["line"]}, "unknown key"),
        ({"d_min": 0.001}, "missing key 'runs_specifications'"),
        ({"runs_specifications": []}, "non-empty list"),
        ({"runs_specifications": ["line", 3]}, "non-empty list"),
        ({"runs_specifications": ["line"], "d_min": -1}, ">= 0"),
        ({"runs_specifications": ["line"], "d_min": "big"}, "number"),
        ({"runs_specifications": ["line"], "d_min": 0.33}, "larger than 5 cm"),
        ({"runs_specifications": ["line"], "shapes": ["x"]}, "mapping"),
    ],
)
def test_bad_configs(data: object, message: str) -> None:
    with pytest.raises(ConfigError, match=message):
        parse_fbm3w_config(data, "cfg.yaml")


# --- property: the compiled closures evaluate like NumPy on the same text --------------------

_FUNCS1 = ("sin", "cos", "tan", "exp", "sqrt", "abs", "log", "atan", "floor", "tanh")
_FUNCS2 = ("atan2", "hypot", "min", "max")
_NUMPY_NAMES = {
    "sin": np.sin, "cos": np.cos, "tan": np.tan, "exp": np.exp, "sqrt": np.sqrt,
    "abs": np.abs, "log": np.log, "atan": np.arctan, "floor": np.floor, "tanh": np.tanh,
    "atan2": np.arctan2, "hypot": np.hypot, "min": np.minimum, "max": np.maximum,
    # np.float64 constants, so that `pi / (pi - pi)` gives inf as NumPy does, not a
    # ZeroDivisionError from Python floats in the test's own reference.
    "pi": np.float64(np.pi), "e": np.float64(np.e), "tau": np.float64(2 * np.pi),
}  # fmt: skip


def _expressions() -> st.SearchStrategy[str]:
    leaves = st.one_of(
        st.sampled_from(["l", "pi", "e", "tau"]),
        st.floats(0.0, 10.0, allow_nan=False).map(lambda v: repr(round(v, 3))),
        st.integers(0, 5).map(str),
    )

    def extend(inner: st.SearchStrategy[str]) -> st.SearchStrategy[str]:
        return st.one_of(
            st.tuples(inner, st.sampled_from(["+", "-", "*", "/", "**", "%"]), inner).map(
                lambda t: f"({t[0]} {t[1]} {t[2]})"
            ),
            st.tuples(st.sampled_from(["-", "+"]), inner).map(lambda t: f"{t[0]}{t[1]}"),
            st.tuples(st.sampled_from(_FUNCS1), inner).map(lambda t: f"{t[0]}({t[1]})"),
            st.tuples(st.sampled_from(_FUNCS2), inner, inner).map(
                lambda t: f"{t[0]}({t[1]}, {t[2]})"
            ),
        )

    return st.recursive(leaves, extend, max_leaves=8)


class _FloatConstants(ast.NodeTransformer):
    """Numbers -> np.float64(number): NumPy semantics (inf/nan, no ZeroDivisionError)."""

    def visit_Constant(self, node: ast.Constant) -> ast.AST:
        call = ast.Call(ast.Name("F", ast.Load()), [node], [])
        return ast.copy_location(call, node)


@pytest.mark.slow
@pytest.mark.filterwarnings("ignore::hypothesis.errors.HypothesisWarning")
@settings(max_examples=150, deadline=None)
@given(text=_expressions())
def test_compiled_expression_equals_numpy_evaluation(text: str) -> None:
    ll = np.linspace(0.0, 1.0, 7)
    # the test's own reference: Python evaluates its *generated* text on NumPy objects
    tree = ast.fix_missing_locations(_FloatConstants().visit(ast.parse(text, mode="eval")))
    code = compile(tree, "<generated>", "eval")
    with np.errstate(all="ignore"):
        expected = eval(code, {"__builtins__": {}}, {**_NUMPY_NAMES, "l": ll, "F": np.float64})
    expected = np.broadcast_to(np.asarray(expected, dtype=float), ll.shape)
    got = compile_expression(text)(ll)
    np.testing.assert_allclose(got, expected.astype(float), rtol=1e-12, atol=0, equal_nan=True)
