"""The score sent live against the score recomputed from the same bag, key by key, explained.

The 2015 BmBox sent its score as YAML in the TRANSMITTING_SCORE payload (seed Listings 13 and
16); ertools' results have the same nesting (``to_dict()``), so the two are flattened to dotted
keys (``runs_details.2.distance_error``) and compared leaf by leaf. Every difference gets an
explanation drawn from what is known to make the two differ: the parameters the result was
computed with (d_min, pose source, transform...), the places where ertools deliberately differs
from the 2015 node (``result.deviations``), and patterns recognised in the numbers themselves
(the orientation wrap, segments numbered from 1).

Pure: no file is read here. :func:`attach` puts a comparison into an
:class:`~ertools.audit.analyse.Audit`.
"""

from __future__ import annotations

import math
import re
from collections.abc import Sequence
from dataclasses import dataclass, fields, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ertools.benchmarks.base import Rows, jsonable
from ertools.configs.transform import MarkerTransform
from ertools.fidelity import Deviation

if TYPE_CHECKING:
    from ertools.audit.analyse import Audit
    from ertools.benchmarks.base import BenchmarkResult

# Two numbers within this are the same score: 1 um, 1 urad, 1 us, far below any effect the
# explanations describe and far above float round-off of a YAML round trip.
DEFAULT_ABS_TOL = 1e-6
DEFAULT_REL_TOL = 1e-9


@dataclass(frozen=True)
class ScoreLine:
    """One leaf of the score: the live value, the recomputed one, and why they differ."""

    key: str
    live: Any
    recomputed: Any
    difference: float | None  # recomputed - live, for numbers
    status: str  # "same", "differs", "only live", "only recomputed"
    explanation: str = ""


@dataclass(frozen=True)
class ScoreComparison:
    """Live vs recomputed score of one benchmark execution."""

    benchmark: str
    lines: tuple[ScoreLine, ...]
    abs_tol: float
    parameters: tuple[tuple[str, str], ...]
    deviations: tuple[Deviation, ...]
    notes: tuple[str, ...] = ()
    # Why the two scores cannot agree whatever the data (an identity transform), shown in the
    # comparison's title and beside every difference it causes; "" when they can.
    caveat: str = ""

    @property
    def differences(self) -> tuple[ScoreLine, ...]:
        """The lines whose values differ beyond the tolerance (numbers) or at all (text)."""
        return tuple(line for line in self.lines if line.status == "differs")

    @property
    def same(self) -> int:
        return sum(1 for line in self.lines if line.status == "same")

    def rows(self) -> Rows:
        return [
            {
                "key": line.key,
                "live": _cell(line.live),
                "recomputed": _cell(line.recomputed),
                "difference": line.difference,
                "status": line.status,
                "explanation": line.explanation,
            }
            for line in self.lines
        ]

    def to_dict(self) -> dict[str, Any]:
        return {
            "benchmark": self.benchmark,
            "caveat": self.caveat or None,
            "tolerance": self.abs_tol,
            "same": self.same,
            "differences": len(self.differences),
            "notes": list(self.notes),
            "parameters": dict(self.parameters),
            "deviations": list(self.deviations),
            "lines": jsonable(self.rows()),
        }


def _cell(value: Any) -> Any:
    if value is None or isinstance(value, bool | int | float | str):
        return value
    return str(value)


# --------------------------------------------------------------------------------------------
# Flattening


def flatten(data: Any, prefix: str = "") -> dict[str, Any]:
    """Nested mappings and lists as ``{"a.b.0.c": leaf}`` (keys as text)."""
    out: dict[str, Any] = {}
    if isinstance(data, dict):
        if not data and prefix:
            out[prefix] = {}
        for k, v in data.items():
            out.update(flatten(v, f"{prefix}.{k}" if prefix else str(k)))
    elif isinstance(data, list | tuple):
        if not data and prefix:
            out[prefix] = []
        for i, v in enumerate(data):
            out.update(flatten(v, f"{prefix}.{i}" if prefix else str(i)))
    else:
        out[prefix] = data
    return out


