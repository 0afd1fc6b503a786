"""The parameters of the public API (ertools/api.py): what each takes, checked in one place
before anything is read. A wrong type is a UsageError naming the parameter, not a TypeError
from deep inside (a ``bytes`` path, ``config=dict``) nor a quiet answer
(``timeline({'a': 1})``); a benchmark's keyword inputs are checked by their declared kind
(:class:`~ertools.benchmarks.base.Input`), as the command line's options are.
"""

from __future__ import annotations

import functools
import inspect
import math
import numbers
import os
from collections.abc import Callable, Sequence
from dataclasses import replace
from pathlib import Path
from typing import Any, TypeVar, cast

from ertools.auditing.model import Audit
from ertools.benchmarks import registry
from ertools.benchmarks.base import Input
from ertools.errors import UsageError
from ertools.exporting.formats import FORMATS
from ertools.timelines.model import Timeline
from ertools.timeutil import MAX_SECONDS

F = TypeVar("F", bound=Callable[..., Any])
PathLike = str | Path


def paths_list(paths: PathLike | Sequence[PathLike]) -> list[Path]:
    """One path or several as a list of Paths."""
    if isinstance(paths, str | os.PathLike):
        return [Path(paths)]
    return [Path(p) for p in paths]


# What each parameter of the public functions takes, checked in one place (:func:`checked`)
# before anything is read: a wrong type is a UsageError naming the parameter, not a TypeError
# from deep inside (a bytes path, ``config=dict``) nor a quiet answer (``timeline({'a': 1})``).


def _is_path(value: Any) -> bool:
    return (
        isinstance(value, str | os.PathLike)
        and isinstance(os.fspath(value), str)
        and (os.fspath(value) != "")
    )


def _is_paths(value: Any) -> bool:
    return _is_path(value) or (isinstance(value, list | tuple) and all(_is_path(v) for v in value))


def _is_text(value: Any) -> bool:
    return isinstance(value, str) and value != ""


def _is_tf(value: Any) -> bool:
    if isinstance(value, str):
        parent, sep, child = value.partition(":")
        return bool(sep and parent and child and ":" not in child)
    return isinstance(value, tuple | list) and len(value) == 2 and all(map(_is_text, value))


def _is_result(value: Any) -> bool:
    return isinstance(value, Timeline | Audit) or (
        isinstance(getattr(value, "name", None), str) and callable(getattr(value, "to_dict", None))
    )


def _is_jobs(value: Any) -> bool:
    return isinstance(value, int) and not isinstance(value, bool) and value >= 1


_BOOL = (lambda v: isinstance(v, bool), "True or False")
_PARAMETERS: dict[str, tuple[Callable[[Any], bool], str]] = {
    "path": (_is_path, "a file path (str or pathlib.Path)"),
    "paths": (_is_paths, "a path (str or pathlib.Path) or a list of paths"),
    "bags": (_is_paths, "a bag path (str or pathlib.Path) or a list of paths"),
    "topic": (_is_text, "a topic name (str)"),
    "tf": (_is_tf, "'PARENT:CHILD' or a (parent, child) pair of frame names"),
    "time_source": (lambda v: v in ("header", "record"), "'header' or 'record'"),
    "name": (
        lambda v: isinstance(v, str) and v in registry.names(),
        "the name of a benchmark ({benchmarks})",
    ),
    "benchmark": (_is_text, "a benchmark namespace (str)"),
    "recompute": _BOOL,
    "check_clocks": _BOOL,
    "reports": _BOOL,
    "use_cache": _BOOL,
    "result": (_is_result, "what ertools.score, ertools.audit or ertools.timeline returned"),
    "format": (lambda v: isinstance(v, str) and v in FORMATS, f"one of {', '.join(FORMATS)}"),
    "out": (_is_path, "a file or folder path (str or pathlib.Path)"),
    "config": (_is_path, "a file path (str or pathlib.Path)"),
    "jobs": (_is_jobs, "a whole number of worker processes, 1 or more"),
}


