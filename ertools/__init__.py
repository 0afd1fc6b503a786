"""ertools: re-score ERL / RoCKIn benchmarks from their logs, with no ROS installed.

The public API (docs/api.md) is the names below, imported on first use so that
``import ertools`` stays light::

    import ertools
    result = ertools.score("fbm2h", "run.bag", goal="goal.yaml")
    result.to_frames()["segments"]

Everything else is private by convention and may change in any release
(docs/ARCHITECTURE.md, "The public API").
"""

from __future__ import annotations

from importlib import import_module
from typing import TYPE_CHECKING, Any

from ertools._callable import submodules
from ertools._version import __version__

# `ertools.audit`, `.timeline`, `.export` and `.rescore` are also packages: a package imported
# sets its name on this module, so those four packages are themselves callable (their
# __init__ makes them so) and each call runs the function of ertools.api.
__all__ = [
    "__version__",
    "audit",
    "export",
    "figures",
    "info",
    "open_bag",
    "read_poses",
    "rescore",
    "score",
    "timeline",
]
API = tuple(__all__[1:])

if TYPE_CHECKING:
    from ertools.api import (
        audit,
        export,
        figures,
        info,
        open_bag,
        read_poses,
        rescore,
        score,
        timeline,
    )


def __getattr__(name: str) -> Any:
    if name in API:
        return getattr(import_module("ertools.api"), name)
    # a private module reached as an attribute (`ertools.yamlout.dump`), imported on first use
    return _submodule(name)


_submodule = submodules(__name__)


def __dir__() -> list[str]:
    return sorted({*globals(), *API})
