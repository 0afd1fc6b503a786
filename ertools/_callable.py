"""A package that is also a function of the public API (``ertools.audit(...)``).

``ertools.audit`` is both the package ``ertools/audit/`` and the API function
``ertools.api.audit``: Python sets a package imported on its parent module, so the package
itself is made callable and a call runs the API function (imported then, by name: the API
sits above every package).
"""

from __future__ import annotations

import sys
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