def _int_keys(d: dict[Any, Any]) -> list[int] | None:
    try:
        return sorted(int(str(k)) for k in d)
    except ValueError:
        return None


def _renest(live: dict[Any, Any], recomputed: dict[str, Any], notes: list[str]) -> dict[Any, Any]:
    """Move a top-level live key into the recomputed mapping that holds it one level down.

    The 2015 FBM2 node wrote ``segments_details`` at the top level; Listing 13 and ertools
    nest it under ``details``.
    """
    out = dict(live)
    for key in list(live):
        k = str(key)
        if k in recomputed:
            continue
        holders = [p for p, v in recomputed.items() if isinstance(v, dict) and k in v]
        if len(holders) != 1:
            continue
        parent = holders[0]
        existing = out.get(parent)
        if existing is not None and not isinstance(existing, dict):
            continue
        merged = dict(existing or {})
        merged[k] = out.pop(key)
        out[parent] = merged
        notes.append(f"the live score has {k} at the top level; compared with {parent}.{k}")
    return out


def _align_indices(live: Any, recomputed: Any, notes: list[str], path: str = "") -> Any:
    """Renumber live mappings indexed 1..N as 0..N-1 where ertools numbers 0..N-1.

    The 2015 FBM2 node numbered its segments from 1 (``segments_detail[i]``, i = 1..N), the
    seed's Listing 13 and ertools from 0; comparing index 1 with index 1 would compare
    different segments.
    """
    if not isinstance(live, dict) or not isinstance(recomputed, dict):
        return live
    lk, rk = _int_keys(live), _int_keys(recomputed)
    if lk and not rk:
        # An early 2015 FBM2 node put the segments straight under ``details``; ertools nests
        # them one level deeper (``details.segments_details``): descend into that mapping.
        holders = [k for k, v in recomputed.items() if isinstance(v, dict) and _int_keys(v)]
        if len(holders) == 1:
            notes.append(
                f"{path or 'score'}: the live score has the indexed entries directly; "
                f"compared with {path + '.' if path else ''}{holders[0]}"
            )
            live = {holders[0]: live}
            lk = None
    if lk and rk and len(lk) == len(rk) and lk == [k + 1 for k in rk]:
        notes.append(
            f"{path or 'score'}: the live score numbers from 1, ertools from 0; "
            "live index i is compared with recomputed index i-1"
        )
        live = {str(int(str(k)) - 1): v for k, v in live.items()}
    out = {}
    rec = {str(k): v for k, v in recomputed.items()}
    for k, v in live.items():
        sub = f"{path}.{k}" if path else str(k)
        out[str(k)] = _align_indices(v, rec.get(str(k)), notes, sub)
    return out


# --------------------------------------------------------------------------------------------
# Explanations


@dataclass(frozen=True)
class _Rule:
    pattern: str  # regex on the last key component
    benchmarks: tuple[str, ...]  # () = every benchmark
    text: str
    params: tuple[str, ...] = ()  # parameter-name fragments worth showing


