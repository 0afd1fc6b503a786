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

from typing import TYPE_CHECKING, Any

from ertools._version import __version__

# The public names, once, in the order docs/api.md shows them.
__all__ = [  # noqa: RUF022 (the docs' order, not alphabetical)
    "__version__",
    "info",
    "open_bag",
    "read_poses",
    "score",
    "audit",
    "timeline",
    "figures",
    "export",
    "rescore",
]
API = tuple(__all__[1:])

if TYPE_CHECKING:  # the same names for type checkers (tests/api: equal to API)
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
    """A public function of ertools.api (PEP 562); any other name is an AttributeError."""
    if name not in API:
        raise AttributeError(f"module 'ertools' has no attribute {name!r}")
    from ertools import api  # lazy: NumPy, the readers, the report: 300-700 ms

    return getattr(api, name)


def __dir__() -> list[str]:
    return sorted({"API", *__all__, *(name for name in globals() if name.startswith("__"))})
