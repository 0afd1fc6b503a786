"""Recomputing an audited benchmark's score with ertools' scorers, and the library function
behind ``ertools audit`` (:func:`audit_bag`: read the state topics, audit them, re-score, compare).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, fields
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ertools.audit.analyse import DEFAULT_MAX_SILENCE_NS, audit_states
from ertools.audit.compare import LIVE_TRANSFORM_KEY, attach, live_transform
from ertools.audit.model import Audit
from ertools.configs.transform import MarkerTransform

if TYPE_CHECKING:
    from ertools.benchmarks.base import BenchmarkResult


# --------------------------------------------------------------------------------------------
# Recomputing


@dataclass(frozen=True)
class ScoreInputs:
    """The scoring inputs an audit passes through to the benchmark's scorer.

    Each scorer uses the ones it knows (``goal``/``transform``/``team``/``transforms``/``hits``
    for fbm2h, ``items``/``results`` for fbm1, ``config``/``d_min`` for fbm3w, ``topic`` for
    all); :func:`rescore` says which ones it ignored.
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

    def given(self) -> set[str]:
        return {f.name for f in fields(self) if getattr(self, f.name) is not None}


# What each benchmark's scorer uses of ScoreInputs.
USES: dict[str, frozenset[str]] = {
    "fbm2h": frozenset({"goal", "transform", "team", "transforms", "topic", "hits"}),
    "fbm1h": frozenset({"items", "results"}),
    "fbm1w": frozenset({"items", "results"}),
    "fbm3w": frozenset({"config", "d_min", "topic"}),
}


def _marker_transform(
    benchmark: str, inputs: ScoreInputs, live: Any
) -> tuple[MarkerTransform | None, tuple[str, ...]]:
    """FBM2H without ``--transform``/``--transforms``: the transform the live score recorded,
    and a note saying so; otherwise None (the inputs decide, identity when they say nothing).
    ``--team`` alone names the team and picks no transform."""
    if benchmark != "fbm2h" or inputs.given() & {"transform", "transforms"}:
        return None, ()
    found = live_transform(live)
    if found is None:
        return None, ()
    t = ", ".join(f"{v:g}" for v in found.translation)
    q = ", ".join(f"{v:.6g}" for v in found.quat_xyzw)
    return found, (
        f"transform taken from the live score (details.{LIVE_TRANSFORM_KEY}: [[{t}], [{q}]]); "
        "give --transform or --team/--transforms to use another",
    )


def rescore(
    benchmark: str, paths: Sequence[Path], inputs: ScoreInputs, live: Any = None
) -> tuple[BenchmarkResult, tuple[str, ...]]:
    """Recompute ``benchmark``'s score from ``paths`` with the scorer of ``ertools.benchmarks``.

    ``live`` (the parsed live score) gives FBM2H the transform its node used when the inputs
    name none (:func:`live_transform`).

    Returns:
        The result, and notes about inputs the scorer does not use.

    Raises:
        ScoringError: no scorer for that benchmark (yet).
        ErtoolsError: whatever the scorer raises for bad input.
    """
    from ertools.errors import ConfigError, ScoringError

    if benchmark not in USES:
        raise ScoringError(f"no scorer to recompute {benchmark!r} from an audit")
    ignored = sorted(inputs.given() - USES[benchmark])
    notes = tuple(f"--{name.replace('_', '-')} is not used by {benchmark}" for name in ignored)
    plist = [Path(p) for p in paths]
    result: BenchmarkResult
    if benchmark == "fbm2h":
        from ertools.benchmarks.fbm2h.benchmark import Fbm2hOptions, score_fbm2h

        marker, said = _marker_transform(benchmark, inputs, live)
        notes += said
        result = score_fbm2h(
            plist,
            Fbm2hOptions(
                goal=inputs.goal,
                transform=inputs.transform,
                team=inputs.team,
                transforms_dir=inputs.transforms,
                topic=inputs.topic,
                hits=inputs.hits,
                namespace=benchmark,
                marker_transform=marker,
            ),
        )
    elif benchmark in ("fbm1h", "fbm1w"):
        from ertools.benchmarks.fbm1.benchmark import Fbm1Options, score_fbm1_bag

        if inputs.items is None:
            raise ConfigError(f"recomputing {benchmark} needs the item list: give --items FILE")
        result = score_fbm1_bag(
            plist,
            inputs.items,
            options=Fbm1Options(benchmark=benchmark),
            results_path=inputs.results,
        )
    else:
        result = _rescore_fbm3w(plist, inputs)
    return result, notes