_RULES: tuple[_Rule, ...] = (
    _Rule(
        r"distance_error$",
        ("fbm3w",),
        "the FBM3 path error depends on d_min (the 2015 node hard-coded 0.00033 m), on the "
        "pose source and on which poses fall in the run window (the live node collected them "
        "by callback while EXECUTING_GOAL/WAITING_RESULT; ertools takes the logged poses "
        "between the logged state changes)",
        ("d_min", "topic", "source", "frame", "runs"),
    ),
    _Rule(
        r"^best_run$",
        ("fbm3w",),
        "the best run is the one with the smallest distance_error: it changes when the "
        "per-run errors change",
    ),
    _Rule(
        r"orientation_(error|accuracy)$",
        ("fbm2h", "trajectory"),
        "the 2015 node took sin and cos of the unwrapped |robot yaw - target yaw|; ertools "
        "wraps the difference to [-pi, pi] first (identical unless the difference crosses "
        "+-pi); the robot pose also depends on the marker-to-robot transform",
        ("transform", "source", "topic", "reached"),
    ),
    _Rule(
        r"(dinstance_error|distance_error|position_accuracy|position_error|robot_pose)$",
        ("fbm2h", "trajectory"),
        "the live node used the latest mocap pose when the result arrived; ertools "
        "interpolates the logged ground truth at the logged moment the waypoint was reached "
        "and applies the marker-to-robot transform as a full SE(3) composition",
        ("transform", "source", "topic", "reached", "max_gap", "association"),
    ),
    _Rule(
        r"(time|_time)$",
        (),
        "the live node timed with its own wall clock (time.time()) as messages arrived; "
        "ertools uses the record times of the logged state messages (differences of a few "
        "milliseconds up to one 10 Hz heartbeat per transition)",
    ),
    _Rule(
        r"(pose_score|x_error|y_error|theta_error|position|orientation)$",
        ("fbm1h", "fbm1w"),
        "the ground truth is averaged over the window in which the board stood still "
        "(the 2015 node interpolated one tf lookup when the result arrived); theta is in "
        "degrees",
        ("window", "source", "topic", "items"),
    ),
    _Rule(
        r"(class|instance)(_accuracy|_correct)?$",
        ("fbm1h", "fbm1w"),
        "class and instance are compared as text with the item list",
        ("items",),
    ),
)

_WORDS = re.compile(r"[a-z]+")
_STOP_WORDS = frozenset({"error", "errors", "accuracy", "details", "best", "total", "value"})


def explain(
    key: str,
    live: Any,
    recomputed: Any,
    *,
    benchmark: str,
    parameters: tuple[tuple[str, str], ...],
    deviations: tuple[str, ...],
    warnings: tuple[str, ...] = (),
) -> str:
    """Why ``live`` and ``recomputed`` differ at ``key``: rules, recognised patterns,
    matching deviations from 2015, the scorer's warnings about the same parameters (d_min
    below the noise...) and the relevant parameter values."""
    leaf = key.rsplit(".", 1)[-1].lower()
    parts: list[str] = []
    wanted: list[str] = []
    if _is_number(live) and _is_number(recomputed):
        pattern = _number_pattern(leaf, float(live), float(recomputed))
        if pattern:
            parts.append(pattern)
    for rule in _RULES:
        if rule.benchmarks and benchmark not in rule.benchmarks:
            continue
        if re.search(rule.pattern, leaf):
            parts.append(rule.text)
            wanted.extend(rule.params)
            break
    # Deviations are matched by the key's own words; words every score uses say nothing.
    words = {w for w in _WORDS.findall(leaf.replace("_", " ")) if len(w) > 3} - _STOP_WORDS
    for dev in deviations:
        if words & set(_WORDS.findall(dev.lower())):
            parts.append(f"ertools differs from 2015: {dev}")
    for warning in warnings:
        if any(frag in warning.lower() for frag in wanted if len(frag) > 3):
            parts.append(f"the scorer warned: {warning}")
    shown = [
        f"{name}={value}"
        for name, value in parameters
        if any(frag in name.lower() for frag in wanted)
    ]
    if shown:
        parts.append("recomputed with " + ", ".join(shown))
    if not parts:
        parts.append(
            "no specific cause known for this key: compare the parameters and the "
            "deviations from 2015 listed with the comparison"
        )
    return "; ".join(parts)


def _number_pattern(leaf: str, live: float, rec: float) -> str:
    """Causes recognisable from the two numbers alone."""
    if "orientation" in leaf and live < 0 <= rec and math.isclose(-live, rec, abs_tol=1e-6):
        return (
            "the live value is the negative of the recomputed one: the unwrapped yaw "
            "difference of the 2015 node exceeded pi (orientation wrap), "
            "so atan2(sin, cos) came out negative"
        )
    if "time" in leaf and abs(live - rec) > 1e8:
        return "the two times use different origins (epoch vs seconds from the bag's start)"
    return ""


def _is_number(value: Any) -> bool:
    return isinstance(value, int | float) and not isinstance(value, bool)


# --------------------------------------------------------------------------------------------
# Comparing


