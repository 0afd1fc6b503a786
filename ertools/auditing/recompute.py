"""Recomputing an audited benchmark's score with ertools' scorers, and the library function
behind ``ertools audit`` (:func:`audit_bag`: read the state topics, audit them, re-score, compare).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import fields
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ertools.auditing.analyse import DEFAULT_MAX_SILENCE_NS, audit_states
from ertools.auditing.compare import attach
from ertools.auditing.model import Audit
from ertools.benchmarks import registry
from ertools.benchmarks.base import AnyBenchmark, Audited
from ertools.benchmarks.common.which import log_benchmark
from ertools.benchmarks.scoring import score_execution
from ertools.errors import BagError, ErtoolsError, ScoringError, UsageError
from ertools.frozen_dataclass import frozen_dataclass
from ertools.io.reader import read_benchmark_states, topics
from ertools.states import STATE_TOPIC_SUFFIXES

if TYPE_CHECKING:
    from ertools.benchmarks.base import BenchmarkResult


# --------------------------------------------------------------------------------------------
# Recomputing


@frozen_dataclass
class ScoreInputs:
    """The scoring inputs an audit passes through to the benchmark's scorer.

    Each is the :class:`~ertools.benchmarks.base.Input` of the same name of the benchmark
    audited, used when it declares one (``goal``, ``transform``, ``items``, ``config``,
    ``d_min``, ``topic``...); :func:`rescore` says which ones it ignored. ``other`` holds
    values for inputs outside this list (by input name).
    """

    goal: Path | None = None
    transform: Path | None = None
    team: str | None = None
    transforms: Path | None = None
    config: Path | None = None
    items: Path | None = None
    results: Path | None = None
    topic: str | None = None
    d_min: float | None = None
    hits: int | None = None
    other: tuple[tuple[str, Any], ...] = ()

    def values(self) -> dict[str, Any]:
        """The inputs given, by name."""
        out = {
            f.name: getattr(self, f.name)
            for f in fields(self)
            if f.name != "other" and getattr(self, f.name) is not None
        }
        out.update(self.other)
        return out

    def given(self) -> set[str]:
        return set(self.values())


def uses(benchmark: str) -> frozenset[str]:
    """The inputs ``benchmark``'s scorer declares (none for an unknown name)."""
    if benchmark not in registry.names():
        return frozenset()
    return frozenset(i.name for i in registry.get(benchmark).inputs)


def _scorer(benchmark: str) -> AnyBenchmark:
    """The registered benchmark an audit can recompute (its states are logged: Audited)."""

    bench = registry.get(benchmark) if benchmark in registry.names() else None
    if not isinstance(bench, Audited):
        raise ScoringError(f"no scorer to recompute {benchmark!r} from an audit")
    return bench


def rescore(
    benchmark: str, paths: Sequence[Path], inputs: ScoreInputs, live: Any = None
) -> tuple[BenchmarkResult, tuple[str, ...]]:
    """Recompute ``benchmark``'s score from ``paths`` with its registered scorer.

    ``live`` (the parsed live score) may complete the options (FBM2H: the transform its node
    used when the inputs name none).

    Returns:
        The result, and notes about inputs the scorer does not use.

    Raises:
        ScoringError: no scorer for that benchmark.
        ErtoolsError: whatever the scorer raises for bad input.
    """
    bench = _scorer(benchmark)
    declared = uses(benchmark)
    given = inputs.values()
    ignored = sorted(set(given) - declared)
    notes = tuple(f"--{name.replace('_', '-')} is not used by {benchmark}" for name in ignored)
    values = {k: v for k, v in given.items() if k in declared}
    plist = [Path(p) for p in paths]
    scored = score_execution(bench, plist, values, live=live, check_logs=False)
    return scored.result, notes + scored.said


def rescore_2015(
    benchmark: str, paths: Sequence[Path], inputs: ScoreInputs, live: Any = None
) -> BenchmarkResult | None:
    """The score recomputed with every 2015 behaviour the scorer can restore (the benchmark's
    ``values_2015`` (:class:`~ertools.benchmarks.base.Audited`): FBM2H unwrapped orientation and
    unscored segments over N; FBM1 the 2015 node's rules; FBM3W ``--2015``), or None when it
    declares none."""
    bench = _scorer(benchmark)
    if not isinstance(bench, Audited) or not bench.values_2015:  # (Audited: _scorer's)
        return None
    declared = uses(benchmark)
    values = {k: v for k, v in inputs.values().items() if k in declared}
    plist = [Path(p) for p in paths]
    values = {**values, **bench.values_2015}
    return score_execution(bench, plist, values, live=live, check_logs=False).result


