"""The toy's options: its inputs, their defaults and every check of their values (NumPy-free:
``ertools score toy --help`` imports it)."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from ertools.benchmarks.base import Input, resolve_values
from ertools.errors import UsageError

DEFAULT_TOPIC = "/toy/marker"

INPUTS = (
    Input("scale", "float", "multiplies the count", default=1.0, positive=True),
    Input("topic", "str", "marker pose topic", default=DEFAULT_TOPIC, metavar="TOPIC"),
    Input(
        "count_nan",
        "flag",
        "count the poses without a position, as the original node did",
        group="2015 behaviour",
    ),
)


@dataclass(frozen=True)
class ToyOptions:
    """How to score: the count's factor, the pose topic, the original node's counting."""

    scale: float = 1.0
    topic: str = DEFAULT_TOPIC
    count_nan: bool = False


def make_options(values: Mapping[str, Any]) -> ToyOptions:
    """The values by input name -> :class:`ToyOptions`, every check here.

    Raises:
        UsageError: a value that does not fit its input, or a topic without its leading ``/``.
    """
    v = resolve_values(INPUTS, values)
    if not v["topic"].startswith("/"):
        raise UsageError(f"--topic {v['topic']}: a topic name starts with /")
    return ToyOptions(scale=v["scale"], topic=v["topic"], count_nan=v["count_nan"])