# The live FBM2H score records the transform its node used (seed Listing 13: details.marker-robot
# transform, [[x, y, z], [qx, qy, qz, qw]]); an audit given none re-scores with it.
LIVE_TRANSFORM_KEY = "marker-robot transform"
IDENTITY_CAVEAT = "identity transform: recomputed scores are not comparable with the live ones"
# Score keys that depend on the robot pose, hence on the marker-to-robot transform.
POSE_KEYS = re.compile(
    r"position|orientation|distance|dinstance|robot_pose|transform", re.IGNORECASE
)  # "dinstance": the 2015 spelling (Listing 13)


def live_transform(live: Any) -> MarkerTransform | None:
    """The marker-to-robot transform the live FBM2H score says its node used, or None when the
    payload has none (or not as ``[[x, y, z], [qx, qy, qz, qw]]``)."""
    from ertools.configs.transform import parse_transform
    from ertools.errors import ConfigError

    if not isinstance(live, dict):
        return None
    details = live.get("details")
    value = details.get(LIVE_TRANSFORM_KEY) if isinstance(details, dict) else None
    if value is None:
        value = live.get(LIVE_TRANSFORM_KEY)  # an early node wrote it at the top level
    if value is None:
        return None
    try:
        return parse_transform(
            {
                "robot_info": "live score",
                "transform_timestamp": "0",
                "marker_to_robot_transform": value,
            },
            source=f"the live score (details.{LIVE_TRANSFORM_KEY})",
        )
    except ConfigError:
        return None


def _identity_caveat(live: Any, result: BenchmarkResult) -> str:
    """:data:`IDENTITY_CAVEAT` when ``result`` was computed with the identity transform and the
    live score does not say its node used the identity too."""
    transform = getattr(result, "transform", None)
    if not isinstance(transform, MarkerTransform) or not transform.is_identity:
        return ""
    used = live_transform(live)
    return "" if used is not None and used.is_identity else IDENTITY_CAVEAT


def compare_scores(
    live: Any,
    result: BenchmarkResult,
    *,
    abs_tol: float = DEFAULT_ABS_TOL,
    rel_tol: float = DEFAULT_REL_TOL,
    as_2015: BenchmarkResult | None = None,
) -> ScoreComparison:
    """Compare the live score (parsed payload) with a recomputed result, key by key.

    Args:
        live: the parsed TRANSMITTING_SCORE payload (``Audit.live_score``), or None.
        result: the recomputed result of the same benchmark execution.
        abs_tol: numbers closer than this are the same.
        rel_tol: ...or closer than this relative to the live value.
        as_2015: the same execution recomputed with the 2015 node's rules (see
            :func:`rescore_2015`); a difference that it reproduces is one of ertools'
            deliberate deviations, one it does not lies in the data or the inputs.

    Returns:
        Every leaf of either score, in the recomputed score's order, with an explanation for
        each difference.
    """
    recomputed = jsonable(result.to_dict())
    params = tuple(result.provenance.parameters)
    devs = tuple(result.deviations)
    caveat = _identity_caveat(live, result)
    notes: list[str] = []
    transform = getattr(result, "transform", None)
    if isinstance(transform, MarkerTransform) and transform.source.startswith("the live score"):
        notes.append(f"transform taken from the live score (details.{LIVE_TRANSFORM_KEY})")
    if live is None:
        notes.append("no live score in the bag (no TRANSMITTING_SCORE payload, or unreadable)")
        live_flat: dict[str, Any] = {}
    elif not isinstance(live, dict):
        notes.append(f"the live score is not a mapping but {type(live).__name__}")
        live_flat = {"(live score)": live}
    else:
        live_flat = flatten(_align_indices(_renest(live, recomputed, notes), recomputed, notes))
    rec_flat = flatten(recomputed)
    flat_2015 = flatten(jsonable(as_2015.to_dict())) if as_2015 is not None else {}
    if live_flat and not set(live_flat) & set(rec_flat):
        notes.append(
            "the live score has no key in common with the recomputed score: it is shown as "
            "sent, beside the recomputed headline values"
        )
        rec_flat = {k: v for k, v in rec_flat.items() if "." not in k}
    lines: list[ScoreLine] = []
    keys = list(rec_flat) + [k for k in live_flat if k not in rec_flat]
    for key in keys:
        has_live, has_rec = key in live_flat, key in rec_flat
        lv: Any = live_flat.get(key)
        rv: Any = rec_flat.get(key)
        if not has_live or not has_rec:
            if live is None:
                continue  # nothing to compare with: listing every key says nothing
            status = "only live" if has_live else "only recomputed"
            lines.append(ScoreLine(key, lv, rv, None, status, ""))
            continue
        diff: float | None = None
        if _is_number(lv) and _is_number(rv):
            diff = float(rv) - float(lv)
            same = abs(diff) <= max(abs_tol, rel_tol * abs(float(lv)))
        else:
            same = lv == rv or str(lv) == str(rv)
        expl = (
            ""
            if same
            else explain(
                key,
                lv,
                rv,
                benchmark=result.name,
                parameters=params,
                deviations=devs,
                warnings=tuple(result.warnings),
            )
        )
        if not same and as_2015 is not None and key in flat_2015:
            expl = _check_2015(lv, flat_2015[key]) + "; " + expl
        if not same and caveat and POSE_KEYS.search(key):
            expl = f"{caveat}; {expl}"  # the reason first: nothing else can explain it away
        lines.append(ScoreLine(key, lv, rv, diff, "same" if same else "differs", expl))
    return ScoreComparison(
        benchmark=result.name,
        lines=tuple(lines),
        abs_tol=abs_tol,
        parameters=params,
        deviations=devs,
        notes=tuple(notes),
        caveat=caveat,
    )


