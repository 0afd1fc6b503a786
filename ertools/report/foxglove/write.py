"""What a score used, as an MCAP file that opens in Foxglove (``--foxglove FILE.mcap``).

Each result type has a small content function turning it into
Foxglove messages: paths as ``foxglove.PoseInFrame`` / ``foxglove.PosesInFrame``, targets,
pairs and errors as ``foxglove.SceneUpdate``, states and notes as ``foxglove.Log``, and the
numbers Foxglove plots on JSON topics. A benchmark gives its own
(:meth:`ertools.benchmarks.base.Reported.foxglove`); an audit's is
:mod:`ertools.report.foxglove.audit`, so no shared code switches over benchmark names.
docs/foxglove.md lists every topic.
"""

from __future__ import annotations

import json
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

from ertools._version import __version__
from ertools.auditing.model import Audit
from ertools.benchmarks import registry
from ertools.benchmarks.base import Reported
from ertools.errors import UsageError
from ertools.frozen_dataclass import frozen_dataclass
from ertools.report.foxglove.mcapout import refuse_inputs, write_mcap
from ertools.serialize import jsonable
from ertools.views.foxglove import Collected

# Pose and error streams longer than this keep every k-th message, k = ceil(n / limit): an
# hour of 100 Hz robot poses is 360 000 messages, more than a viewer needs.
STREAM_LIMIT = 50_000


@frozen_dataclass
class Written:
    """What was written: the file, and message counts by topic."""

    path: Path
    counts: dict[str, int]

    @property
    def messages(self) -> int:
        return sum(self.counts.values())


def content_function(result: Any) -> Callable[..., None] | None:
    """The content function of the result's benchmark (of the audit, for an audit), None when
    there is none."""
    if isinstance(result, Audit):
        from ertools.report.foxglove.audit import content  # lazy: the audit's messages, 10 ms

        return content
    name = str(getattr(result, "name", ""))
    bench = registry.get(name) if name in registry.names() else None
    return bench.foxglove if isinstance(bench, Reported) else None


def collect(result: Any, *, limit: int = STREAM_LIMIT) -> Any:
    """The result's Foxglove messages, not yet written (an
    :class:`ertools.views.foxglove.Collected`)."""

    fn = content_function(result)
    if fn is None:
        raise UsageError(f"--foxglove: no Foxglove export for {result.name} results")
    out = Collected()
    fn(out, result, limit=limit)
    out.metadata.update(
        {
            "benchmark": str(result.name),
            "ertools_version": __version__,
            "score": json.dumps(jsonable(result.to_dict()), allow_nan=False),
        }
    )
    return out


def write_foxglove(
    result: Any,
    path: str | Path,
    *,
    inputs: Sequence[str | Path] = (),
    limit: int = STREAM_LIMIT,
) -> Written:
    """Write the result's Foxglove MCAP file (parent folders created).

    Raises:
        UsageError: ``path`` is one of ``inputs`` or of the result's inputs, or the result
            has no Foxglove export.
        OSError: the file cannot be written.
    """

    out_path = Path(path)
    refuse_inputs(out_path, [*inputs, *result.provenance.inputs])
    out = collect(result, limit=limit)
    write_mcap(out, out_path)
    counts: dict[str, int] = {}
    for _, topic, _ in out.messages:
        counts[topic] = counts.get(topic, 0) + 1
    return Written(out_path, counts)
