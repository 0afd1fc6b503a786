"""Every registered benchmark's result class is a :class:`~ertools.benchmarks.results.ResultBase`
subclass (issue 37): ``to_dict``, ``to_yaml`` and ``to_frames`` are written once, in the base,
and a result gives only its ``listing()`` and ``tables()``."""

from __future__ import annotations

import ast
import inspect
import sys
from importlib import import_module
from pathlib import Path

from ertools.benchmarks import registry
from ertools.benchmarks.fbm2h.result import Fbm2hResult
from ertools.benchmarks.referee.result import RefereeResult
from ertools.benchmarks.results import ResultBase

# Results not on the base: none, and none may be added.
ALLOWED: dict[str, str] = {}


def result_class(name: str) -> type:
    """The class ``score_runs`` of benchmark ``name`` is annotated to return, resolved from
    its declaring module (where it may be imported only for type checking)."""
    method = registry.get(name).score_runs
    wanted = inspect.signature(method).return_annotation
    if isinstance(wanted, type):
        return wanted
    module = sys.modules[method.__module__]
    found = getattr(module, wanted, None)
    if isinstance(found, type):
        return found
    tree = ast.parse(Path(str(module.__file__)).read_text(encoding="utf-8"))
    for node in ast.walk(tree):
        if (
            isinstance(node, ast.ImportFrom)
            and node.module
            and any((a.asname or a.name) == wanted for a in node.names)
        ):
            found = getattr(import_module(node.module), wanted)
            assert isinstance(found, type)
            return found
    raise AssertionError(f"{name}: cannot resolve the result class {wanted!r}")


def test_every_result_is_a_result_base() -> None:
    off = {
        f"{n}: {result_class(n).__qualname__}"
        for n in registry.names()
        if not issubclass(result_class(n), ResultBase)
    }
    allowed = {f"{n}: {cls}" for n, cls in ALLOWED.items()}
    assert off == allowed, (
        f"not on ResultBase: {sorted(off - allowed)}; fixed: {sorted(allowed - off)}"
    )


def test_the_resolver_finds_the_classes_it_must_judge() -> None:
    # the check above is only as good as the lookup: both declarations import their result
    # class for type checking only, so it is found through the import statement
    assert result_class("hwv") is RefereeResult
    assert result_class("fbm2h") is Fbm2hResult
    assert not issubclass(int, ResultBase)
