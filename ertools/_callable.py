"""Lazy parts of a package: a package that is also a function of the public API
(``ertools.audit(...)``), and submodules imported on first use (:func:`submodules`).

``ertools.audit`` is both the package ``ertools/auditing/`` and the API function
``ertools.api.audit``: Python sets a package imported on its parent module, so the package
itself is made callable and a call runs the API function (imported then, by name: the API
sits above every package).
"""

from __future__ import annotations

import sys
from collections.abc import Callable
from importlib import import_module
from types import ModuleType
from typing import Any


class CallablePackage(ModuleType):
    """A module whose call is ``ertools.api.<its last name>``."""

    def __call__(self, *args: Any, **kwargs: Any) -> Any:
        function = getattr(import_module("ertools.api"), self.__name__.rpartition(".")[2])
        return function(*args, **kwargs)


def make_callable(name: str) -> None:
    """Make the package ``name`` (its ``__name__``) callable; its doc says what the call does."""
    sys.modules[name].__class__ = CallablePackage


def submodules(package: str) -> Callable[[str], ModuleType]:
    """A package's module ``__getattr__`` that imports a submodule on first use: code that
    needs a heavy part only now and then (``ertools.report.folder`` for ``--report``) imports
    the light package at its top and reaches the part as an attribute when it runs."""

    def attribute(name: str) -> ModuleType:
        try:
            return import_module(f"{package}.{name}")
        except ModuleNotFoundError as err:
            if err.name != f"{package}.{name}":
                raise
            raise AttributeError(f"module {package!r} has no attribute {name!r}") from None

    return attribute