def rescore_2015(
    benchmark: str, paths: Sequence[Path], inputs: ScoreInputs, live: Any = None
) -> BenchmarkResult | None:
    """The score recomputed with every 2015 quirk the scorer can reproduce (fbm2h: unwrapped
    orientation and unscored segments over N; fbm1: ``Fbm1Options.as_2015``; fbm3w:
    ``--2015``: the hard-coded d_min of 0.33 mm, no arc-length parametrisation, timed-out runs
    scored, stopped runs' time left out), or None when there is nothing to recompute."""
    plist = [Path(p) for p in paths]
    if benchmark == "fbm3w":
        from ertools.benchmarks.fbm3w.benchmark import Fbm3wOptions, options_2015, score_fbm3w
        from ertools.configs.fbm3w import load_fbm3w_config

        options = options_2015(Fbm3wOptions(topic=inputs.topic))
        return score_fbm3w(plist, load_fbm3w_config(inputs.config), options)
    if benchmark == "fbm2h":
        from ertools.benchmarks.fbm2h.benchmark import Fbm2hOptions, score_fbm2h

        return score_fbm2h(
            plist,
            Fbm2hOptions(
                goal=inputs.goal,
                transform=inputs.transform,
                team=inputs.team,
                transforms_dir=inputs.transforms,
                topic=inputs.topic,
                hits=inputs.hits,
                namespace=benchmark,
                orientation_2015=True,
                unscored_2015=True,
                marker_transform=_marker_transform(benchmark, inputs, live)[0],
            ),
        )
    if benchmark in ("fbm1h", "fbm1w") and inputs.items is not None:
        from ertools.benchmarks.fbm1.benchmark import Fbm1Options, score_fbm1_bag

        return score_fbm1_bag(
            plist,
            inputs.items,
            options=Fbm1Options.as_2015(benchmark),
            results_path=inputs.results,
        )
    return None


def _rescore_fbm3w(paths: list[Path], inputs: ScoreInputs) -> BenchmarkResult:
    from ertools.benchmarks.fbm3w.benchmark import Fbm3wOptions, score_fbm3w
    from ertools.configs.fbm3w import load_fbm3w_config

    config = load_fbm3w_config(inputs.config)
    options = Fbm3wOptions(d_min=inputs.d_min, topic=inputs.topic)
    return score_fbm3w(paths, config, options)


# --------------------------------------------------------------------------------------------
# The library function behind `ertools audit`


def infer_benchmark(paths: Sequence[Path]) -> str:
    """The namespace of the state topics in ``paths`` (``/fbm2h/bmbox_state`` -> ``fbm2h``).

    Raises:
        BagError: no state topic at all.
        UsageError: state topics of several benchmarks.
    """
    from ertools.errors import BagError, UsageError
    from ertools.io import topics
    from ertools.states import STATE_TOPIC_SUFFIXES

    suffixes = {s for group in STATE_TOPIC_SUFFIXES.values() for s in group}
    found = sorted(
        {
            t.strip("/").split("/")[0]
            for t in topics(list(paths))
            if t.count("/") == 2 and t.rsplit("/", 1)[1] in suffixes
        }
    )
    if not found:
        raise BagError(
            "no benchmark state topics (/<benchmark>/bmbox_state, refbox_state, client_state): "
            "nothing to audit; score such logs with `ertools score NAME ... --reached timing`",
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
    from ertools.errors import BagError, ErtoolsError
    from ertools.io import read_benchmark_states

    plist = [Path(p) for p in paths]
    for path in plist:
        if not path.exists():
            raise BagError("no such file or directory", path=path)
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
        if given.given() & USES.get(ns, frozenset()):
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
