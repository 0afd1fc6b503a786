"""The score sent live against the score recomputed from the same bag, key by key, explained.

The 2015 BmBox sent its score as YAML in the TRANSMITTING_SCORE payload (seed Listings 13 and
16); ertools' results have the same nesting (``to_dict()``), so the two are flattened to dotted
keys (``runs_details.2.distance_error``) and compared leaf by leaf. Every difference gets an
explanation drawn from what is known to make the two differ: the parameters the result was
computed with (d_min, pose source, transform...), the places where ertools deliberately differs
from the 2015 node (``result.deviations``), and patterns recognised in the numbers themselves
(the orientation wrap, segments numbered from 1).

Pure: no file is read here. :func:`attach` puts a comparison into an
:class:`~ertools.auditing.model.Audit`.
"""

from __future__ import annotations

import re
from dataclasses import replace
from typing import TYPE_CHECKING, Any

from ertools.auditing.explain import explain, is_number
from ertools.auditing.model import Audit, ScoreComparison, ScoreLine
from ertools.benchmarks import registry
from ertools.configs.transform import LIVE_TRANSFORM_KEY, MarkerTransform, live_transform
from ertools.serialize import jsonable

if TYPE_CHECKING:
    from ertools.benchmarks.base import BenchmarkResult

# Two numbers within this are the same score: 1 um, 1 urad, 1 us, far below any effect the
# explanations describe and far above float round-off of a YAML round trip.
DEFAULT_ABS_TOL = 1e-6
DEFAULT_REL_TOL = 1e-9


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
# Comparing


IDENTITY_CAVEAT = "identity transform: recomputed scores are not comparable with the live ones"
# Score keys that depend on the robot pose, hence on the marker-to-robot transform.
POSE_KEYS = re.compile(
    r"position|orientation|distance|dinstance|robot_pose|transform", re.IGNORECASE
)  # "dinstance": the 2015 spelling (Listing 13)


def _identity_caveat(live: Any, result: BenchmarkResult) -> str:
    """:data:`IDENTITY_CAVEAT` when ``result`` was computed with the identity transform and the
    live score does not say its node used the identity too."""
    transform = getattr(result, "transform", None)
    if not isinstance(transform, MarkerTransform) or not transform.is_identity:
        return ""
    used = live_transform(live)
    return "" if used is not None and used.is_identity else IDENTITY_CAVEAT


def _interval_key(key: str) -> bool:
    """A flattened key of an interval (``..._interval.0``) or of the ``uncertainty`` block."""
    parts = key.split(".")
    return parts[0] == "uncertainty" or any(p.endswith("_interval") for p in parts)


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
    # The intervals and their uncertainty block (issue 28) qualify the recomputed score; the
    # live node never sent any: not compared, not listed as "only recomputed".
    rec_flat = {k: v for k, v in flatten(recomputed).items() if not _interval_key(k)}
    flat_2015 = flatten(jsonable(as_2015.to_dict())) if as_2015 is not None else {}
    if live_flat and not set(live_flat) & set(rec_flat):
        notes.append(
            "the live score has no key in common with the recomputed score: it is shown as "
            "sent, beside the recomputed headline values"
        )
        rec_flat = {k: v for k, v in rec_flat.items() if "." not in k}
    lines: list[ScoreLine] = []
    keys = list(rec_flat) + [k for k in live_flat if k not in rec_flat]
    # A referee's input the score only echoes (FBM2H's hits): not given to the rescoring, it
    # is not recomputed, and its live value is no difference in the data.
    echoed = (
        {i.name: i.option for i in registry.get(result.name).inputs}
        if result.name in registry.names()
        else {}
    )
    for key in keys:
        has_live, has_rec = key in live_flat, key in rec_flat
        lv: Any = live_flat.get(key)
        rv: Any = rec_flat.get(key)
        if key in echoed and rv is None and has_live:
            why = f"a referee's input, not given to the rescoring ({echoed[key]})"
            lines.append(ScoreLine(key, lv, rv, None, "only live", why))
            continue
        if not has_live or not has_rec:
            if live is None:
                continue  # nothing to compare with: listing every key says nothing
            status = "only live" if has_live else "only recomputed"
            lines.append(ScoreLine(key, lv, rv, None, status, ""))
            continue
        diff: float | None = None
        if is_number(lv) and is_number(rv):
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
    if is_number(live) and is_number(value):
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