def _shown(value: Any) -> str:
    text = repr(value)
    text = text if len(text) <= 60 else text[:57] + "..."
    return f"{text} ({type(value).__name__})"


def checked(function: F) -> F:
    """``function`` with its arguments checked against :data:`_PARAMETERS` first (None is
    taken where it is the default); keyword inputs (``**inputs``) are the benchmark's, checked
    by kind in :func:`_value`."""
    signature = inspect.signature(function)
    name = function.__name__

    @functools.wraps(function)
    def checked(*args: Any, **kwargs: Any) -> Any:
        try:
            bound = signature.bind(*args, **kwargs)
        except TypeError as err:  # a missing or unknown argument
            raise UsageError(f"ertools.{name}: {err}") from None
        for key, value in bound.arguments.items():
            parameter = signature.parameters[key]
            if parameter.kind is parameter.VAR_KEYWORD or (
                value is None and parameter.default is None
            ):
                continue
            valid, expected = _PARAMETERS[key]
            if not valid(value):
                expected = expected.format(benchmarks=", ".join(registry.names()))
                raise UsageError(f"ertools.{name}: {key}={_shown(value)}: give {expected}")
        return function(*args, **kwargs)

    return cast(F, checked)


_KINDS: dict[str, tuple[Callable[[Any], bool], str]] = {
    "path": (_is_path, "a file path (str or pathlib.Path)"),
    "paths": (_is_paths, "a path (str or pathlib.Path) or a list of paths"),
    "float": (
        lambda v: isinstance(v, numbers.Real) and not isinstance(v, bool),
        "a number",
    ),
    "int": (
        lambda v: isinstance(v, numbers.Integral) and not isinstance(v, bool),
        "a whole number",
    ),
    "str": (lambda v: isinstance(v, str), "text (str)"),
    "choice": (lambda v: isinstance(v, str), "one of its choices (str)"),
    "flag": (lambda v: isinstance(v, bool), "True or False"),
}


def value_of(declared: Input, value: Any) -> Any:
    """A keyword argument as the command line would have given it (``str`` paths as Paths, a
    ``with_file`` choice as its words, a flag not set as None); a value of the wrong type is a
    UsageError naming the input."""
    if value is None:
        return None
    if declared.repeat and isinstance(value, list | tuple):
        return [value_of(replace(declared, repeat=False), v) for v in value]
    if declared.with_file:
        return _choice_with_file(declared, value)
    valid, expected = _KINDS[declared.kind]
    if not valid(value):
        raise UsageError(f"{declared.name}={_shown(value)}: give {expected}")
    if declared.kind == "flag":
        return True if value else None
    if declared.kind == "path":
        return Path(value)
    if declared.kind == "paths":
        return paths_list(value)
    if declared.kind == "choice" and value not in declared.choices:
        raise UsageError(
            f"{declared.name}={value!r}: choose from {', '.join(map(repr, declared.choices))}"
        )
    if declared.repeat:
        return [value]
    if declared.kind == "float" and not (math.isfinite(value) and abs(value) < MAX_SECONDS):
        raise UsageError(
            f"{declared.name}={value}: give a finite number smaller than {MAX_SECONDS:g} in size"
        )
    return value


def _choice_with_file(declared: Input, value: Any) -> list[str]:
    """``"states"`` or ``("timing", FILE)``: the words the command line would have had."""
    words = [value] if isinstance(value, str) else value
    if (
        not isinstance(words, list | tuple)
        or not words
        or not isinstance(words[0], str)
        or words[0] not in declared.choices
        or len(words) != (2 if words[0] in declared.with_file else 1)
        or not all(_is_path(w) for w in words[1:])
    ):
        shapes = " or ".join(
            f"({c!r}, FILE)" if c in declared.with_file else repr(c) for c in declared.choices
        )
        raise UsageError(f"{declared.name}={_shown(value)}: give {shapes}")
    return [str(w) for w in words]