# A value recomputed with the 2015 rules "reproduces" the live one within this: far above the
# mocap noise on a recomputed score (~1e-5 relative), far below the effect of a rule (>1%).
REPRODUCED_REL_TOL = 1e-3
# Within this, a remaining difference is what the live node's timing explains: it read the
# mocap stream a few ms after the logged moment, which moves a pose by ~0.3 % of a typical
# FBM2 distance error at walking speed; a wrong input or rule moves it by far more.
TIMING_REL_TOL = 1e-2


def _check_2015(live: Any, value: Any) -> str:
    if _is_number(live) and _is_number(value):
        lv, v = float(live), float(value)
        if abs(v - lv) <= max(DEFAULT_ABS_TOL, REPRODUCED_REL_TOL * abs(lv)):
            return (
                f"recomputed with the 2015 rules: {v:.6g}, the live value (within "
                f"{REPRODUCED_REL_TOL:.1%}): the difference comes from ertools' deliberate "
                "deviations or the options of this re-score, not from the data"
            )
        if abs(v - lv) <= TIMING_REL_TOL * abs(lv):
            return (
                f"recomputed with the 2015 rules: {v:.6g}, within {TIMING_REL_TOL:.0%} of the "
                "live value: the live node read the mocap stream a few ms after the logged "
                "moment (mocap noise and motion in between), not a deviation or a data problem"
            )
        return (
            f"recomputed with the 2015 rules: {v:.6g}, still not the live value: the cause "
            "is in the data or the inputs, not in ertools' deviations"
        )
    if str(live) == str(value):
        return "recomputed with the 2015 rules: the live value (a deviation or an option)"
    return f"recomputed with the 2015 rules: {value!r}, still not the live value"


def attach(audit: Audit, result: BenchmarkResult, as_2015: BenchmarkResult | None = None) -> Audit:
    """The audit with the recomputed result and its comparison with the live score."""
    comparison = compare_scores(audit.live_score, result, as_2015=as_2015)
    warnings = list(audit.warnings)
    if comparison.differences:
        warnings.append(
            f"{len(comparison.differences)} value(s) of the live score differ from the "
            "recomputed score (see the comparison)"
        )
    return replace(
        audit,
        recomputed=result,
        comparison=comparison,
        warnings=tuple(warnings) + tuple(result.warnings),
        deviations=tuple(result.deviations),
        failures=tuple(result.failures),
    )


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
    from ertools.audit.analyse import DEFAULT_MAX_SILENCE_NS, audit_states
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