# --------------------------------------------------------------------------------------------
# The library function behind `ertools audit`


def infer_benchmark(paths: Sequence[Path]) -> str:
    """The namespace of the state topics in ``paths`` (``/fbm2h/bmbox_state`` -> ``fbm2h``).

    Raises:
        BagError: no state topic at all.
        UsageError: state topics of several benchmarks.
    """

    suffixes = {s for group in STATE_TOPIC_SUFFIXES.values() for s in group}
    found = sorted(
        {
            t.strip("/").split("/")[0]
            for t in topics(list(paths))
            if t.count("/") == 2 and t.rsplit("/", 1)[1] in suffixes
        }
    )
    if not found:
        # a GT-only or robot log: the score command that takes it says which inputs it needs
        name = log_benchmark(Path(paths[0]))
        title = f"an {registry.get(name).title} log" if name else "a log"
        hint = f"ertools score {name}" if name else "ertools score NAME ... --reached timing"
        raise BagError(
            "no benchmark state topics (/<benchmark>/bmbox_state, refbox_state, client_state): "
            f"nothing to audit; {title} without them scores with `{hint}`",
            path=paths[0],
        )
    if len(found) > 1:
        raise UsageError(
            f"state topics of several benchmarks ({', '.join(found)}): give --benchmark"
        )
    return found[0]


def audit_bag(
    paths: Sequence[Path],
    *,
    benchmark: str | None = None,
    max_silence_ns: int | None = None,
    inputs: ScoreInputs | None = None,
    recompute: bool = True,
    check_2015: bool = True,
) -> tuple[Audit, tuple[str, ...]]:
    """Audit the benchmark logged in ``paths`` and, where a scorer exists, re-score it.

    Args:
        paths: the log file(s).
        benchmark: the namespace; inferred from the state topics when None.
        max_silence_ns: heartbeat gaps longer than this are findings (default 1 s).
        inputs: scoring inputs for the re-score.
        recompute: False = the timeline and checks only.
        check_2015: when the scores differ, recompute once more with the 2015 rules to tell
            ertools' deliberate deviations from differences in the data.

    Returns:
        The audit (with the comparison when re-scored) and notes for the user: inputs the
        scorer ignored, or why the score could not be recomputed.

    Raises:
        BagError: unreadable logs or no state topics.
        ErtoolsError: the scorer's error when the user gave a scoring input it uses (a bad
            ``--goal``/``--items``/``--config``/``--topic``/``--hits``...); without explicit
            inputs a score that cannot be recomputed is a note, not an error.
    """

    plist = [Path(p) for p in paths]
    for path in plist:
        if not path.exists():
            raise BagError("no such file or directory", path=path, transient=True)
    ns = benchmark or infer_benchmark(plist)
    states = read_benchmark_states(plist, ns)
    if states.bmbox is None and states.refbox is None and states.client is None:
        raise BagError(f"no /{ns} state topics: nothing to audit", path=plist[0])
    audit = audit_states(
        states.bmbox,
        states.refbox,
        states.client,
        benchmark=ns,
        max_silence_ns=DEFAULT_MAX_SILENCE_NS if max_silence_ns is None else max_silence_ns,
        inputs=tuple(str(p) for p in plist),
    )
    if not recompute:
        return audit, ()
    given = inputs or ScoreInputs()
    try:
        result, notes = rescore(ns, plist, given, audit.live_score)
    except ErtoolsError as err:
        if given.given() & uses(ns):
            # The user named a scoring input: when it (or what it points at) is bad, that is
            # their error to fix, not a score that merely cannot be recomputed from the log.
            raise
        # The timeline is worth having even when the score cannot be recomputed.
        return audit, (f"score not recomputed: {err}",)
    attached = attach(audit, result)
    if not check_2015 or attached.comparison is None or not attached.comparison.differences:
        return attached, notes
    try:
        as_2015 = rescore_2015(ns, plist, given, audit.live_score)
    except ErtoolsError as err:
        return attached, (*notes, f"not recomputed with the 2015 rules: {err}")
    if as_2015 is None:
        return attached, notes
    return attach(audit, result, as_2015), notes
